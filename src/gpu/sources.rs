//! Where WGSL kernels (and their `#include`s) and the default graphs are read from. Every file
//! under `wgsl/` and `graphs/` is embedded in the binary (see `build.rs`; so are the presets'
//! scene files, `scenes/presets/*.ron`, which `voltex import --preset` reads from here), so an installed or copied
//! binary needs no source tree; files on disk still win, so kernels and graphs stay editable (and
//! hot-reloadable) in place. A shader `rel` (a path relative to the WGSL root, e.g.
//! `shared/types.wgsl`) is looked up, first match wins:
//!
//! 1. beside the graph file in use (a graph copied elsewhere with its own WGSL next to it);
//! 2. `$VOLTEX_ROOT/wgsl` when `VOLTEX_ROOT` is set, else the source tree voltex was built from,
//!    when it still exists on disk;
//! 3. the copy embedded in the binary, reported as `<embedded>/wgsl/rel`.
//!
//! `VOLTEX_ROOT` replaces the build's source tree (as it always did): pointing it at a folder
//! without `wgsl/` and `graphs/` makes voltex use only its embedded files.

use std::path::{Component, Path, PathBuf};

use crate::error::{Error, Result};

/// The embedded files: (`wgsl/...` or `graphs/...`, contents), sorted by path.
static EMBEDDED: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/embedded.rs"));

/// How embedded files are named in messages: `<embedded>/wgsl/composite.wgsl`.
pub(crate) const EMBEDDED_PREFIX: &str = "<embedded>";

/// The embedded file at `rel` (`wgsl/x.wgsl`, `graphs/frame.ron`), if any.
pub(crate) fn embedded(rel: &str) -> Option<&'static str> {
    EMBEDDED.binary_search_by(|(p, _)| (*p).cmp(rel)).ok().map(|i| EMBEDDED[i].1)
}

/// Every embedded file as (`wgsl/...` or `graphs/...`, contents).
pub(crate) fn embedded_files() -> &'static [(&'static str, &'static str)] {
    EMBEDDED
}

/// A file found by [`Sources`]: its text and where it came from.
#[derive(Debug, Clone)]
pub(crate) struct Source {
    /// The file on disk, or `<embedded>/wgsl/...` for an embedded one (for messages).
    pub(crate) path: PathBuf,
    pub(crate) text: String,
}

/// The places shaders and graphs are looked up in, in order (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Sources {
    /// Folders searched for shaders, in order.
    dirs: Vec<PathBuf>,
    /// The project tree's `graphs/` folder on disk, if any.
    graphs: Option<PathBuf>,
    /// Whether the embedded files come last.
    embedded: bool,
}

impl Sources {
    /// The project's sources: `$VOLTEX_ROOT` (or the build's source tree when it exists), then the
    /// embedded files. Fails when `VOLTEX_ROOT` names something that is not a folder.
    pub fn project() -> Result<Self> {
        let root = match std::env::var_os("VOLTEX_ROOT").filter(|v| !v.is_empty()) {
            Some(root) => {
                let root = PathBuf::from(root);
                if !root.is_dir() {
                    return Err(Error::file(&root, "VOLTEX_ROOT does not name a folder"));
                }
                Some(root)
            }
            None => Some(PathBuf::from(env!("CARGO_MANIFEST_DIR"))).filter(|r| r.is_dir()),
        };
        Ok(Self {
            dirs: root.iter().map(|r| r.join("wgsl")).collect(),
            graphs: root.map(|r| r.join("graphs")),
            embedded: true,
        })
    }

    /// Only the WGSL folder `dir` on disk, nothing embedded (tests and tools).
    pub fn folder(dir: &Path) -> Self {
        Self { dirs: vec![dir.to_path_buf()], graphs: None, embedded: false }
    }

    /// These sources with the folder of `graph_file` (a graph read from disk) searched first.
    pub fn beside(mut self, graph_file: &Path) -> Self {
        let dir = match graph_file.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !self.dirs.contains(&dir) {
            self.dirs.insert(0, dir);
        }
        self
    }

    /// The shader `rel` (relative to the WGSL root), from the first place that has it; `None`
    /// when no place has it. A file that exists but cannot be read is an error.
    pub(crate) fn shader(&self, rel: &str) -> Result<Option<Source>> {
        for dir in &self.dirs {
            let path = dir.join(rel);
            // Anything at the path counts as found, so a FIFO or a folder there is an error
            // rather than a silent fall-through to the embedded copy.
            if std::fs::symlink_metadata(&path).is_ok() {
                let text = crate::input::read_text(&path, "a WGSL file")?;
                return Ok(Some(Source { path, text }));
            }
        }
        Ok(self.embedded_file("wgsl", rel))
    }

    /// What looking up the shader `rel` finds on disk, one `stat` per folder tried: each path
    /// tried with its modification time and length if something is there (the last one tried
    /// is the one found, or none is and the embedded copy is used).
    pub(crate) fn probe(&self, rel: &str) -> Vec<(PathBuf, Option<(std::time::SystemTime, u64)>)> {
        let mut out = Vec::new();
        for dir in &self.dirs {
            let path = dir.join(rel);
            let meta = std::fs::symlink_metadata(&path).ok();
            let found = meta.map(|m| (m.modified().unwrap_or(std::time::UNIX_EPOCH), m.len()));
            out.push((path, found));
            if found.is_some() {
                break;
            }
        }
        out
    }

    /// Whether the shader `rel` exists in a place (one `stat` per folder, no read).
    pub(crate) fn has_shader(&self, rel: &str) -> bool {
        self.probe(rel).last().is_some_and(|(_, f)| f.is_some())
            || (self.embedded && normalized(rel).is_some_and(|r| embedded(&format!("wgsl/{r}")).is_some()))
    }

    /// The project tree's file of the graph `name`, when it is on disk (else the embedded copy
    /// is used).
    pub(crate) fn graph_path(&self, name: &str) -> Option<PathBuf> {
        self.graphs.as_ref().map(|g| g.join(name)).filter(|p| p.exists())
    }

    /// The graph `name` of the project (e.g. `frame.ron`): the file in the project tree's
    /// `graphs/` when present, else the embedded copy.
    pub(crate) fn graph(&self, name: &str) -> Result<Option<Source>> {
        if let Some(path) = self.graphs.as_ref().map(|g| g.join(name)).filter(|p| p.exists()) {
            let text = crate::input::read_text(&path, "a graph file")?;
            return Ok(Some(Source { path, text }));
        }
        Ok(self.embedded_file("graphs", name))
    }

    fn embedded_file(&self, folder: &str, rel: &str) -> Option<Source> {
        if !self.embedded {
            return None;
        }
        let key = normalized(rel).map(|r| format!("{folder}/{r}"))?;
        let text = embedded(&key)?;
        Some(Source { path: Path::new(EMBEDDED_PREFIX).join(&key), text: text.to_string() })
    }

    /// The folders on disk that shaders are looked up in and that exist (what the preview
    /// watches, with the graph's folder); the embedded files are not watched.
    pub fn watched_dirs(&self) -> Vec<PathBuf> {
        self.dirs.iter().filter(|d| d.is_dir()).cloned().collect()
    }

    /// The places searched, for "not found" messages: `/g, /p/wgsl or the embedded kernels`.
    pub(crate) fn describe(&self) -> String {
        let mut places: Vec<String> = self.dirs.iter().map(|d| d.display().to_string()).collect();
        if self.embedded {
            places.push("the embedded kernels".into());
        }
        match places.split_last() {
            None => "nowhere".into(),
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        }
    }
}

/// `rel` with `/` separators and `.` components dropped; `None` for absolute paths and `..`
/// (never embedded).
fn normalized(rel: &str) -> Option<String> {
    let mut parts = Vec::new();
    for c in Path::new(rel).components() {
        match c {
            Component::Normal(p) => parts.push(p.to_str()?),
            Component::CurDir => {}
            _ => return None,
        }
    }
    (!parts.is_empty()).then(|| parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every file under `dir` (as `rel/path`), with the build script's exclusions.
    fn walk(dir: &Path, rel: &str, out: &mut Vec<(String, PathBuf)>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let e = e.unwrap();
            let name = e.file_name().to_str().unwrap().to_string();
            if name.starts_with('.') || name.ends_with('~') {
                continue;
            }
            let child = format!("{rel}/{name}");
            if e.path().is_dir() {
                walk(&e.path(), &child, out);
            } else {
                out.push((child, e.path()));
            }
        }
    }

    #[test]
    fn every_kernel_graph_and_preset_is_embedded_byte_identically() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        walk(&root.join("wgsl"), "wgsl", &mut files);
        walk(&root.join("graphs"), "graphs", &mut files);
        let mut presets = Vec::new();
        walk(&root.join("scenes/presets"), "scenes/presets", &mut presets);
        files.extend(presets.into_iter().filter(|(r, _)| r.ends_with(".ron")));
        files.sort();
        assert!(files.iter().any(|(r, _)| r == "wgsl/shared/types.wgsl"), "{files:?}");
        assert!(files.iter().any(|(r, _)| r == "graphs/frame.ron"), "{files:?}");
        for (rel, path) in &files {
            let on_disk = std::fs::read(path).unwrap();
            let copy = embedded(rel).unwrap_or_else(|| panic!("{rel} is not embedded"));
            assert!(copy.as_bytes() == on_disk.as_slice(), "{rel}: the embedded copy differs");
        }
        let names: Vec<&str> = embedded_files().iter().map(|(r, _)| *r).collect();
        let expected: Vec<&str> = files.iter().map(|(r, _)| r.as_str()).collect();
        assert_eq!(names, expected, "embedded files that are not on disk");
    }

    #[test]
    fn lookup_order_beside_then_folder_then_embedded() {
        let dir = std::env::temp_dir().join(format!("voltex-sources-{}", std::process::id()));
        let (graph_dir, wgsl) = (dir.join("g"), dir.join("wgsl"));
        std::fs::create_dir_all(graph_dir.join("shared")).unwrap();
        std::fs::create_dir_all(&wgsl).unwrap();
        std::fs::write(graph_dir.join("tint.wgsl"), "// beside\n").unwrap();
        std::fs::write(wgsl.join("tint.wgsl"), "// project\n").unwrap();
        std::fs::write(wgsl.join("composite.wgsl"), "// project composite\n").unwrap();
        let s = Sources { dirs: vec![wgsl.clone()], graphs: None, embedded: true }
            .beside(&graph_dir.join("frame.ron"));
        let tint = s.shader("tint.wgsl").unwrap().unwrap();
        assert_eq!((tint.path, tint.text.as_str()), (graph_dir.join("tint.wgsl"), "// beside\n"));
        let c = s.shader("composite.wgsl").unwrap().unwrap();
        assert_eq!(c.path, wgsl.join("composite.wgsl"));
        let t = s.shader("./shared/types.wgsl").unwrap().unwrap();
        assert_eq!(t.path, Path::new("<embedded>/wgsl/shared/types.wgsl"));
        assert!(t.path.starts_with(EMBEDDED_PREFIX) && t.text == embedded("wgsl/shared/types.wgsl").unwrap());
        assert!(s.shader("nothere.wgsl").unwrap().is_none());
        assert!(s.shader("../wgsl/shared/types.wgsl").unwrap().is_none());
        assert!(Sources::folder(&wgsl).shader("shared/types.wgsl").unwrap().is_none());
        assert_eq!(s.watched_dirs(), vec![graph_dir.clone(), wgsl.clone()]);
        let g = s.graph("frame.ron").unwrap().unwrap();
        assert_eq!(g.path, Path::new("<embedded>/graphs/frame.ron"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
