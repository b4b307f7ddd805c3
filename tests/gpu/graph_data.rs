//! Passes and resources from data alone: a copy of `graphs/frame.ron` outside the project, with a
//! luminance histogram (a graph buffer), a compute pass filling it from `hdr`, and a raster pass
//! drawing it as bars over the output, tuned by two graph parameters, each a WGSL file beside the
//! graph: rendered by the `voltex` binary and the library and checked against the CPU; picked up
//! live by the preview's reload; and the errors of sizes and types at `file:line:col`.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use voltex::gpu::cache::CacheStats;
use voltex::io::Image;
use voltex::preview::{Outcome, Session, Watcher};
use voltex::render::{Blueprint, RenderOptions, Renderer};

const SIZE: u32 = 64;
const BINS: usize = 64;

const HISTOGRAM_WGSL: &str = r#"// Counts the pixels of `hdr` per luminance bin (64 bins over [0, 1], the last one open).
@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> luminance_histogram: array<atomic<u32>, 64>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(hdr);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let c = textureLoad(hdr, vec2<i32>(id.xy), 0);
    let l = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    let bin = u32(clamp(l * 64.0, 0.0, 63.0));
    atomicAdd(&luminance_histogram[bin], 1u);
}
"#;

const OVERLAY_WGSL: &str = r#"// Draws `luminance_histogram` over the output: column x is bin x, a bar of count * bar_scale rows from the top.
@group(0) @binding(0) var<storage, read> luminance_histogram: array<u32, 64>;
@group(0) @binding(1) var<uniform> bar_color: vec4<f32>;
@group(0) @binding(2) var<uniform> bar_scale: f32;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<u32>(pixel.xy);
    if (p.x >= 64u || f32(p.y) >= floor(f32(luminance_histogram[p.x]) * bar_scale)) {
        discard;
    }
    return bar_color;
}
"#;

const RESOURCES: &str = r#"
        "luminance_histogram": Buffer(size: Words("64"), clear: Zero),
        "bar_color": Parameter(Vec4(0.1, 0.9, 0.2, 1.0)),
        "bar_scale": Parameter(F32(0.125)),"#;

const PASSES: &str = r#"
        Compute(
            name: "histogram",
            shader: "histogram.wgsl",
            dispatch: Threads("width", "height", "1"),
        ),
        // After `composite` (both write `linear`): bars over the output, the rest kept.
        Raster(
            name: "histogram_overlay",
            shader: "histogram_overlay.wgsl",
            targets: [(resource: "linear")],
            draw: Vertices("3"),
        ),"#;

const COLOR: [f32; 4] = [0.1, 0.9, 0.2, 1.0];
const SCALE: f32 = 0.125;

fn scene_path() -> PathBuf {
    common::root().join("scenes/view_slices/flat_box.ron")
}

fn frame_ron() -> String {
    std::fs::read_to_string(common::root().join("graphs/frame.ron")).unwrap()
}

/// `graphs/frame.ron` with `resources` and `passes` added at the end of their lists.
fn graph_text(resources: &str, passes: &str) -> String {
    let text = frame_ron();
    let anchor = "\"reference_rgba\": Texture(format: Rgba32Float, size: Output),";
    assert!(text.contains(anchor));
    let text = text.replacen(anchor, &format!("{anchor}{resources}"), 1);
    let start = text.find("passes: [").expect("`passes`");
    let end = start + text[start..].find("\n    ],\n").expect("the end of `passes`") + 1;
    format!("{}{passes}\n{}", &text[..end], &text[end..])
}

/// A folder outside the project with the extended graph and its two kernels; returns the graph.
fn write_graph(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("histogram.wgsl"), HISTOGRAM_WGSL).unwrap();
    std::fs::write(dir.join("histogram_overlay.wgsl"), OVERLAY_WGSL).unwrap();
    let graph = dir.join("frame.ron");
    std::fs::write(&graph, graph_text(RESOURCES, PASSES)).unwrap();
    graph
}

fn options(graph: Option<&Path>) -> RenderOptions {
    RenderOptions { size: Some((SIZE, SIZE)), graph: graph.map(Path::to_path_buf), ..Default::default() }
}

/// The luminance bin of a linear premultiplied colour, as `histogram.wgsl` computes it.
fn bin(c: [f32; 4]) -> usize {
    let l = 0.2126f32 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    (l * 64.0).clamp(0.0, 63.0) as usize
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytemuck::pod_collect_to_vec(bytes)
}

/// Checks `image` against `plain` (the default graph's image) and the histogram: bars of the bar
/// colour where the overlay draws, bit-identical pixels elsewhere.
#[track_caller]
fn check_overlay(image: &Image, plain: &Image, histogram: &[u32]) {
    let mut bar_pixels = 0;
    for y in 0..SIZE as usize {
        for (x, &count) in histogram.iter().enumerate().take(SIZE as usize) {
            let i = y * SIZE as usize + x;
            let rows = (count as f32 * SCALE).floor() as usize;
            if y < rows {
                assert_eq!(image.pixels[i], COLOR, "a bar at ({x}, {y})");
                bar_pixels += 1;
            } else {
                assert_eq!(image.pixels[i], plain.pixels[i], "no bar at ({x}, {y})");
            }
        }
    }
    assert!(bar_pixels > 0, "the overlay draws something");
}

/// What `voltex plan` prints for the scene at 64x64, with `graph` or the default one.
fn plan_with(graph: Option<&Path>) -> String {
    let scene = scene_path();
    let mut args = vec!["plan", common::s(&scene), "--size", "64x64"];
    if let Some(g) = graph {
        args.extend(["--graph", common::s(g)]);
    }
    common::ok(common::voltex(&args))
}
#[test]
fn histogram_buffer_and_overlay_from_the_graph_alone() {
    let dir = common::scratch_dir("voltex-graph-data-render");
    assert!(!dir.starts_with(common::root()), "the graph lives outside the project");
    let graph = write_graph(&dir);
    let scene = voltex::scene::load(&scene_path()).unwrap();

    // `voltex plan` shows the new resources and counts them in the memory estimate.
    let plan = plan_with(Some(&graph));
    for s in [
        "histogram            histogram.wgsl",
        "histogram_overlay    histogram_overlay.wgsl",
        "luminance_histogram  buffer 256 bytes (\"64\" x 4), cleared each frame",
        "bar_color            parameter vec4<f32>",
        "bar_scale            parameter f32 = F32(0.125)",
        "buffer luminance_histogram 256 bytes",
    ] {
        assert!(plan.contains(s), "{s:?} not in:\n{plan}");
    }
    let total = |text: &str| -> f64 {
        let line = text.lines().find(|l| l.trim_end().ends_with("MiB  total")).unwrap();
        line.split_whitespace().next().unwrap().parse().unwrap()
    };
    let plain_plan = plan_with(None);
    assert!(!plain_plan.contains("luminance_histogram"));
    // 256 + 16 + 4 bytes more: below the printed precision, so only "not less".
    assert!(total(&plan) >= total(&plain_plan));

    // The library: the histogram read back against one counted on the CPU from `hdr`, twice (the
    // buffer is zeroed each frame, not accumulated).
    let ctx = gpu!(ADAPTER);
    let bp = Blueprint::new(&scene, &options(Some(&graph))).unwrap();
    assert_eq!(bp.plan.buffers["luminance_histogram"].bytes, 256);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    r.render(&ctx).unwrap();
    let frame = r.render(&ctx).unwrap();
    let histogram = words(&r.read_buffer(&ctx, "luminance_histogram").unwrap());
    assert_eq!(histogram.len(), BINS);
    assert_eq!(histogram.iter().sum::<u32>(), SIZE * SIZE, "every pixel counted once: {histogram:?}");
    let hdr = r.read_texture(&ctx, "hdr").unwrap();
    let mut cpu = vec![0u32; BINS];
    for p in &hdr.pixels {
        cpu[bin(*p)] += 1;
    }
    // Pixels right on a bin boundary may round either way (the GPU may fuse the multiply-adds).
    let moved: u32 = histogram.iter().zip(&cpu).map(|(g, c)| g.abs_diff(*c)).sum();
    assert!(moved <= 8, "GPU {histogram:?}\nCPU {cpu:?}");
    assert!(cpu.iter().filter(|&&n| n > 0).count() >= 3, "a few bins in use: {cpu:?}");
    assert_eq!(words(&r.read_buffer(&ctx, "bar_scale").unwrap()), [SCALE.to_bits()]);

    let mut plain = Renderer::new(&ctx, Blueprint::new(&scene, &options(None)).unwrap()).unwrap();
    let plain = plain.render(&ctx).unwrap().image;
    check_overlay(&frame.image, &plain, &histogram);
    drop(ctx);

    // The binary: the same image in the EXR, and the bars in the PNG.
    let exr = dir.join("out.exr");
    let scene_file = scene_path();
    let args = [
        "render",
        common::s(&scene_file),
        "--size",
        "64x64",
        "--graph",
        common::s(&graph),
        "-o",
        common::s(&exr),
    ];
    common::ok(common::voltex(&args));
    let (image, _) = voltex::io::exr::read(&exr).unwrap();
    check_overlay(&image, &plain, &histogram);
    let (w, h, png) = voltex::io::png::read_rgba8(&exr.with_extension("png")).unwrap();
    assert_eq!((w, h), (SIZE, SIZE));
    let x = (0..BINS).max_by_key(|&x| histogram[x]).unwrap();
    let [r, g, b, _] = png[x];
    // Tone-mapped: (0.1, 0.9, 0.2) is about (99, 229, 149).
    assert!(g > 200 && g > r + 60 && g > b + 60, "a green bar at the top of column {x}: {:?}", png[x]);
}

/// The next change the watcher reports that includes `path`, within a few seconds.
fn wait_for(w: &Watcher, path: &Path) {
    let want = std::fs::canonicalize(path).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        let changes = w.changes(Duration::from_millis(200));
        if changes.iter().any(|p| std::fs::canonicalize(p).unwrap_or(p.clone()) == want || *p == want) {
            w.changes(Duration::from_millis(50));
            return;
        }
    }
    panic!("no change reported for {}", path.display());
}

#[test]
fn preview_picks_up_a_new_buffer_and_pass() {
    let dir = common::scratch_dir("voltex-graph-data-preview");
    let graph = dir.join("frame.ron");
    std::fs::write(&graph, frame_ron()).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut s = Session::open(&ctx, &scene_path(), options(Some(&graph)));
    assert!(s.error.is_none(), "{:?}", s.error);
    let plain = s.render(&ctx).unwrap().unwrap().image;
    let w = Watcher::new(&s.watch_dirs()).unwrap();
    assert!(s.renderer().unwrap().read_buffer(&ctx, "luminance_histogram").is_err());

    // The technical artist's edit: two WGSL files beside the graph, then the graph.
    write_graph(&dir);
    wait_for(&w, &graph);
    let o = s.rebuild(&ctx);
    assert!(matches!(o, Outcome::Rebuilt(_)), "{o:?}");
    let image = s.render(&ctx).unwrap().unwrap().image;
    let histogram = words(&s.renderer().unwrap().read_buffer(&ctx, "luminance_histogram").unwrap());
    assert_eq!(histogram.iter().sum::<u32>(), SIZE * SIZE);
    check_overlay(&image, &plain, &histogram);

    // A parameter is tuned live: no module, pipeline or bake made anew.
    let text = std::fs::read_to_string(&graph).unwrap();
    std::fs::write(&graph, text.replace("Parameter(F32(0.125))", "Parameter(F32(0.25))")).unwrap();
    wait_for(&w, &graph);
    assert_eq!(s.rebuild(&ctx), Outcome::Rebuilt(CacheStats::default()));
    let taller = s.render(&ctx).unwrap().unwrap().image;
    let bar = |img: &Image| img.pixels.iter().filter(|p| **p == COLOR).count();
    assert!(bar(&taller) > bar(&image), "{} against {}", bar(&taller), bar(&image));
}

/// The error of planning the flat box through `graph` text (written beside the two kernels).
fn plan_error(name: &str, graph: &str) -> (PathBuf, String) {
    let dir = common::scratch_dir(&format!("voltex-graph-data-{name}"));
    let path = write_graph(&dir);
    std::fs::write(&path, graph).unwrap();
    let scene = voltex::scene::load(&scene_path()).unwrap();
    match Blueprint::new(&scene, &options(Some(&path))) {
        Ok(_) => panic!("{name}: planned without an error"),
        Err(e) => (path, e.to_string()),
    }
}

/// `path:line:col` of the first `needle` in `text`, plus `offset` columns.
fn at(path: &Path, text: &str, needle: &str, offset: usize) -> String {
    let i = text.find(needle).unwrap_or_else(|| panic!("{needle:?} not in the graph"));
    let line = text[..i].matches('\n').count() + 1;
    let col = i - text[..i].rfind('\n').map_or(0, |n| n + 1) + 1 + offset;
    format!("{}:{line}:{col}", path.display())
}

#[track_caller]
fn expect(name: &str, resources: &str, needle: &str, offset: usize, words: &[&str]) {
    let text = graph_text(resources, PASSES);
    let (path, msg) = plan_error(name, &text);
    let loc = at(&path, &text, needle, offset);
    assert!(msg.starts_with(&loc), "{name}: expected {loc} in: {msg}");
    for w in words {
        assert!(msg.contains(w), "{name}: expected {w:?} in: {msg}");
    }
}

#[test]
fn size_and_type_errors_name_the_place() {
    let params = r#"
        "bar_color": Parameter(Vec4(0.1, 0.9, 0.2, 1.0)),
        "bar_scale": Parameter(F32(0.125)),"#;
    let with = |buffer: &str| format!("\n        \"luminance_histogram\": {buffer},{params}");
    // An unknown count, a per-object count, and what is not a size expression: at the very word.
    expect(
        "unknown",
        &with(r#"Buffer(size: Elements(count: "width * depth", stride: 4))"#),
        "\"width * depth\"",
        9,
        &["unknown count `depth`", "[\"width\", \"height\"]"],
    );
    expect(
        "per-object",
        &with(r#"Buffer(size: Words("prisms + 64"))"#),
        "\"prisms + 64\"",
        1,
        &["`prisms` is counted per object"],
    );
    expect("syntax", &with(r#"Buffer(size: Words("width - 1"))"#), "\"width - 1\"", 7, &["found `-`"]);
    // Zero bytes, and fewer bytes than the WGSL type: at the declaration.
    expect(
        "zero",
        &with(r#"Buffer(size: Words("width * 0"))"#),
        "\"luminance_histogram\":",
        0,
        &["is 0 bytes"],
    );
    expect(
        "small",
        &with(r#"Buffer(size: Words("16"))"#),
        "\"luminance_histogram\":",
        0,
        &["is 64 bytes", "histogram.wgsl", "array<atomic<u32>, 64>", "at least 256 bytes"],
    );
    // A buffer where the WGSL binds a uniform, a parameter whose type the WGSL disagrees with.
    expect(
        "not-storage",
        "\n        \"luminance_histogram\": Buffer(size: Words(\"64\")),\n        \"bar_color\": Buffer(size: Words(\"4\")),\n        \"bar_scale\": Parameter(F32(0.125)),",
        "\"bar_color\":",
        0,
        &["`bar_color` is a graph buffer", "histogram_overlay.wgsl", "`var<uniform>` `vec4<f32>`"],
    );
    expect(
        "parameter-type",
        "\n        \"luminance_histogram\": Buffer(size: Words(\"64\")),\n        \"bar_color\": Parameter(Vec4(0.1, 0.9, 0.2, 1.0)),\n        \"bar_scale\": Parameter(U32(2)),",
        "\"bar_scale\":",
        0,
        &["parameter `bar_scale` is declared U32 (`u32`)", "`var<uniform> bar_scale: f32`"],
    );
    expect(
        "runtime-name",
        &format!("{}\n        \"frame\": Parameter(F32(1.0)),", with(r#"Buffer(size: Words("64"))"#)),
        "\"frame\":",
        0,
        &["one the runtime provides"],
    );
}

#[test]
fn an_oversized_buffer_names_the_adapter_limit() {
    let resources = r#"
        "luminance_histogram": Buffer(size: Elements(count: "width * height * 65536", stride: 16)),
        "bar_color": Parameter(Vec4(0.1, 0.9, 0.2, 1.0)),
        "bar_scale": Parameter(F32(0.125)),"#;
    let text = graph_text(resources, PASSES);
    let dir = common::scratch_dir("voltex-graph-data-oversized");
    let path = write_graph(&dir);
    std::fs::write(&path, &text).unwrap();
    let bytes = 64u64 * 64 * 65536 * 16;
    let loc = at(&path, &text, "\"luminance_histogram\":", 0);
    // `voltex plan` refuses it from the size alone, against the limits it assumes.
    let scene = scene_path();
    let out = common::voltex(&["plan", common::s(&scene), "--size", "64x64", "--graph", common::s(&path)]);
    assert!(!out.status.success());
    let err = common::stderr(&out);
    for w in [loc.as_str(), &format!("({bytes} bytes)"), "max_storage_buffer_binding_size of"] {
        assert!(err.contains(w), "expected {w:?} in: {err}");
    }
    let out = common::voltex(&[
        "render",
        common::s(&scene_path()),
        "--size",
        "64x64",
        "--graph",
        common::s(&path),
        "-o",
        common::s(&dir.join("o.exr")),
    ]);
    assert!(!out.status.success());
    let err = common::stderr(&out);
    for w in
        [loc.as_str(), &format!("({bytes} bytes)"), "max_storage_buffer_binding_size of", "this adapter's"]
    {
        assert!(err.contains(w), "expected {w:?} in: {err}");
    }
}

/// Plans the flat box through `text` (beside the two kernels).
fn plan_of(name: &str, text: &str) -> Blueprint {
    let dir = common::scratch_dir(&format!("voltex-graph-data-{name}"));
    let path = write_graph(&dir);
    std::fs::write(&path, text).unwrap();
    let scene = voltex::scene::load(&scene_path()).unwrap();
    Blueprint::new(&scene, &options(Some(&path))).unwrap()
}

#[test]
fn buffers_order_and_prune_passes() {
    // Declared reader first: the writer of the histogram still runs before it.
    let (histogram, overlay) = PASSES.split_at(PASSES.find("        // After").unwrap());
    let bp = plan_of("order", &graph_text(RESOURCES, &format!("{overlay}{histogram}")));
    let order: Vec<&str> = bp.plan.passes.iter().map(|p| p.decl.name()).collect();
    let at = |n: &str| order.iter().position(|p| *p == n).unwrap_or_else(|| panic!("{n} in {order:?}"));
    assert!(at("draw_slices") < at("histogram"), "{order:?}");
    assert!(at("histogram") < at("histogram_overlay"), "{order:?}");
    assert!(at("composite") < at("histogram_overlay"), "{order:?}");
    assert_eq!(bp.plan.buffers["luminance_histogram"].bytes, 256);
    assert!(bp.plan.buffers["luminance_histogram"].clear);
    // Without a reader, the histogram reaches no output: its pass, buffer and parameters go.
    let bp = plan_of("prune", &graph_text(RESOURCES, histogram));
    assert!(bp.plan.passes.iter().all(|p| p.decl.name() != "histogram"));
    assert!(bp.plan.buffers.is_empty() && bp.plan.parameters.is_empty());
    for line in ["pass histogram:", "resource luminance_histogram:", "resource bar_color:"] {
        assert!(bp.plan.pruned.iter().any(|p| p.starts_with(line)), "{line} in {:?}", bp.plan.pruned);
    }
}
