//! Strict parsing of scene and graph files (issue 19): unknown fields in every serde type,
//! duplicate map keys and empty sequences are errors at their `line:col`, not silently ignored.

use std::path::{Path, PathBuf};
use voltex::graph::Graph;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// 1-based `line:col` of the `nth` (0-based) occurrence of `needle` in `text`.
fn at(text: &str, needle: &str, nth: usize) -> String {
    let i =
        text.match_indices(needle).nth(nth).unwrap_or_else(|| panic!("{needle:?} #{nth} not in the text")).0;
    let (line, col) = voltex::error::line_col(text, i);
    format!("{line}:{col}")
}

fn replaced(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} not in the text");
    text.replacen(from, to, 1)
}

#[track_caller]
fn scene_err(text: &str, loc: &str, words: &[&str]) {
    let e = match voltex::scene::parse(text, Path::new("s.ron")) {
        Ok(_) => panic!("expected an error at {loc}"),
        Err(e) => e.to_string(),
    };
    assert!(e.starts_with(&format!("s.ron:{loc}: ")), "expected an error at {loc}, got: {e}");
    for w in words {
        assert!(e.contains(w), "expected {w:?} in: {e}");
    }
}

#[track_caller]
fn graph_err(text: &str, loc: &str, words: &[&str]) {
    let e = match Graph::parse(Path::new("g.ron"), text.to_string()) {
        Ok(_) => panic!("expected an error at {loc}"),
        Err(e) => e.to_string(),
    };
    assert!(e.starts_with(&format!("g.ron:{loc}: ")), "expected an error at {loc}, got: {e}");
    for w in words {
        assert!(e.contains(w), "expected {w:?} in: {e}");
    }
}

fn hyper_scene() -> String {
    std::fs::read_to_string(root().join("scenes/hard_cases/noise_far.ron")).unwrap()
}

fn frame_graph() -> String {
    std::fs::read_to_string(root().join("graphs/frame.ron")).unwrap()
}

/// Every type deserialized from a scene or graph file denies unknown fields (or is a transparent
/// wrapper): the types are found by walking the sources, so a new one cannot be forgotten.
#[test]
fn every_file_type_denies_unknown_fields() {
    let mut missing = Vec::new();
    let mut seen = 0;
    for rel in ["src/scene/types.rs", "src/scene/hypertexture.rs", "src/graph/mod.rs"] {
        let text = std::fs::read_to_string(root().join(rel)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            if !(l.contains("derive(") && l.contains("Deserialize")) {
                continue;
            }
            seen += 1;
            // The attributes from the derive down to the item.
            let item = (i..lines.len()).find(|&j| !lines[j].trim_start().starts_with("#[")).unwrap();
            let attrs = lines[i..item].join("\n");
            if !attrs.contains("deny_unknown_fields") && !attrs.contains("transparent") {
                missing.push(format!("{rel}:{}: {}", item + 1, lines[item].trim()));
            }
        }
    }
    assert!(seen > 40, "found only {seen} Deserialize types: has the layout changed?");
    assert!(missing.is_empty(), "types without #[serde(deny_unknown_fields)]:\n{}", missing.join("\n"));
}

#[test]
fn misspelt_fields_in_transfers_are_errors() {
    // ColorTransfer::Step: a misspelt `opacity` was silently the default.
    let text = replaced(&hyper_scene(), "opacity: 1.0)", "opactiy: 0.0)");
    scene_err(&text, &at(&text, "opactiy", 0), &["opactiy", "opacity"]);
    // ShapeTransfer::Image.
    let text = replaced(
        &hyper_scene(),
        "shape: Curve([(0.0, 0.0, 1.0), (1.0, 1.0, 1.0)])",
        "shape: Image(path: \"t.png\", rows: [])",
    );
    scene_err(&text, &at(&text, "rows", 0), &["rows", "path"]);
}

#[test]
fn misspelt_field_in_a_depth_sorted_draw_is_an_error() {
    let text = frame_graph();
    let i = text.find("DepthSorted(").expect("frame.ron has a DepthSorted draw");
    let text = format!("{}DepthSorted(hole: \"x\", {}", &text[..i], &text[i + "DepthSorted(".len()..]);
    graph_err(&text, &at(&text, "hole", 0), &["hole", "whole"]);
}

#[test]
fn duplicate_keys_are_errors_at_the_second() {
    // ron positions the error at the key's text, just inside its opening quote.
    let text = replaced(&hyper_scene(), "\"e3\":", "\"origin\":");
    scene_err(&text, &at(&text, "origin\":", 1), &["\"origin\" is declared twice"]);
    let text = frame_graph();
    let first = text.find("resources: {").expect("frame.ron declares resources") + "resources: {".len();
    let text =
        format!("{}\n        \"hdr\": Texture(format: Rgba16Float),{}", &text[..first], &text[first..]);
    graph_err(&text, &at(&text, "hdr\":", 1), &["\"hdr\" is declared twice"]);
}

#[test]
fn an_empty_sequence_is_an_error_at_its_list() {
    let text = r#"Scene(
    output: (width: 8, height: 8),
    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),
    texels: {
        "t": (resolution: (8, 8, 8), source: Sequence(texels: [], fps: 1.0)),
    },
)
"#;
    let e = voltex::scene::parse(text, Path::new("s.ron")).unwrap_err().to_string();
    assert!(e.starts_with("s.ron:5:"), "{e}");
    assert!(e.contains("expected at least one texel name in a sequence"), "{e}");
}
