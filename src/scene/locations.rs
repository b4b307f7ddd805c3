//! Where a scene file writes the values planning may refuse (the output size, the AOV list, each
//! texel's resolution, each node): found once, when the file is parsed, so that a planning error
//! (a method's knob past a device limit, a texel beyond the memory budget) is placed at its
//! `file:line:col` without reading or parsing the file again.

use crate::error::FileLoc;
use crate::scene::{Node, Scene};

/// Positions in the scene file, by what they hold.
#[derive(Debug, Clone, Default)]
pub(crate) struct Locations {
    /// The `output` field.
    pub(crate) output: Option<FileLoc>,
    /// The `aovs` field.
    pub(crate) aovs: Option<FileLoc>,
    /// Each texel's `resolution` (its name where none is written).
    pub(crate) texels: Vec<(String, FileLoc)>,
    /// Each node's name.
    pub(crate) objects: Vec<(String, FileLoc)>,
}

impl Locations {
    /// The positions in `src`, the text `scene` was parsed from.
    pub(super) fn of(scene: &Scene, src: &str) -> Self {
        let loc = |at: usize| {
            let (line, col) = crate::error::line_col(src, at);
            FileLoc::new(&scene.path, line, col)
        };
        let texels_at = find_key(src, 0, "texels").unwrap_or(0);
        let texels = (scene.texels.keys())
            .filter_map(|name| {
                let key = find_key(src, texels_at, &format!("\"{name}\""))?;
                Some((name.clone(), loc(find_key(src, key, "resolution").unwrap_or(key))))
            })
            .collect();
        let nodes_at = find_key(src, 0, "nodes").unwrap_or(0);
        let mut names = Vec::new();
        collect_names(&scene.nodes, &mut names);
        let objects = (names.into_iter())
            .filter_map(|name| {
                let i = src[nodes_at..].find(&format!("\"{name}\""))?;
                Some((name.to_string(), loc(nodes_at + i)))
            })
            .collect();
        Locations {
            output: find_key(src, 0, "output").map(loc),
            aovs: top_level_key(src, "aovs").map(loc),
            texels,
            objects,
        }
    }
}

fn collect_names<'a>(nodes: &'a [Node], out: &mut Vec<&'a str>) {
    for n in nodes {
        out.push(&n.name);
        collect_names(&n.children, out);
    }
}

/// Byte offset of `key` used as a field or map key (followed by `:`) at or after `from`.
fn find_key(src: &str, from: usize, key: &str) -> Option<usize> {
    let mut at = from.min(src.len());
    while let Some(i) = src[at..].find(key) {
        let start = at + i;
        let end = start + key.len();
        let ident = |c: char| c.is_alphanumeric() || c == '_';
        let before_ok = !key.starts_with(ident) || !src[..start].ends_with(ident);
        if before_ok && src[end..].trim_start().starts_with(':') {
            return Some(start);
        }
        at = end;
    }
    None
}

/// Byte offset of the field `key` written at the start of a line (`key:`), if it is.
fn top_level_key(src: &str, key: &str) -> Option<usize> {
    let mut offset = 0;
    for line in src.split_inclusive('\n') {
        let t = line.trim_start();
        if t.strip_prefix(key).is_some_and(|rest| rest.trim_start().starts_with(':')) {
            return Some(offset + line.len() - t.len());
        }
        offset += line.len();
    }
    None
}
