//! Which scenes a run checks: every `.ron` file under a folder whose top level is not a
//! `Graph(...)`, sorted by relative path; and the `--shard` argument.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::{Error, Result};

/// One scene of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneEntry {
    /// Relative to the scanned folder, `/`-separated: `view_slices/torus_egg.ron`.
    pub(crate) rel: String,
    pub(crate) path: PathBuf,
    /// `<stem>.ref.exr` beside the scene file.
    pub(crate) reference: PathBuf,
    /// The scene's output folder relative to the run's output folder: `rel` without `.ron`.
    pub(crate) folder: PathBuf,
}

impl SceneEntry {
    pub(super) fn new(base: &Path, rel_parts: &[String]) -> Self {
        let rel = rel_parts.join("/");
        let path = rel_parts.iter().fold(base.to_path_buf(), |p, s| p.join(s));
        let stem = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let reference = path.with_file_name(format!("{stem}.ref.exr"));
        let mut folder: PathBuf = rel_parts[..rel_parts.len() - 1].iter().collect();
        folder.push(&stem);
        Self { rel, path, reference, folder }
    }
}

/// `--shard i/n` (1-based: `1/2` and `2/2` split a suite in two); which scenes shard `i` checks
/// is the plan's business (`shards.rs`).
///
/// `auto/n` takes `i` from the engine running the task: Slurm's `SLURM_ARRAY_TASK_ID` (counted
/// from `SLURM_ARRAY_TASK_MIN`, so arrays numbered from 0 or 1 both work) or Kubernetes'
/// `JOB_COMPLETION_INDEX` (0-based); plain `auto` also takes `n` from `SLURM_ARRAY_TASK_COUNT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Shard {
    pub(crate) index: usize,
    pub(crate) count: usize,
}

impl Default for Shard {
    fn default() -> Self {
        Shard { index: 1, count: 1 }
    }
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Self::parse(s, &|k| std::env::var(k).ok())
    }
}

impl Shard {
    /// Parses `i/n`, `auto/n` or `auto`, reading engine variables through `env`.
    pub(crate) fn parse(s: &str, env: &dyn Fn(&str) -> Option<String>) -> std::result::Result<Self, String> {
        let bad = || format!("`{s}`: expected a shard i/n with 1 <= i <= n, e.g. 1/4, or auto/n");
        let (i, n) = match s.split_once('/') {
            Some((i, n)) => (i.trim(), Some(n.trim())),
            None if s.trim() == "auto" => ("auto", None),
            None => return Err(bad()),
        };
        let number = |name: &str, v: &str| {
            v.trim().parse::<usize>().map_err(|_| format!("`{s}`: {name}={v:?} is not a whole number"))
        };
        let count = match n {
            Some(n) => n.parse().map_err(|_| bad())?,
            None => match env("SLURM_ARRAY_TASK_COUNT") {
                Some(v) => number("SLURM_ARRAY_TASK_COUNT", &v)?,
                None => {
                    return Err(format!(
                        "`{s}`: SLURM_ARRAY_TASK_COUNT is not set; give the count, e.g. auto/4"
                    ))
                }
            },
        };
        let index = if i == "auto" {
            if let Some(id) = env("SLURM_ARRAY_TASK_ID") {
                let min =
                    env("SLURM_ARRAY_TASK_MIN").map(|m| number("SLURM_ARRAY_TASK_MIN", &m)).transpose()?;
                let id = number("SLURM_ARRAY_TASK_ID", &id)?;
                id.checked_sub(min.unwrap_or(0)).ok_or_else(bad)? + 1
            } else if let Some(k) = env("JOB_COMPLETION_INDEX") {
                number("JOB_COMPLETION_INDEX", &k)? + 1
            } else {
                return Err(format!(
                    "`{s}`: no engine shard index: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set \
                     (run it as a Slurm array task or a Kubernetes Indexed Job, or give i/n)"
                ));
            }
        } else {
            i.parse().map_err(|_| bad())?
        };
        if index == 0 || index > count {
            return Err(if i == "auto" {
                format!("`{s}`: the engine's task is shard {index}, outside 1..={count}")
            } else {
                bad()
            });
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
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
    fn shard_arguments() {
        let none = |_: &str| None;
        assert_eq!(Shard::parse("2/3", &none), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/2", "3/2", "1", "a/b", "1/0", "", "auto/3", "auto"] {
            assert!(Shard::parse(bad, &none).is_err(), "{bad}");
        }
        let slurm = |k: &str| match k {
            "SLURM_ARRAY_TASK_ID" => Some("4".to_string()),
            "SLURM_ARRAY_TASK_MIN" => Some("3".to_string()),
            "SLURM_ARRAY_TASK_COUNT" => Some("5".to_string()),
            _ => None,
        };
        assert_eq!(Shard::parse("auto", &slurm), Ok(Shard { index: 2, count: 5 }));
        assert_eq!(Shard::parse("auto/2", &slurm), Ok(Shard { index: 2, count: 2 }));
        assert!(Shard::parse("auto/1", &slurm).unwrap_err().contains("outside 1..=1"));
        let k8s = |k: &str| (k == "JOB_COMPLETION_INDEX").then(|| "0".to_string());
        assert_eq!(Shard::parse("auto/3", &k8s), Ok(Shard { index: 1, count: 3 }));
        assert!(Shard::parse("auto", &k8s).unwrap_err().contains("SLURM_ARRAY_TASK_COUNT"));
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
