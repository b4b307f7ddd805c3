//! Lenient parsing and late failures (issue 19): an unknown field in any struct, a key or field
//! written twice, invalid UTF-8 at any offset of any text file, and node names that EXR
//! metadata cannot hold (what `plan` accepts, the EXR written last must hold).

use super::hostile::{edit, example, planned, Tree, FLAT};
use super::{files, root};
use crate::fuzz_support::runner::{accepted, fuzz, SMALL};
use crate::fuzz_support::special;
use crate::fuzz_support::{check_error, ron_items};

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::render::RenderOptions;
use voltex::Error;

/// Every example scene and graph with its text.
fn examples() -> Vec<(PathBuf, String)> {
    let mut paths = files(&root().join("scenes"), "ron");
    paths.extend(files(&root().join("graphs"), "ron"));
    paths.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

fn is_graph(path: &Path) -> bool {
    path.parent().is_some_and(|d| d.ends_with("graphs"))
}

/// Parses `text` as the scene or graph `path` is; `Ok(true)`: accepted; `Ok(false)`: a parse
/// error with its position (checked strictly).
fn parses(path: &Path, text: &str) -> Result<bool, String> {
    let result = match is_graph(path) {
        true => voltex::graph::Graph::parse(path, text.to_string()).map(drop),
        false => voltex::scene::parse(text, path).map(drop),
    };
    match result {
        Ok(()) => Ok(true),
        Err(e) => check_error(&e, path, text, true).map(|()| false),
    }
}

#[test]
fn unknown_fields() {
    let all = examples();
    let strategy = (any::<Index>(), any::<Index>(), any::<bool>());
    fuzz("unknown_fields", 400, SMALL, strategy, |(file, at, before_close)| {
        let (path, text) = &all[file.index(all.len())];
        let open = ron_items::openings(text);
        let k = open[at.index(open.len())];
        // Right after `(`, or as the last field before its `)`: both must be refused.
        let text = match before_close {
            false => format!("{}fuzz_unknown: 0, {}", &text[..k], &text[k..]),
            true => {
                let end = ron_items::closing(text, k);
                let inside = text[k..end].trim_end();
                let sep = if inside.is_empty() || inside.ends_with(',') { "" } else { ", " };
                format!("{}{sep}fuzz_unknown: 0{}", &text[..end], &text[end..])
            }
        };
        match parses(path, &text)? {
            true => Err(format!("an unknown field was accepted:\n{text}")),
            false => Ok(()),
        }
    });
}

#[test]
fn duplicate_keys() {
    let all = examples();
    fuzz("duplicate_keys", 400, SMALL, (any::<Index>(), any::<Index>()), |(file, at)| {
        let (path, text) = &all[file.index(all.len())];
        let items = ron_items::items(text);
        let item = items[at.index(items.len())];
        let text = ron_items::duplicate(text, item);
        match parses(path, &text)? {
            true => Err(format!("a duplicate key was accepted:\n{text}")),
            false => Ok(()),
        }
    });
}

/// Bytes that are not UTF-8 (alone, or cut short), and where they go.
const BAD_UTF8: &[&[u8]] =
    &[b"\xff", b"\x80", b"\xc3\x28", b"\xe2\x82", b"\xed\xa0\x80", b"\xf8\x88\x80\x80\x80", b"\xc0\xaf"];

/// Invalid UTF-8 at a random offset of a scene, graph, kernel, include or OBJ file, read from
/// disk: the error names the file and the line of the first bad byte.
#[test]
fn invalid_utf8() {
    let tree = Tree::new("utf8");
    let scenes = files(&root().join("scenes"), "ron");
    let objs = files(&root().join("scenes"), "obj");
    let kernels = files(&root().join("wgsl"), "wgsl");
    let strategy = (0..4u8, any::<Index>(), any::<Index>(), prop::sample::select(BAD_UTF8), any::<bool>());
    fuzz("invalid_utf8", 300, SMALL, strategy, |(kind, file, at, bad, overwrite)| {
        let (source, rel) = match kind {
            0 => (scenes[file.index(scenes.len())].clone(), "scene.ron".to_string()),
            1 => (root().join("graphs/frame.ron"), "frame.ron".to_string()),
            2 => {
                let k = &kernels[file.index(kernels.len())];
                (k.clone(), k.strip_prefix(root().join("wgsl")).unwrap().display().to_string())
            }
            _ => (objs[file.index(objs.len())].clone(), "mesh.obj".to_string()),
        };
        let mut bytes = std::fs::read(&source).unwrap();
        let k = at.index(bytes.len() + 1);
        let end = if overwrite { (k + bad.len()).min(bytes.len()) } else { k };
        bytes.splice(k..end, bad.iter().copied());
        let valid = match std::str::from_utf8(&bytes) {
            Ok(_) => return Ok(()),
            Err(e) => e.valid_up_to(),
        };
        let line = bytes[..valid].iter().filter(|&&b| b == b'\n').count() + 1;
        let path = tree.dir.join(&rel);
        let result = tree.with_file(&rel, &bytes, || match kind {
            0 => voltex::scene::load(&path).map(drop),
            1 => voltex::graph::Graph::load(&path).map(drop),
            2 => {
                let sources = voltex::gpu::sources::Sources::folder(&tree.dir);
                voltex::gpu::shader::load_from(&sources, &rel).map(drop)
            }
            _ => voltex::mesh::load(&path).map(drop),
        });
        match result {
            Err(Error::At { loc, message }) if loc.path == path && loc.line == line => {
                match message.contains("UTF-8") {
                    true => Ok(()),
                    false => Err(format!("{}: {message}", loc)),
                }
            }
            Err(e) => Err(format!("expected an error at {}:{line}: {e}", path.display())),
            Ok(()) => Err("invalid UTF-8 was accepted".into()),
        }
    });
}

fn node_name() -> impl Strategy<Value = String> {
    let char = prop_oneof![
        4 => prop::char::range('a', 'z'),
        2 => prop::char::range('\u{a0}', '\u{ff}'),
        1 => prop::char::range('\u{80}', '\u{9f}'),
        1 => prop::sample::select(vec!['漢', '🎉', '\u{301}', '\u{0}', '"', '\\', ' ', '\u{ffff}', '\u{100}']),
    ];
    prop_oneof![
        prop::collection::vec(char, 0..300).prop_map(|c| c.into_iter().collect()),
        (
            prop::sample::select(vec!['n', 'é', 'ÿ', '漢']),
            prop::sample::select(vec![1usize, 120, 121, 240, 241, 242, 255, 256])
        )
            .prop_map(|(c, n)| std::iter::repeat_n(c, n).collect()),
    ]
}

#[test]
fn node_names() {
    let dir = special::scratch("names");
    let (path, flat) = example(FLAT);
    fuzz("node_names", 300, SMALL, node_name(), |name| {
        let escaped = name.replace('\\', "\\\\").replace('"', "\\\"");
        let text = edit(&flat, "name: \"box\"", &format!("name: \"{escaped}\""));
        let opts = RenderOptions { size: Some((16, 16)), ..Default::default() };
        if planned(&path, &text, &opts)?.is_none() {
            return Ok(());
        }
        // What `render` writes last: the EXR with the object's name in its metadata.
        let image = voltex::io::Image::new(1, 1);
        let key = format!("voltex_object_{name}");
        match voltex::io::exr::write(&dir.join("x.exr"), &image, &[(&key, "ViewSlices".into())]) {
            Ok(()) => accepted(),
            Err(e) => Err(format!("plan accepted the name {name:?}, the EXR cannot hold it: {e}")),
        }
    });
}
