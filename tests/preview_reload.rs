//! The preview's reload machinery, headless, over a scripted sequence of edits made the way
//! editors make them (in place, by renaming a temporary file, deleting and recreating, in bursts,
//! half-written then completed), each picked up by the file watcher: after every step, what was
//! rebuilt, the error if any, and the frame. Also measures save-to-frame latency per kind of edit.
//!
//! One test in its own binary: it points `VOLTEX_ROOT` at a copy of `graphs/` and `wgsl/`.

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use voltex::gpu::cache::CacheStats;
use voltex::gpu::GpuContext;
use voltex::io::Image;
use voltex::preview::{Outcome, Session, Watcher};
use voltex::render::RenderOptions;

const SCENE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 32, height: 32),
    camera: (eye: (0.0, -2.5, 2.0), target: (0.0, 0.0, 0.1), up: (0.0, 0.0, 1.0), fov_y: 40.0),
    background: (0.1, 0.1, 0.1),
    lights: [Directional(direction: (-0.3, 0.2, -1.0))],
    texels: {
        "balls": (
            resolution: (16, 16, 16),
            opacity_length: 0.05,
            source: Implicit(shapes: [Sphere(center: (0.5, 0.5, 0.4), radius: 0.3, color: (0.9, 0.5, 0.2))]),
        ),
    },
    nodes: [(
        name: "ground",
        surface: Plane(size: (2.0, 2.0), cells: (2, 2)),
        height: (length: 0.4),
        texel: "balls",
        method: ViewSlices(planes: 24),
        base_color: (0.2, 0.3, 0.2),
    )],
)
"#;

/// The next change the watcher reports that includes `path`, within a few seconds.
fn wait_for(w: &Watcher, path: &Path) -> Vec<PathBuf> {
    let want = std::fs::canonicalize(path.parent().unwrap()).unwrap().join(path.file_name().unwrap());
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut seen = Vec::new();
    while Instant::now() < deadline {
        let changes = w.changes(Duration::from_millis(200));
        let hit = changes.iter().any(|p| std::fs::canonicalize(p).unwrap_or(p.clone()) == want || *p == want);
        seen.extend(changes);
        if hit {
            // Let a burst settle into what the rebuild will read.
            seen.extend(w.changes(Duration::from_millis(50)));
            return seen;
        }
    }
    panic!("no change reported for {} (saw {seen:?})", path.display());
}

fn frame(s: &mut Session, ctx: &GpuContext) -> Image {
    s.render(ctx).expect("a good renderer").expect("a frame").image
}

fn mean(img: &Image) -> f64 {
    img.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / img.pixels.len() as f64
}

fn stats(o: &Outcome) -> CacheStats {
    match o {
        Outcome::Rebuilt(s) => *s,
        Outcome::Failed(e) => panic!("expected a rebuild, got: {e}"),
    }
}

#[track_caller]
fn failed(o: &Outcome, words: &[&str]) {
    let Outcome::Failed(msg) = o else { panic!("expected a failure, got {o:?}") };
    for w in words {
        assert!(msg.contains(w), "expected {w:?} in: {msg}");
    }
}

fn edit(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from:?} not in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn reload_sequence() {
    let root = std::env::temp_dir().join(format!("voltex-reload-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    common::copy_dir(&voltex::project_root().join("graphs"), &root.join("graphs"));
    common::copy_dir(&voltex::project_root().join("wgsl"), &root.join("wgsl"));
    std::fs::create_dir_all(root.join("scenes")).unwrap();
    std::env::set_var("VOLTEX_ROOT", &root);
    let scene = root.join("scenes/scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let wgsl = root.join("wgsl");
    let graph = root.join("graphs/frame.ron");

    let ctx = GpuContext::new().expect("a GPU adapter (software Vulkan: mesa-vulkan-drivers)");
    let mut s = Session::open(&ctx, &scene, RenderOptions::default());
    assert!(s.error.is_none(), "{:?}", s.error);
    let first = frame(&mut s, &ctx);
    let w = Watcher::new(&s.watch_dirs()).unwrap();
    let mut latency: Vec<(&str, f64)> = Vec::new();
    // One step: make the edit, wait for the watcher, rebuild, render; returns the outcome and
    // the frame (the last good one after a failure), timing save to frame.
    let mut step = |s: &mut Session, what: &'static str, path: &Path, change: &dyn Fn()| {
        let t = Instant::now();
        change();
        wait_for(&w, path);
        let o = s.rebuild(&ctx);
        let img = frame(s, &ctx);
        if matches!(o, Outcome::Rebuilt(_)) {
            latency.push((what, t.elapsed().as_secs_f64() * 1e3));
        }
        (o, img)
    };

    // Camera: a new frame, nothing recompiled or rebaked.
    let (o, camera) =
        step(&mut s, "camera", &scene, &|| edit(&scene, "eye: (0.0, -2.5, 2.0)", "eye: (0.3, -2.4, 2.1)"));
    assert_eq!(stats(&o), CacheStats::default());
    assert_ne!(camera.pixels, first.pixels);

    // A texel's colour: that texel rebaked, no pipeline made.
    let (o, texel) =
        step(&mut s, "texel", &scene, &|| edit(&scene, "color: (0.9, 0.5, 0.2)", "color: (0.2, 0.5, 0.9)"));
    assert_eq!(stats(&o), CacheStats { modules: 0, pipelines: 0, bakes: 1 });
    assert_ne!(texel.pixels, camera.pixels);

    // A bake kernel edited: that texel rebaked with it (bakes are kept by their request and the
    // source of the kernels that make them), nothing else made; a touch of the kernel that leaves
    // its text as it was rebakes nothing; the edit undone finds the texel's earlier bake, which
    // the preview keeps for a few builds (up to 256 MiB of unused bakes).
    let bake = wgsl.join("bake/bake_implicit.wgsl");
    let (store, halved) = (
        "textureStore(volume, id, baked.rgba);",
        "textureStore(volume, id, vec4<f32>(0.5 * baked.rgba.rgb, baked.rgba.a));",
    );
    let (o, darker) = step(&mut s, "bake kernel", &bake, &|| edit(&bake, store, halved));
    assert_eq!(stats(&o), CacheStats { modules: 0, pipelines: 0, bakes: 1 });
    assert!(mean(&darker) < 0.9 * mean(&texel), "{} against {}", mean(&darker), mean(&texel));
    let (o, same) = step(&mut s, "touch kernel", &bake, &|| edit(&bake, halved, halved));
    assert_eq!(stats(&o), CacheStats::default());
    assert_eq!(same.pixels, darker.pixels);
    let (o, undone) = step(&mut s, "bake kernel", &bake, &|| edit(&bake, halved, store));
    assert_eq!(stats(&o), CacheStats::default());
    assert_eq!(undone.pixels, texel.pixels);

    // Broken RON: the error names the place, the last good frame stays; the fix recovers with
    // nothing to rebuild.
    let (o, img) = step(&mut s, "broken", &scene, &|| edit(&scene, "planes: 24)", "planes: 24"));
    failed(&o, &["scene.ron:", "expected"]);
    assert_eq!(img.pixels, texel.pixels);
    assert!(s.error.is_some());
    let (o, img) = step(&mut s, "fix", &scene, &|| edit(&scene, "planes: 24", "planes: 24)"));
    assert_eq!(stats(&o), CacheStats::default());
    assert_eq!(img.pixels, texel.pixels);
    assert!(s.error.is_none());

    // Broken WGSL: error at the kernel's line; fixed: nothing rebuilt (the module was kept).
    let draw = wgsl.join("view_slices/draw_slices.wgsl");
    let (o, img) = step(&mut s, "broken", &draw, &|| {
        edit(&draw, "let a = clamp(texel.a, 0.0, 1.0);", "let a = clamp(texel.a, 0.0, 1.0)")
    });
    failed(&o, &["draw_slices.wgsl:", "WGSL"]);
    assert_eq!(img.pixels, texel.pixels);
    let (o, _) = step(&mut s, "fix", &draw, &|| {
        edit(&draw, "let a = clamp(texel.a, 0.0, 1.0)", "let a = clamp(texel.a, 0.0, 1.0);")
    });
    assert_eq!(stats(&o), CacheStats::default());

    // A kernel edit recompiles that kernel and its pipeline only.
    // The slices' shading is an include of draw_slices.wgsl (shared with the Tiles compositor).
    let shading = wgsl.join("shared/slice_shading.wgsl");
    let (o, darker) = step(&mut s, "wgsl", &shading, &|| {
        edit(
            &shading,
            "return vec4<f32>(rgb * frame.light_color.rgb, corrected);",
            "return vec4<f32>(0.5 * rgb * frame.light_color.rgb, corrected);",
        )
    });
    assert_eq!(stats(&o), CacheStats { modules: 1, pipelines: 1, bakes: 0 });
    assert!(mean(&darker) < mean(&texel), "{} against {}", mean(&darker), mean(&texel));

    // A shared include: every kernel including it (count_slices and emit_slices), nothing else.
    let shared = wgsl.join("shared/slice_prism.wgsl");
    let (o, _) = step(&mut s, "wgsl include", &shared, &|| {
        edit(&shared, "const MIN_DENOM", "// edited\nconst MIN_DENOM")
    });
    assert_eq!(stats(&o), CacheStats { modules: 2, pipelines: 2, bakes: 0 });

    // Saved by writing a temporary file and renaming it over the scene.
    let (o, renamed) = step(&mut s, "camera (rename)", &scene, &|| {
        let text = std::fs::read_to_string(&scene).unwrap().replacen("fov_y: 40.0", "fov_y: 35.0", 1);
        let tmp = root.join("scenes/scene.ron.tmp");
        std::fs::write(&tmp, text).unwrap();
        std::fs::rename(&tmp, &scene).unwrap();
    });
    assert_eq!(stats(&o), CacheStats::default());
    assert_ne!(renamed.pixels, darker.pixels);

    // Deleted (an error, the frame stays), then recreated.
    let text = std::fs::read_to_string(&scene).unwrap();
    let (o, img) = step(&mut s, "delete", &scene, &|| std::fs::remove_file(&scene).unwrap());
    failed(&o, &["scene.ron"]);
    assert_eq!(img.pixels, renamed.pixels);
    let (o, img) = step(&mut s, "recreate", &scene, &|| std::fs::write(&scene, &text).unwrap());
    assert_eq!(stats(&o), CacheStats::default());
    assert_eq!(img.pixels, renamed.pixels);

    // Half-written, then completed.
    let (o, _) = step(&mut s, "half", &scene, &|| std::fs::write(&scene, &text[..text.len() / 2]).unwrap());
    failed(&o, &["scene.ron:"]);
    let (o, img) = step(&mut s, "complete", &scene, &|| std::fs::write(&scene, &text).unwrap());
    assert_eq!(stats(&o), CacheStats::default());
    assert_eq!(img.pixels, renamed.pixels);

    // A burst of saves: the watcher reports them together; the rebuild sees the last one.
    let (o, burst) = step(&mut s, "burst", &scene, &|| {
        for fov in [36.0, 37.0, 38.0, 39.0, 30.0] {
            let t = text.replacen("fov_y: 35.0", &format!("fov_y: {fov:.1}"), 1);
            std::fs::write(&scene, t).unwrap();
        }
    });
    assert_eq!(stats(&o), CacheStats::default());
    assert_ne!(burst.pixels, renamed.pixels);

    // A new pass written only in RON and WGSL: a tint added over the frame.
    let tint = wgsl.join("tint.wgsl");
    std::fs::write(
        &tint,
        "// Adds a constant tint (a pass added while the preview runs).\n\
         @vertex fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {\n\
         let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));\n    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);\n}\n\
         @fragment fn fs_main() -> @location(0) vec4<f32> { return vec4<f32>(0.0, 0.0, 0.5, 0.0); }\n",
    )
    .unwrap();
    let (o, tinted) = step(&mut s, "graph", &graph, &|| {
        edit(
            &graph,
            "        Raster(\n            name: \"composite\",",
            "        Raster(name: \"tint\", shader: \"tint.wgsl\", targets: [(resource: \"hdr\", blend: Add)], draw: Vertices(\"3\")),\n        Raster(\n            name: \"composite\",",
        )
    });
    assert_eq!(stats(&o), CacheStats { modules: 1, pipelines: 1, bakes: 0 });
    let blue = |img: &Image| img.pixels.iter().map(|p| p[2] as f64).sum::<f64>();
    assert!(blue(&tinted) > blue(&burst) + 0.4 * tinted.pixels.len() as f64);

    eprintln!(
        "save-to-frame latency (quiet time {} ms and this test's 50 ms settle included), {}:",
        voltex::preview::watch::DEBOUNCE.as_millis(),
        ctx.adapter_line()
    );
    for (what, ms) in &latency {
        eprintln!("  {what:<16} {ms:>7.1} ms");
    }
    drop(w);
    std::fs::remove_dir_all(&root).ok();
}

/// Another process opening and reading a watched file is not a change; a write is.
#[test]
fn reads_of_watched_files_are_not_changes() {
    let dir = std::env::temp_dir().join(format!("voltex-watch-read-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("scene.ron");
    std::fs::write(&file, SCENE).unwrap();
    let w = Watcher::new(std::slice::from_ref(&dir)).unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let status =
        std::process::Command::new("cat").arg(&file).stdout(std::process::Stdio::null()).status().unwrap();
    assert!(status.success());
    let _ = std::fs::read(&file).unwrap();
    let seen = w.changes(Duration::from_millis(800));
    assert!(seen.is_empty(), "reads reported as changes: {seen:?}");
    std::fs::write(&file, SCENE.replace("planes: 24", "planes: 25")).unwrap();
    wait_for(&w, &file);
    std::fs::remove_dir_all(&dir).ok();
}
