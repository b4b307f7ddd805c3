//! One meaning per name: the types named by the design's vocabulary (`../shared/DESIGN.md`) and
//! the words a reader meets in every layer are declared once in the library, so `Volume` or
//! `Lighting` means one thing wherever it is read. (Per-command names such as `Args` or `Row`,
//! private to their module and never imported next to each other, are not checked.)

use std::collections::BTreeMap;
use std::path::Path;

use crate::layers::rust_files;

/// Names that may be declared once (`struct`, `enum`, `type` or `trait`, any visibility).
const ONE_MEANING: &[&str] = &[
    "Texel",
    "Prism",
    "Shell",
    "Method",
    "Scene",
    "Graph",
    "Plan",
    "Volume",
    "Shape",
    "Lighting",
    "Light",
    "View",
    "Truth",
    "Voxels",
    "Camera",
    "Frame",
    "Hypertexture",
    "Noise",
    "Field",
    "Surface",
    "Object",
    "Bake",
    "Baked",
    "Blueprint",
    "Renderer",
    "Record",
    "Status",
    "Shard",
    "Switch",
];

/// Where each of `ONE_MEANING`'s names is declared in `src/`, as `file:line`.
fn declarations() -> BTreeMap<String, Vec<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let mut words =
                line.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty());
            let Some(kind) = words.find(|w| ["struct", "enum", "type", "trait"].contains(w)) else {
                continue;
            };
            let before = &line[..line.find(kind).unwrap()];
            // A declaration starts the line (after its visibility), not a use in an expression.
            let head = before.trim_start();
            if !(head.is_empty() || head.starts_with("pub")) {
                continue;
            }
            if let Some(name) = words.next().filter(|w| ONE_MEANING.contains(w)) {
                let rel = file.strip_prefix(&src).unwrap().display();
                out.entry(name.to_string()).or_default().push(format!("src/{rel}:{}", n + 1));
            }
        }
    }
    out
}

#[test]
fn vocabulary_types_have_one_meaning() {
    let found = declarations();
    assert!(found.contains_key("Scene") && found.contains_key("Volume"), "is the scan broken? {found:?}");
    let twice: Vec<String> = found
        .iter()
        .filter(|(_, places)| places.len() > 1)
        .map(|(name, places)| format!("{name}: {}", places.join(", ")))
        .collect();
    assert!(twice.is_empty(), "a type name declared more than once (rename one):\n{}", twice.join("\n"));
}
