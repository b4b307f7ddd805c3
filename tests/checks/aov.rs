//! AOV requests and declarations are checked when planning, before any GPU work: unknown names
//! (from the command line or the scene, with its position), more objects than a per-object AOV
//! holds, objects drawn together asking for a per-object AOV, and malformed `aovs` in a graph.

use std::path::Path;

use voltex::graph::Graph;
use voltex::render::{Blueprint, MethodKind, RenderOptions};
use voltex::scene;

/// A scene of `n` small ViewSlices planes side by side, with `extra` top-level fields.
fn scene(n: usize, extra: &str) -> scene::Scene {
    let nodes: Vec<String> = (0..n)
        .map(|i| {
            format!(
                r#"(name: "p{i}", transform: (translate: ({i}.0, 0.0, 0.0)), surface: Plane(size: (0.5, 0.5), cells: (1, 1)), height: (length: 0.2), texel: "fog", method: ViewSlices(planes: 8))"#
            )
        })
        .collect();
    let src = format!(
        r#"#![enable(implicit_some)]
Scene(
    output: (width: 16, height: 16),
    camera: (eye: (0.0, -4.0, 2.0), target: (0.0, 0.0, 0.0), up: (0.0, 0.0, 1.0)),
    {extra}
    texels: {{ "fog": (resolution: (4, 4, 4), opacity_length: 0.4, source: Constant(color: (0.8, 0.6, 0.4), opacity: 0.5)) }},
    nodes: [{}],
)"#,
        nodes.join(",\n        ")
    );
    scene::parse(&src, Path::new("aovs.ron")).unwrap()
}

fn aovs(names: &[&str]) -> RenderOptions {
    RenderOptions { aovs: Some(names.iter().map(|s| s.to_string()).collect()), ..Default::default() }
}

fn error(s: &scene::Scene, opts: RenderOptions) -> String {
    match Blueprint::new(s, &opts) {
        Ok(_) => panic!("planned"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn aovs_are_planned_only_when_asked_for() {
    let s = scene(2, "");
    let bp = Blueprint::new(&s, &RenderOptions::default()).unwrap();
    assert!(bp.aovs.is_empty());
    assert!(!bp.plan.passes.iter().any(|p| p.decl.name().starts_with("cover_")));
    let bp = Blueprint::new(&s, &aovs(&["coverage", "depth", "depth"])).unwrap();
    let names: Vec<&str> = bp.aovs.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["coverage", "depth"]);
    let channels: Vec<Option<&str>> = bp.aovs[0].channels.iter().map(|c| c.as_deref()).collect();
    assert_eq!(channels, [Some("coverage.p0.Y"), Some("coverage.p1.Y"), None, None, None, None]);
    let kept: Vec<&str> = bp.plan.passes.iter().map(|p| p.decl.name()).collect();
    for pass in ["cover_slices", "depth_slices", "resolve_depth"] {
        assert!(kept.contains(&pass), "{pass} not in {kept:?}");
    }
    assert!(!kept.contains(&"resolve_transmittance"), "{kept:?}");
}

#[test]
fn an_unknown_aov_is_an_error_naming_the_known_ones() {
    let e = error(&scene(1, ""), aovs(&["normals"]));
    assert!(
        e.contains("unknown AOV `normals`") && e.contains(r#"["coverage", "depth", "transmittance"]"#),
        "{e}"
    );
    // From the scene file: at its `aovs` field.
    let e = error(&scene(1, r#"aovs: ["depth", "normals"],"#), RenderOptions::default());
    assert!(e.starts_with("aovs.ron:5:5: unknown AOV `normals`"), "{e}");
}

#[test]
fn per_object_aovs_have_limits() {
    let e = error(&scene(7, ""), aovs(&["coverage"]));
    assert!(e.contains("AOV `coverage` holds 6 objects") && e.contains("this scene has 7"), "{e}");
    assert!(Blueprint::new(&scene(7, ""), &aovs(&["depth", "transmittance"])).is_ok());
    // The Reference method draws all its objects in one instance: one layer for all.
    let reference =
        RenderOptions { method: Some(MethodKind::named("Reference").unwrap()), ..aovs(&["coverage"]) };
    let e = error(&scene(2, ""), reference.clone());
    assert!(e.contains("drawn together in one layer") && e.contains(r#"["p0", "p1"]"#), "{e}");
    assert!(Blueprint::new(&scene(1, ""), &reference).is_ok());
}

#[test]
fn malformed_aov_declarations_are_graph_errors_at_line_col() {
    let frame = std::fs::read_to_string(voltex::project_root().join("graphs/frame.ron")).unwrap();
    let cases = [
        (r#"channels: Named(["Z"])"#, r#"channels: Named(["A"])"#, "channel `A` is written by the colour"),
        (
            r#"textures: ["aov_depth"]"#,
            r#"textures: ["hdr_missing"]"#,
            "`hdr_missing` must be an R32Float or Rgba32Float texture",
        ),
        (
            r#"textures: ["aov_depth"]"#,
            r#"textures: ["depth"]"#,
            "`depth` must be an R32Float or Rgba32Float texture",
        ),
        (
            r#"channels: Named(["Z"])"#,
            r#"channels: Named(["Z", "W"])"#,
            "names 2 channels; its textures hold 1",
        ),
    ];
    for (from, to, words) in cases {
        let text = frame.replacen(from, to, 1);
        let e = Graph::parse(Path::new("g.ron"), text.clone())
            .err()
            .unwrap_or_else(|| panic!("{to} parsed"))
            .to_string();
        assert!(e.starts_with("g.ron:") && e.contains(words), "{to}: {e}");
        let line: usize = e.split(':').nth(1).unwrap().parse().unwrap();
        assert!(text.lines().nth(line - 1).unwrap().contains("\"depth\": ("), "{to}: {e} is not at the AOV");
    }
}
