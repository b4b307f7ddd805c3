//! Which scenes a run checks: every `.ron` file under a folder whose top level is not a
//! `Graph(...)`, sorted by relative path, then the shard's share of them.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::{Error, Result};

/// One scene of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneEntry {
    /// Relative to the scanned folder, `/`-separated: `view_slices/torus_egg.ron`.
    pub rel: String,
    pub path: PathBuf,
    /// `<stem>.ref.exr` beside the scene file.
    pub reference: PathBuf,
    /// The scene's output folder relative to the run's output folder: `rel` without `.ron`.
    pub folder: PathBuf,
}

impl SceneEntry {
    fn new(base: &Path, rel_parts: &[String]) -> Self {
        let rel = rel_parts.join("/");
        let path = rel_parts.iter().fold(base.to_path_buf(), |p, s| p.join(s));
        let stem = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let reference = path.with_file_name(format!("{stem}.ref.exr"));
        let mut folder: PathBuf = rel_parts[..rel_parts.len() - 1].iter().collect();
        folder.push(&stem);
        Self { rel, path, reference, folder }
    }
}

/// `--shard i/n`: the scenes whose 0-based index `k` in the sorted list has `k % n == i - 1`
/// (`i` is 1-based: `1/2` and `2/2` split a suite in two).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Default for Shard {
    fn default() -> Self {
        Shard { index: 1, count: 1 }
    }
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || format!("`{s}`: expected a shard i/n with 1 <= i <= n, e.g. 1/4");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) =
            (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    pub fn take(&self, scenes: Vec<SceneEntry>) -> Vec<SceneEntry> {
        scenes
            .into_iter()
            .enumerate()
            .filter(|(k, _)| k % self.count == self.index - 1)
            .map(|(_, s)| s)
            .collect()
    }
}

/// Every scene under `dir` (recursively; hidden folders and symlinked folders skipped), sorted by
/// relative path. `dir` may also be a single scene file.
pub fn find(dir: &Path) -> Result<Vec<SceneEntry>> {
    let meta =
        std::fs::metadata(dir).map_err(|e| Error::file(dir, format!("cannot read scene folder: {e}")))?;
    if meta.is_file() {
        let name = dir.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let base = dir.parent().unwrap_or(Path::new(""));
        return Ok(vec![SceneEntry::new(base, &[name])]);
    }
    let mut found = Vec::new();
    walk(dir, &mut Vec::new(), &mut found)?;
    let mut scenes: Vec<SceneEntry> = found.iter().map(|parts| SceneEntry::new(dir, parts)).collect();
    scenes.sort_by(|a, b| a.rel.cmp(&b.rel));
    Ok(scenes)
}

fn walk(dir: &Path, rel: &mut Vec<String>, found: &mut Vec<Vec<String>>) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::file(dir, format!("cannot list: {e}")))?;
    for e in entries {
        let e = e.map_err(|e| Error::file(dir, format!("cannot list: {e}")))?;
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let path = e.path();
        let kind = e.file_type().map_err(|err| Error::file(&path, err))?;
        rel.push(name.clone());
        if kind.is_dir() {
            walk(&path, rel, found)?;
        } else if name.ends_with(".ron") && path.is_file() && !is_graph(&path) {
            found.push(rel.clone());
        }
        rel.pop();
    }
    Ok(())
}

/// Whether a RON file's top level is `Graph(` (a render graph, not a scene). Unreadable files count
/// as scenes, so that the run reports them.
fn is_graph(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path) else { return false };
    let rest = skip_trivia(&text);
    rest.strip_prefix("Graph").is_some_and(|r| r.trim_start().starts_with('('))
}

/// Skips whitespace, `//` and `/* */` comments and `#![...]` attributes at the start of RON text.
fn skip_trivia(mut s: &str) -> &str {
    loop {
        s = s.trim_start();
        if let Some(r) = s.strip_prefix("//") {
            s = r.split_once('\n').map_or("", |(_, r)| r);
        } else if let Some(r) = s.strip_prefix("/*") {
            s = r.split_once("*/").map_or("", |(_, r)| r);
        } else if let Some(r) = s.strip_prefix("#!") {
            s = r.split_once(']').map_or("", |(_, r)| r);
        } else {
            return s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_list() {
        let scenes: Vec<SceneEntry> =
            (0..7).map(|i| SceneEntry::new(Path::new("d"), &[format!("s{i}.ron")])).collect();
        let a = "1/3".parse::<Shard>().unwrap().take(scenes.clone());
        let b = "2/3".parse::<Shard>().unwrap().take(scenes.clone());
        let c = "3/3".parse::<Shard>().unwrap().take(scenes.clone());
        assert_eq!(a.iter().map(|s| s.rel.as_str()).collect::<Vec<_>>(), ["s0.ron", "s3.ron", "s6.ron"]);
        assert_eq!(a.len() + b.len() + c.len(), 7);
        for bad in ["0/2", "3/2", "1", "a/b", "1/0", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn entry_names() {
        let e = SceneEntry::new(Path::new("scenes"), &["view_slices".into(), "torus_egg.ron".into()]);
        assert_eq!(e.rel, "view_slices/torus_egg.ron");
        assert_eq!(e.reference, Path::new("scenes/view_slices/torus_egg.ref.exr"));
        assert_eq!(e.folder, Path::new("view_slices/torus_egg"));
    }

    #[test]
    fn graphs_are_recognised() {
        assert_eq!(skip_trivia("// c\n/* x */ #![enable(implicit_some)]\n Graph("), "Graph(");
        assert!(skip_trivia("#![enable(implicit_some)]\nScene(").starts_with("Scene"));
    }
}
