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
    let knobs =
        std::fs::read_dir(root().join("src/methods")).unwrap().map(|e| e.unwrap().path().join("knobs.rs"));
    let knobs: Vec<String> = knobs
        .filter(|p| p.exists())
        .map(|p| p.strip_prefix(root()).unwrap().display().to_string())
        .chain(["src/scene/methods.rs".to_string()])
        .collect();
    assert!(knobs.len() >= 5, "the methods' knobs files moved: {knobs:?}");
    let files = ["src/scene/types.rs", "src/scene/hypertexture.rs", "src/graph/mod.rs"].map(String::from);
    for rel in files.iter().chain(&knobs) {
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

// ---- checks that only the GPU (or the EXR writer) made, now made when the files are read ----

#[test]
fn node_names_must_fit_exr_metadata() {
    let base = std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap();
    let name = base.split("name: \"").nth(1).and_then(|r| r.split('"').next()).expect("a node name");
    let text = replaced(&base, &format!("\"{name}\""), "\"漢\"");
    // ron positions a string's error just inside its opening quote.
    scene_err(&text, &at(&text, "漢\"", 0), &["Latin-1", "EXR metadata"]);
    let long = "n".repeat(250);
    let text = replaced(&base, &format!("\"{name}\""), &format!("\"{long}\""));
    scene_err(&text, &at(&text, &long, 0), &["at most 241 bytes", "found 250"]);
}

/// A graph with one extra texture resource and one raster pass, from `graphs/frame.ron`.
fn frame_with(resource: &str) -> String {
    let text = frame_graph();
    let first = text.find("resources: {").unwrap() + "resources: {".len();
    format!("{}\n        {resource},{}", &text[..first], &text[first..])
}

#[test]
fn graph_values_are_checked_when_read() {
    let text = frame_with("\"x\": Texture(format: Depth32Float, clear: Depth(NaN))");
    graph_err(&text, &at(&text, "NaN", 0), &["expected a depth clear value in [0, 1]"]);
    let text = frame_with("\"x\": Texture(format: Rgba16Float, clear: Color(0.0, inf, 0.0, 1.0))");
    graph_err(&text, &at(&text, "inf", 0), &["expected a finite clear value"]);
    let text = frame_with("\"x\": Texture(format: Rgba16Float, clear: Depth(1.0))");
    graph_err(&text, &at(&text, "\"x\"", 0), &["Rgba16Float", "`Color(..)`"]);
    let text = frame_with("\"x\": Texture(format: R32Float, size: Fixed(0, 100000))");
    graph_err(&text, &at(&text, "0, 100000", 0), &["expected a texture side in 1..=16384"]);
}

#[test]
fn raster_targets_are_checked_against_their_formats_and_count() {
    let text = frame_graph();
    // The frame's depth target on a colour texture.
    let depth = text.find("depth: (resource: \"depth\"").expect("a pass with a depth target");
    let text = format!(
        "{}depth: (resource: \"hdr\"{}",
        &text[..depth],
        &text[depth + "depth: (resource: \"depth\"".len()..]
    );
    let e = Graph::parse(Path::new("g.ron"), text.clone()).unwrap_err().to_string();
    let (line, _) = voltex::error::line_col(&text, depth);
    assert!(e.starts_with(&format!("g.ron:{line}:")), "{e}");
    assert!(e.contains("depth target `hdr` needs a depth format (Depth32Float), found Rgba32Float"), "{e}");
    // Nine colour targets.
    let text = frame_graph();
    let t = text.find("targets: [(resource: \"hdr\"").expect("a pass drawing into hdr");
    let nine = ["(resource: \"hdr\")"; 9].join(", ");
    let end = t + text[t..].find(']').unwrap();
    let text = format!("{}targets: [{nine}{}", &text[..t], &text[end..]);
    let e = Graph::parse(Path::new("g.ron"), text).unwrap_err().to_string();
    assert!(e.contains("9 colour targets: at most 8"), "{e}");
}

#[test]
fn kernels_beyond_the_default_limits_are_errors_at_their_wgsl_line() {
    use voltex::gpu::shader::load_str;
    let k = |body: &str| load_str(Path::new("k.wgsl"), body).map(|_| ()).map_err(|e| e.to_string());
    let ok = "@compute @workgroup_size(64)\nfn main() {}\n";
    k(ok).unwrap();
    let e = k("// big\n@compute @workgroup_size(1024, 1024, 64)\nfn main() {}\n").unwrap_err();
    assert!(e.starts_with("k.wgsl:2:10: ") && e.contains("(1024, 1024, 64) is beyond the limits"), "{e}");
    let e = k("@compute @workgroup_size(16, 32)\nfn main() {}\n").unwrap_err();
    assert!(e.contains("256 invocations in all"), "{e}");
    let big = "var<private> big: array<vec4<f32>, 100000000>;\n@compute @workgroup_size(1)\nfn main() { big[0] = vec4(1.0); }\n";
    let e = k(big).unwrap_err();
    assert!(e.starts_with("k.wgsl:1:") && e.contains("var<private> `big` takes 1600000000 bytes"), "{e}");
    let shared =
        "var<workgroup> w: array<f32, 8192>;\n@compute @workgroup_size(1)\nfn main() { w[0] = 1.0; }\n";
    let e = k(shared).unwrap_err();
    assert!(e.starts_with("k.wgsl:1:") && e.contains("workgroup memory to 32768 bytes"), "{e}");
    let local =
        "@compute @workgroup_size(1)\nfn main() {\n    var a: array<u32, 1000000>;\n    a[0] = 1u;\n}\n";
    let e = k(local).unwrap_err();
    assert!(e.starts_with("k.wgsl:3:") && e.contains("var `a` takes 4000000 bytes"), "{e}");
}

// ---- budgets from the counts, before any work ----

#[test]
fn work_over_a_budget_is_refused_from_the_counts() {
    let base = std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap();
    // Inside the documented cell maximum, but 33,554,432 triangles.
    let text = replaced(&base, "cells: (4, 4)", "cells: (4096, 4096)");
    scene_err(&text, &at(&text, "Plane(", 0), &["33554432 base triangles", "at most 2097152"]);
    // More nodes than the budget: the first one past it is named.
    let node = "(name: \"n\", surface: Plane(size: (1.0, 1.0), cells: (1, 1))),\n";
    let nodes = node.repeat(voltex::scene::MAX_NODES + 1);
    let text = format!("Scene(\n    output: (width: 8, height: 8),\n    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),\n    nodes: [\n{nodes}    ],\n)\n");
    let loc = format!("{}:", voltex::scene::MAX_NODES + 5);
    let e = voltex::scene::parse(&text, Path::new("s.ron")).unwrap_err().to_string();
    assert!(e.starts_with(&format!("s.ron:{loc}")) && e.contains("1025 nodes: at most 1024"), "{e}");
    // An Implicit texel: shapes x voxels.
    let sphere = "Sphere(center: (0.5, 0.5, 0.5), radius: 0.3, color: (1.0, 1.0, 1.0)), ";
    let text = format!(
        "Scene(\n    output: (width: 8, height: 8),\n    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),\n    texels: {{\n        \"many\": (resolution: (1024, 1024, 1024), source: Implicit(shapes: [{}])),\n    }},\n)\n",
        sphere.repeat(5)
    );
    scene_err(&text, "5:9", &["texel \"many\": 5 shapes x 1073741824 voxels", "at most 536870912"]);
    // Issue 19: 10,000 spheres at 64^3 took minutes on llvmpipe; the budget is the scene's, so
    // two texels of 1,500 spheres each are over it together (the second is named).
    let texel = |name: &str, n: usize| {
        format!("\"{name}\": (resolution: (64, 64, 64), source: Implicit(shapes: [{}])),\n", sphere.repeat(n))
    };
    let scene = |texels: String| {
        format!("Scene(\n    output: (width: 8, height: 8),\n    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),\n    texels: {{\n{texels}    }},\n)\n")
    };
    scene_err(&scene(texel("many", 10_000)), "5:1", &["10000 shapes x 262144 voxels", "at most 536870912"]);
    let text = scene(texel("a", 1500) + &texel("b", 1500));
    scene_err(&text, "6:1", &["texel \"b\": 1500 shapes", "with 393216000 of the other Implicit texels"]);
    assert!(voltex::scene::parse(&scene(texel("a", 1500)), Path::new("s.ron")).is_ok());
}
