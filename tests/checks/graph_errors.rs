//! Render-graph files through the library (no GPU): parse errors at `file:line:col`, pass order
//! derived from reads and writes, pruning, and new passes added only in RON and WGSL.

use crate::common;

use std::path::{Path, PathBuf};

use voltex::gpu::sources::Sources;
use voltex::graph::plan::{ObjectInfo, Plan};
use voltex::graph::Graph;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn wgsl_root() -> PathBuf {
    root().join("wgsl")
}

/// Plans `g` with its shaders read from the folder `wgsl` only.
fn plan(g: &Graph, wgsl: &Path, objects: &[ObjectInfo]) -> voltex::Result<Plan> {
    voltex::graph::plan::plan(g, &Sources::folder(wgsl), objects, (64, 64), &voltex::render::vocabulary())
}

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-graph-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Passes of `graphs/frame.ron`, one snippet each, so tests can declare them in any order.
const DRAW_BASE: &str = r#"Raster(
            name: "draw_base",
            shader: "base_surface/draw_base.wgsl",
            instances: Objects("BaseSurface"),
            targets: [(resource: "hdr")],
            depth: (resource: "depth", write: true),
            draw: Vertices("base_vertices"),
        )"#;
const COUNT: &str = r#"Compute(
            name: "count_slices",
            shader: "view_slices/count_slices.wgsl",
            instances: Objects("ViewSlices"),
            clear: ["plane_cursors"],
            dispatch: Threads("prisms", "planes", "1"),
        )"#;
const SCAN: &str = r#"Compute(
            name: "scan_plane_offsets",
            shader: "view_slices/scan_plane_offsets.wgsl",
            instances: Objects("ViewSlices"),
            dispatch: Groups("1", "1", "1"),
        )"#;
const EMIT: &str = r#"Compute(
            name: "emit_slices",
            shader: "view_slices/emit_slices.wgsl",
            instances: Objects("ViewSlices"),
            dispatch: Threads("prisms", "planes", "1"),
        )"#;
const DRAW_SLICES: &str = r#"Raster(
            name: "draw_slices",
            shader: "view_slices/draw_slices.wgsl",
            instances: Objects("ViewSlices"),
            targets: [(resource: "hdr", blend: PremultipliedOver)],
            depth: (resource: "depth", write: false),
            draw: Indirect("draw_args"),
        )"#;
const COMPOSITE: &str = r#"Raster(
            name: "composite",
            shader: "composite.wgsl",
            targets: [(resource: "linear")],
            draw: Vertices("3"),
        )"#;

const RESOURCES: &str = r#"
        "hdr": Texture(format: Rgba16Float, size: Output, clear: Color(0.0, 0.0, 0.0, 0.0)),
        "depth": Texture(format: Depth32Float, size: Output, clear: Depth(1.0)),
        "linear": Texture(format: Rgba32Float, size: Output),"#;

/// A graph file text with the given outputs, extra resources and passes.
fn graph_text(outputs: &[&str], extra_resources: &str, passes: &[&str]) -> String {
    let outputs: Vec<String> = outputs.iter().map(|o| format!("\"{o}\"")).collect();
    format!(
        "Graph(\n    outputs: [{}],\n    resources: {{{RESOURCES}{extra_resources}\n    }},\n    passes: [\n        {},\n    ],\n)\n",
        outputs.join(", "),
        passes.join(",\n        ")
    )
}

fn parse(text: &str) -> voltex::Result<Graph> {
    Graph::parse(Path::new("test.ron"), text.to_string())
}

fn objects(filters: &[&[&'static str]]) -> Vec<ObjectInfo> {
    filters
        .iter()
        .enumerate()
        .map(|(i, f)| ObjectInfo { name: format!("o{i}"), filters: f.to_vec(), distance: i as f64, order: 0 })
        .collect()
}

fn names(p: &Plan) -> Vec<&str> {
    p.passes.iter().map(|p| p.decl.name()).collect()
}

fn pos(order: &[&str], name: &str) -> usize {
    order.iter().position(|n| *n == name).unwrap_or_else(|| panic!("{name} not in {order:?}"))
}

#[track_caller]
fn assert_err(e: voltex::Error, at: &str, words: &[&str]) {
    let msg = e.to_string();
    assert!(msg.starts_with(&format!("{at}: ")), "expected an error at {at}, got: {msg}");
    for w in words {
        assert!(msg.contains(w), "expected {w:?} in: {msg}");
    }
}

// ---- parsing ----

#[test]
fn frame_graph_parses_and_plans() {
    let g = Graph::load(&root().join("graphs/frame.ron")).unwrap();
    let all: &[&[&str]] = &[
        &["ViewSlices", "ViewSlicesRaster", "BaseSurface"],
        &["ViewSlices", "ViewSlicesTiles"],
        &["Reference"],
        &["ShellMarch"],
        &["AxisSlices", "AxisSlicesBinary"],
        &["AxisSlices", "AxisSlicesBinary", "AxisSlicesBySlice"],
        &["AxisSlices", "AxisSlicesBlended"],
        &["RayMarch"],
        &["RayMarch", "RayMarchPeeling"],
        &["RayMarch", "RayMarchSplatting"],
        &["Volume"],
    ];
    let p = plan(&g, &wgsl_root(), &objects(all)).unwrap();
    assert_eq!(
        names(&p),
        [
            "draw_base",
            "choose_axis_slices",
            "scan_axis_slices",
            "emit_axis_slices",
            "scan_axis_layers",
            "group_axis_slices",
            "draw_axis_slices",
            "count_slices",
            "scan_plane_offsets",
            "emit_slices",
            "draw_slices",
            "bin_slices",
            "scan_tiles",
            "fill_tiles",
            "composite_tiles",
            "blend_tiles",
            "blend_axis_slices",
            "trace_reference",
            "composite_reference",
            "march_shell",
            "composite_shell_march",
            "bake_transfer",
            "begin_segments",
            "peel_segments",
            "ray_march",
            "splat_segments",
            "resolve_splats",
            "composite_ray_march",
            "march_volume",
            "composite_volume",
            "composite"
        ]
    );
    // Only the AOV passes, which no render asked for, are pruned.
    let aov = ["aov_", "cover_", "depth_", "resolve_"];
    assert!(p.pruned.iter().all(|r| aov.iter().any(|a| r.contains(a))), "{:?}", p.pruned);
    // Asked for, the AOV passes come after the passes they repeat or whose results they read.
    let mut with_aovs = g.clone();
    for a in g.file.aovs.values() {
        with_aovs.file.outputs.extend(a.textures.iter().cloned());
    }
    let p = plan(&with_aovs, &wgsl_root(), &objects(all)).unwrap();
    let order = names(&p);
    for (before, after) in [
        ("draw_axis_slices", "cover_base"),
        ("blend_axis_slices", "cover_blended_axis_slices"),
        ("cover_base", "cover_axis_slices"),
        ("cover_slices", "cover_blended_axis_slices"),
        ("cover_reference", "cover_ray_march"),
        ("ray_march", "resolve_depth"),
        ("trace_reference", "resolve_depth"),
        ("depth_slices", "resolve_depth"),
        ("composite_ray_march", "resolve_transmittance"),
    ] {
        assert!(pos(&order, before) < pos(&order, after), "{before} after {after}: {order:?}");
    }
    assert!(p.pruned.is_empty(), "{:?}", p.pruned);
    // Without Reference objects its passes and layer go.
    let p = plan(&g, &wgsl_root(), &objects(&[&["ViewSlices", "BaseSurface"]])).unwrap();
    assert!(!names(&p).contains(&"trace_reference"), "{:?}", names(&p));
    assert!(p.pruned.iter().any(|r| r.contains("reference_rgba")), "{:?}", p.pruned);
}

#[test]
fn malformed_ron_is_reported_at_line_col() {
    let text = graph_text(&["linear"], "", &[COMPOSITE]);
    // Drop the closing parenthesis of the composite pass's target tuple.
    let broken = text.replacen("(resource: \"linear\")]", "(resource: \"linear\"]", 1);
    assert_ne!(broken, text);
    let line = broken.lines().position(|l| l.contains("(resource: \"linear\"]")).unwrap() + 1;
    let col = broken.lines().nth(line - 1).unwrap().find(']').unwrap() + 1;
    let e = parse(&broken).unwrap_err();
    assert_err(e, &format!("test.ron:{line}:{col}"), &[]);

    let e = parse("Graph(\n    outputs: [\"linear\"],\n").unwrap_err();
    assert!(e.to_string().starts_with("test.ron:"), "{e}");
}

#[test]
fn unknown_pass_field_lists_expected_names() {
    let pass = COMPOSITE.replace("shader:", "shadr:");
    let text = graph_text(&["linear"], "", &[&pass]);
    let line = text.lines().position(|l| l.contains("shadr")).unwrap() + 1;
    let e = parse(&text).unwrap_err();
    assert_err(e, &format!("test.ron:{line}:13"), &["shadr", "name", "shader", "targets", "draw"]);
}

#[test]
fn unknown_object_filter_is_reported_at_the_filter() {
    let pass = EMIT.replace("Objects(\"ViewSlices\")", "Objects(\"Spheres\")");
    let text = graph_text(&["linear"], "", &[COMPOSITE, &pass]);
    let line = text.lines().position(|l| l.contains("Spheres")).unwrap() + 1;
    let col = text.lines().nth(line - 1).unwrap().find("\"Spheres").unwrap() + 1;
    // The graph core names no method: the filter is checked when planning against the runtime's
    // vocabulary, still before any GPU work.
    let g = parse(&text).unwrap();
    let e = plan(&g, &wgsl_root(), &[]).err().unwrap();
    assert_err(e, &format!("test.ron:{line}:{col}"), &["Spheres", "ViewSlices", "BaseSurface"]);
}

#[test]
fn undeclared_render_target_is_an_error() {
    let pass = COMPOSITE.replace("(resource: \"linear\")", "(resource: \"final\")");
    let text = graph_text(&["linear"], "", &[&pass]);
    let line = text.lines().position(|l| l.contains("\"final\"")).unwrap() + 1;
    let col = text.lines().nth(line - 1).unwrap().find("\"final\"").unwrap() + 1;
    let e = parse(&text).unwrap_err();
    assert_err(e, &format!("test.ron:{line}:{col}"), &["render target `final`", "resources"]);
    // A depth target too.
    let pass = DRAW_BASE.replace("(resource: \"depth\"", "(resource: \"zbuf\"");
    let e = parse(&graph_text(&["linear"], "", &[&pass])).unwrap_err();
    assert!(e.to_string().contains("`zbuf`"), "{e}");
}

#[test]
fn empty_outputs_is_an_error() {
    let e = parse(&graph_text(&[], "", &[COMPOSITE])).unwrap_err();
    assert!(e.to_string().starts_with("test.ron:"), "{e}");
    assert!(e.to_string().contains("outputs"), "{e}");
}

#[test]
fn duplicate_pass_name_is_an_error() {
    let e = parse(&graph_text(&["linear"], "", &[COMPOSITE, COMPOSITE])).unwrap_err();
    assert!(e.to_string().contains("declared twice"), "{e}");
}

#[test]
fn missing_shader_is_reported_at_the_graph() {
    let pass = COMPOSITE.replace("composite.wgsl", "nothere.wgsl");
    let text = graph_text(&["linear"], "", &[&pass]);
    let line = text.lines().position(|l| l.contains("nothere")).unwrap() + 1;
    let col = text.lines().nth(line - 1).unwrap().find('"').unwrap() + 1;
    let g = parse(&text).unwrap();
    let e = plan(&g, &wgsl_root(), &[]).err().unwrap();
    assert_err(e, &format!("test.ron:{line}:{col}"), &["nothere.wgsl"]);
}

#[test]
fn missing_entry_point_names_the_pass() {
    let pass = COMPOSITE
        .replace("shader: \"composite.wgsl\",", "shader: \"composite.wgsl\", fragment: \"fs_nope\",");
    let g = parse(&graph_text(&["linear"], "", &[&pass])).unwrap();
    let e = plan(&g, &wgsl_root(), &[]).err().unwrap();
    let msg = e.to_string();
    assert!(msg.starts_with("test.ron:") && msg.contains("composite") && msg.contains("fs_nope"), "{msg}");
}

#[test]
fn unknown_count_is_an_error_before_any_gpu_work() {
    let pass = COMPOSITE.replace("Vertices(\"3\")", "Vertices(\"tree\")");
    let g = parse(&graph_text(&["linear"], "", &[&pass])).unwrap();
    let e = plan(&g, &wgsl_root(), &[]).err().unwrap();
    let msg = e.to_string();
    assert!(msg.starts_with("test.ron:") && msg.contains("`tree`") && msg.contains("prisms"), "{msg}");
}

// ---- order ----

#[test]
fn order_follows_reads_and_writes_not_declaration() {
    // Shuffled: readers before writers wherever reads/writes decide. count, scan and emit all
    // write `plane_cursors`, so their relative order is the declared one (by design).
    let shuffled = [COMPOSITE, DRAW_SLICES, COUNT, SCAN, EMIT, DRAW_BASE];
    let g = parse(&graph_text(&["linear"], "", &shuffled)).unwrap();
    let p = plan(&g, &wgsl_root(), &objects(&[&["ViewSlices"], &["ViewSlices", "BaseSurface"]])).unwrap();
    let order = names(&p);
    assert_eq!(order.len(), 6, "{order:?}");
    let chain = ["count_slices", "scan_plane_offsets", "emit_slices", "draw_slices", "composite"];
    for w in chain.windows(2) {
        assert!(pos(&order, w[0]) < pos(&order, w[1]), "{order:?}");
    }
    assert!(pos(&order, "draw_base") < pos(&order, "composite"), "{order:?}");
    assert!(
        pos(&order, "draw_base") < pos(&order, "draw_slices"),
        "draw_slices reads the depth draw_base writes: {order:?}"
    );
    // Instances run back to front (largest distance first).
    let ds = &p.passes[pos(&order, "draw_slices")];
    assert_eq!(ds.instances.as_deref(), Some(&[1, 0][..]));
    let comp = &p.passes[pos(&order, "composite")];
    assert!(comp.instances.is_none());
}

#[test]
fn a_cycle_is_an_error_naming_the_passes() {
    let dir = temp_dir("cycle");
    let w = dir.join("wgsl");
    std::fs::create_dir_all(&w).unwrap();
    for (file, read, write) in [("a.wgsl", "x", "y"), ("b.wgsl", "y", "x"), ("c.wgsl", "x", "z")] {
        std::fs::write(
            w.join(file),
            format!(
                "// Test kernel.\n@group(0) @binding(0) var<storage, read> {read}: array<u32>;\n\
                 @group(0) @binding(1) var<storage, read_write> {write}: array<u32>;\n\
                 @compute @workgroup_size(1)\nfn main() {{ {write}[0] = {read}[0]; }}\n"
            ),
        )
        .unwrap();
    }
    let text = r#"Graph(
    outputs: ["x", "y", "z"],
    passes: [
        Compute(name: "pass_a", shader: "a.wgsl", dispatch: Groups("1", "1", "1")),
        Compute(name: "pass_b", shader: "b.wgsl", dispatch: Groups("1", "1", "1")),
        Compute(name: "pass_c", shader: "c.wgsl", dispatch: Groups("1", "1", "1")),
    ],
)
"#;
    let g = parse(text).unwrap();
    let e = plan(&g, &w, &[]).err().unwrap();
    let msg = e.to_string();
    assert_err(e, "test.ron:4:23", &["pass_a", "pass_b", "depend on each other"]);
    // pass_c only waits for the cycle; it is not part of it.
    assert!(!msg.contains("pass_c"), "{msg}");
}

// ---- pruning ----

#[test]
fn slicing_passes_are_pruned_without_view_slices_objects() {
    let g = Graph::load(&root().join("graphs/frame.ron")).unwrap();
    let p = plan(&g, &wgsl_root(), &objects(&[&["BaseSurface"]])).unwrap();
    assert_eq!(names(&p), ["draw_base", "composite"]);
    for pass in ["count_slices", "scan_plane_offsets", "emit_slices", "draw_slices"] {
        assert!(
            p.pruned.iter().any(|l| l.contains(pass) && l.contains("ViewSlices")),
            "{pass}: {:?}",
            p.pruned
        );
    }
    // And the base pass without base surfaces.
    let p = plan(&g, &wgsl_root(), &objects(&[&["ViewSlices"]])).unwrap();
    assert!(!names(&p).contains(&"draw_base"));
    assert!(p.pruned.iter().any(|l| l.contains("draw_base")));
}

#[test]
fn passes_and_resources_reaching_no_output_are_pruned() {
    // The debug output: only the slice polygons; draw_slices and composite are not needed, and
    // neither are the textures.
    let text = graph_text(
        &["slice_vertices", "draw_args"],
        "\n        \"unused\": Texture(format: Rgba8Unorm, size: Fixed(4, 4)),",
        &[COUNT, SCAN, EMIT, DRAW_SLICES, COMPOSITE],
    );
    let g = parse(&text).unwrap();
    let p = plan(&g, &wgsl_root(), &objects(&[&["ViewSlices"]])).unwrap();
    assert_eq!(names(&p), ["count_slices", "scan_plane_offsets", "emit_slices"]);
    for pass in ["draw_slices", "composite"] {
        assert!(
            p.pruned.iter().any(|l| l == &format!("pass {pass}: nothing it writes reaches an output")),
            "{pass}: {:?}",
            p.pruned
        );
    }
    assert!(p.textures.is_empty(), "{:?}", p.textures.keys());
    for r in ["hdr", "depth", "linear", "unused"] {
        assert!(p.pruned.iter().any(|l| l.starts_with(&format!("resource {r}:"))), "{r}: {:?}", p.pruned);
    }
}

#[test]
fn unused_texture_is_pruned_in_the_full_frame() {
    let text = graph_text(
        &["linear"],
        "\n        \"spare\": Texture(format: Rgba8Unorm),",
        &[DRAW_BASE, COUNT, SCAN, EMIT, DRAW_SLICES, COMPOSITE],
    );
    let g = parse(&text).unwrap();
    let p = plan(&g, &wgsl_root(), &objects(&[&["ViewSlices"]])).unwrap();
    assert!(!p.textures.contains_key("spare"));
    assert!(p.textures.contains_key("hdr") && p.textures.contains_key("linear"));
    assert!(p.pruned.contains(&"resource spare: no kept pass uses it".to_string()));
}

// ---- a new pass in RON + WGSL only ----

/// A copy of `wgsl/` with extra files.
fn wgsl_copy(test: &str, extra: &[(&str, &str)]) -> PathBuf {
    let dir = temp_dir(test).join("wgsl");
    common::copy_dir(&wgsl_root(), &dir);
    for (name, text) in extra {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

const POST: &str = r#"// Test post effect: inverts the linear image.
#include "shared/types.wgsl"

@group(0) @binding(3) var<uniform> frame: FrameParams;
@group(0) @binding(0) var linear: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(linear, vec2<i32>(pixel.xy), 0);
    return vec4<f32>(frame.background.rgb + 1.0 - c.rgb, 1.0);
}
"#;

const POST_PASS: &str = r#"Raster(
            name: "invert",
            shader: "invert.wgsl",
            targets: [(resource: "final")],
            draw: Vertices("3"),
        )"#;

#[test]
fn new_pass_from_ron_and_wgsl_is_planned_with_reflected_bindings() {
    let wgsl = wgsl_copy("post", &[("invert.wgsl", POST)]);
    let text = graph_text(
        &["final"],
        "\n        \"final\": Texture(format: Rgba8Unorm),",
        // Declared first: order comes from `linear`.
        &[POST_PASS, DRAW_BASE, COUNT, SCAN, EMIT, DRAW_SLICES, COMPOSITE],
    );
    let g = parse(&text).unwrap();
    let p = plan(&g, &wgsl, &objects(&[&["ViewSlices"]])).unwrap();
    let order = names(&p);
    assert_eq!(order.last(), Some(&"invert"), "{order:?}");
    assert!(order.contains(&"composite"), "{order:?}");
    let inv = p.passes.last().unwrap();
    let b: Vec<(&str, u32)> = inv.bindings.iter().map(|b| (b.name.as_str(), b.binding)).collect();
    assert_eq!(b, [("linear", 0), ("frame", 3)]);
    assert!(inv.reads.contains("linear") && inv.writes.contains("final"));
    assert!(p.textures.contains_key("final") && p.textures.contains_key("linear"));
    assert!(p.kernels().contains("invert.wgsl"));

    // Not an output and nothing reads it: pruned, and `final` with it.
    let text = graph_text(
        &["linear"],
        "\n        \"final\": Texture(format: Rgba8Unorm),",
        &[POST_PASS, COUNT, SCAN, EMIT, DRAW_SLICES, COMPOSITE],
    );
    let p = plan(&parse(&text).unwrap(), &wgsl, &objects(&[&["ViewSlices"]])).unwrap();
    assert!(!names(&p).contains(&"invert"));
    assert!(p.pruned.contains(&"pass invert: nothing it writes reaches an output".to_string()));
    assert!(p.pruned.contains(&"resource final: no kept pass uses it".to_string()));
}

#[test]
fn broken_wgsl_is_reported_at_its_line_col() {
    let broken = POST.replace("let c = textureLoad", "let c = = textureLoad");
    let wgsl = wgsl_copy("broken", &[("invert.wgsl", &broken)]);
    let text =
        graph_text(&["final"], "\n        \"final\": Texture(format: Rgba8Unorm),", &[COMPOSITE, POST_PASS]);
    let e = plan(&parse(&text).unwrap(), &wgsl, &[]).err().unwrap();
    let at = format!("{}:15:13", wgsl.join("invert.wgsl").display());
    assert_err(e, &at, &["WGSL"]);
}

#[test]
fn output_pruned_for_the_scene_is_an_error_at_the_output() {
    // `linear` is written only by a pass for ViewSlices objects: a scene without one prunes it.
    let pass = r#"Raster(
            name: "slices_to_linear",
            shader: "composite.wgsl",
            instances: Objects("ViewSlices"),
            targets: [(resource: "linear")],
            draw: Vertices("3"),
        )"#;
    let text = graph_text(&["linear"], "", &[pass]);
    let g = parse(&text).unwrap();
    assert!(plan(&g, &wgsl_root(), &objects(&[&["ViewSlices"]])).is_ok());
    let Err(e) = plan(&g, &wgsl_root(), &objects(&[&["Reference"]])) else { panic!("the output was pruned") };
    assert_err(e, "test.ron:2:15", &["output `linear`", "no pass kept", "no object matches ViewSlices"]);
}
