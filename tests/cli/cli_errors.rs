//! Bad input through the real `voltex` binary: every error names the file (and `line:col` where
//! there is one), exits with status 1 (no panic, no signal) and leaves no output or temporary
//! file behind. Plus the success case and `voltex plan`.

use crate::common;

use common::{entries, s, stderr};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn flat_box() -> String {
    std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap()
}

/// A fresh folder with an empty `out/` inside.
fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("out")).unwrap();
    d
}

/// Runs `voltex ARGS` with `VOLTEX_ROOT` (this checkout unless given: the shared target folder may
/// hold a binary built elsewhere, and the compiled-in root would then be another checkout).
fn voltex(args: &[&str], voltex_root: Option<&Path>) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args).env("VOLTEX_ROOT", voltex_root.unwrap_or(&root()));
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    cmd.output().unwrap()
}

/// `voltex render SCENE -o DIR/out/out.exr --size 64x64 EXTRA...`.
fn render(dir: &Path, scene: &Path, extra: &[&str], voltex_root: Option<&Path>) -> Output {
    let out = dir.join("out/out.exr");
    let mut args = vec!["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--size", "64x64"];
    args.extend_from_slice(extra);
    voltex(&args, voltex_root)
}

/// 1-based `line:col` of the first occurrence of `needle` in `text`.
fn line_col(text: &str, needle: &str) -> String {
    let at = text.find(needle).unwrap_or_else(|| panic!("{needle:?} not in the text"));
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = at - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
    format!("{line}:{col}")
}

/// Exit status 1, no panic, stderr contains every string of `words`, and `dir/out` is empty.
#[track_caller]
fn assert_fails(out: &Output, dir: &Path, words: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "expected exit status 1; stderr:\n{err}");
    assert!(!err.contains("panicked"), "panic:\n{err}");
    assert!(err.starts_with("error: "), "stderr:\n{err}");
    for w in words {
        assert!(err.contains(w), "expected {w:?} in stderr:\n{err}");
    }
    let left = entries(&dir.join("out"));
    assert!(left.is_empty(), "files left in the output folder: {left:?}");
}

/// Writes `text` as `dir/scene.ron`, renders it and expects an error at `scene.ron:LOC`
/// (`LOC` = the position of `at` in `text`, or any `line:col` when `at` is empty).
#[track_caller]
fn assert_scene_error(test: &str, text: &str, at: &str, words: &[&str]) {
    let dir = temp_dir(test);
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    let out = render(&dir, &scene, &[], None);
    let prefix = format!("error: {}:", scene.display());
    let mut all = vec![prefix.as_str()];
    let loc;
    if !at.is_empty() {
        loc = format!("{}:{}: ", scene.display(), line_col(text, at));
        all.push(&loc);
    } else {
        let err = stderr(&out);
        let rest = err.strip_prefix(&prefix).unwrap_or_else(|| panic!("{err}"));
        let pos: Vec<&str> = rest.splitn(3, ':').collect();
        assert!(
            pos.len() == 3 && pos[0].parse::<u32>().is_ok() && pos[1].parse::<u32>().is_ok(),
            "expected line:col after the path: {err}"
        );
    }
    all.extend_from_slice(words);
    assert_fails(&out, &dir, &all);
}

fn replaced(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} not in the scene");
    text.replacen(from, to, 1)
}

// ---- scene errors ----

#[test]
fn truncated_ron() {
    let text = flat_box();
    let cut = &text[..text.find("nodes:").unwrap() + 12];
    assert_scene_error("truncated", cut, "", &[]);
}

#[test]
fn malformed_ron() {
    let text = replaced(&flat_box(), "fov_y: 40.0)", "fov_y: 40.0");
    assert_scene_error("malformed", &text, "", &[]);
}

#[test]
fn unknown_field() {
    let text = replaced(&flat_box(), "ambient: 1.0,", "ambient: 1.0, glow: 2.0,");
    assert_scene_error("field", &text, "glow", &["glow", "camera", "nodes"]);
}

#[test]
fn unknown_method_variant() {
    let text = replaced(&flat_box(), "ViewSlices(planes", "RayTrace(planes");
    assert_scene_error("method", &text, "RayTrace", &["RayTrace", "ViewSlices", "RayMarch"]);
}

#[test]
fn nan() {
    let text = replaced(&flat_box(), "ambient: 1.0", "ambient: NaN");
    assert_scene_error("nan", &text, "NaN", &["NaN"]);
    let text = replaced(&flat_box(), "fov_y: 40.0", "fov_y: inf");
    assert_scene_error("inf", &text, "inf", &[]);
}

#[test]
fn plane_counts_out_of_range() {
    let text = replaced(&flat_box(), "planes: 256", "planes: 0");
    assert_scene_error("planes0", &text, "0, lighting", &["plane count"]);
    let text = replaced(&flat_box(), "planes: 256", "planes: 100000");
    assert_scene_error("planes_big", &text, "100000", &["plane count", "100000"]);
}

#[test]
fn output_size_out_of_range() {
    let text = replaced(&flat_box(), "width: 128", "width: 100000");
    let dir = temp_dir("width");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, &text).unwrap();
    // No --size: the scene's size counts.
    let out =
        voltex(&["render", scene.to_str().unwrap(), "-o", dir.join("out/out.exr").to_str().unwrap()], None);
    let loc = format!("{}:{}: ", scene.display(), line_col(&text, "100000"));
    assert_fails(&out, &dir, &[&loc, "100000"]);
}

#[test]
fn texel_resolution_too_large() {
    let text = replaced(&flat_box(), "resolution: (8, 8, 8)", "resolution: (8, 2048, 8)");
    assert_scene_error("resolution", &text, "2048", &["2048"]);
}

#[test]
fn unknown_texel() {
    let text = replaced(&flat_box(), "texel: \"fog\"", "texel: \"smoke\"");
    assert_scene_error("texel", &text, "\"smoke\"", &["smoke", "fog"]);
}

#[test]
fn missing_obj_file() {
    let text = replaced(&flat_box(), "Plane(size: (2.0, 2.0), cells: (4, 4))", "Obj(path: \"missing.obj\")");
    assert_scene_error("obj_missing", &text, "\"missing.obj\"", &["missing.obj"]);
}

#[test]
fn obj_face_index_out_of_range() {
    let dir = temp_dir("obj_face");
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n").unwrap();
    let text = replaced(&flat_box(), "Plane(size: (2.0, 2.0), cells: (4, 4))", "Obj(path: \"tri.obj\")");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    let out = render(&dir, &scene, &[], None);
    let loc = format!("error: {}:5:7: ", obj.display());
    assert_fails(&out, &dir, &[&loc, "7"]);
}

#[test]
fn degenerate_obj_is_an_error_at_its_node() {
    // All three corners on a line: no area, no normal.
    let dir = temp_dir("obj_degenerate");
    std::fs::write(dir.join("line.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    let text = replaced(&flat_box(), "Plane(size: (2.0, 2.0), cells: (4, 4))", "Obj(path: \"line.obj\")");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    let out = render(&dir, &scene, &[], None);
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    // Nothing could be drawn: an error at the node, not an empty image.
    let loc = format!("error: {}:", scene.display());
    assert_fails(&out, &dir, &[&loc, "\"box\"", "degenerate"]);
    let rest = err.split(&loc).nth(1).unwrap_or("");
    let mut parts = rest.splitn(3, ':');
    let line = parts.next().and_then(|l| l.parse::<usize>().ok());
    let col = parts.next().and_then(|c| c.parse::<usize>().ok());
    let text = std::fs::read_to_string(&scene).unwrap();
    let expected_line = text.lines().position(|l| l.contains("name: \"box\"")).map(|i| i + 1);
    assert!(line.is_some() && line == expected_line && col.is_some(), "{err}");
}

#[test]
fn missing_scene_file() {
    let dir = temp_dir("no_scene");
    let scene = dir.join("nope.ron");
    let out = render(&dir, &scene, &[], None);
    assert_fails(&out, &dir, &[&format!("error: {}", scene.display())]);
}

// ---- command-line errors ----

/// A missing output folder is made (issue 32: the tutorial's `-o out/my/balls.exr`); one that
/// cannot be made (under a plain file) is an error naming it, before any work.
#[test]
fn unmakeable_output_folder() {
    let dir = temp_dir("no_out_dir");
    let file = dir.join("plain");
    std::fs::write(&file, "x").unwrap();
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let target = file.join("sub/x.exr");
    let out =
        voltex(&["render", scene.to_str().unwrap(), "-o", target.to_str().unwrap(), "--size", "64x64"], None);
    assert_fails(&out, &dir, &[&file.join("sub").display().to_string(), "cannot make the output folder"]);
}

#[test]
fn output_folder_is_a_file() {
    let dir = temp_dir("out_is_file");
    let file = dir.join("plain");
    std::fs::write(&file, "x").unwrap();
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let target = file.join("x.exr");
    let out = voltex(&["render", scene.to_str().unwrap(), "-o", target.to_str().unwrap()], None);
    assert_fails(&out, &dir, &[file.to_str().unwrap()]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn bad_size_and_planes_options() {
    let dir = temp_dir("options");
    let scene = root().join("scenes/view_slices/flat_box.ron");
    for size in ["0x5", "5x0", "100000x64", "64", "axb"] {
        let out = voltex(
            &[
                "render",
                scene.to_str().unwrap(),
                "-o",
                dir.join("out/out.exr").to_str().unwrap(),
                "--size",
                size,
            ],
            None,
        );
        // Command-line syntax errors are clap's usage errors: status 2.
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "--size {size}: {err}");
        assert!(err.contains("--size"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(entries(&dir.join("out")).is_empty());
    }
    for planes in ["0", "100000"] {
        let out = render(&dir, &scene, &["--planes", planes], None);
        assert_fails(&out, &dir, &["--planes", planes]);
    }
}

#[test]
fn slice_memory_beyond_the_per_object_limit() {
    // Terrain with 16384 planes needs about 1.2 GiB of slice vertices: beyond the 1 GiB each
    // object may use (sweeps are split into chunks that fit a binding, but not without end).
    let dir = temp_dir("slice_memory");
    let scene = root().join("scenes/view_slices/terrain.ron");
    let out = render(&dir, &scene, &["--planes", "16384"], None);
    assert_fails(&out, &dir, &["ground", "planes", "limit"]);
}

// ---- custom graphs and WGSL (VOLTEX_ROOT) ----

/// `dir/root` with copies of `wgsl/` and `graphs/`, to be passed as `VOLTEX_ROOT`.
fn project_copy(dir: &Path) -> PathBuf {
    let r = dir.join("root");
    common::copy_dir(&root().join("wgsl"), &r.join("wgsl"));
    common::copy_dir(&root().join("graphs"), &r.join("graphs"));
    r
}

#[test]
fn wgsl_parse_error_names_the_wgsl_file() {
    let dir = temp_dir("wgsl_parse");
    let r = project_copy(&dir);
    let path = r.join("wgsl/composite.wgsl");
    let text = std::fs::read_to_string(&path).unwrap();
    let broken = replaced(&text, "let c = textureLoad", "let c = = textureLoad");
    std::fs::write(&path, &broken).unwrap();
    let loc = line_col(&broken, "= textureLoad");
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = render(&dir, &scene, &[], Some(&r));
    assert_fails(&out, &dir, &[&format!("error: {}:{loc}: ", path.display()), "WGSL"]);
    // `plan` compiles the kernels too and reports the same error.
    let out = voltex(&["plan", scene.to_str().unwrap()], Some(&r));
    assert_fails(&out, &dir, &[&format!("{}:{loc}: ", path.display())]);
}

#[test]
fn wgsl_error_in_an_included_file_names_that_file() {
    let dir = temp_dir("wgsl_include");
    let r = project_copy(&dir);
    let path = r.join("wgsl/shared/types.wgsl");
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str("\nfn broken( {}\n");
    std::fs::write(&path, &text).unwrap();
    let line = text.lines().count();
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = render(&dir, &scene, &[], Some(&r));
    assert_fails(&out, &dir, &[&format!("error: {}:{line}:", path.display())]);
}

#[test]
fn graph_naming_a_missing_shader() {
    let dir = temp_dir("graph_shader");
    let graph = dir.join("g.ron");
    let text = std::fs::read_to_string(root().join("graphs/frame.ron")).unwrap();
    let text = replaced(&text, "\"composite.wgsl\"", "\"compost.wgsl\"");
    std::fs::write(&graph, &text).unwrap();
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let loc = format!("error: {}:{}: ", graph.display(), line_col(&text, "\"compost"));
    let out = render(&dir, &scene, &["--graph", graph.to_str().unwrap()], None);
    assert_fails(&out, &dir, &[&loc, "compost.wgsl"]);
    let out = voltex(&["plan", scene.to_str().unwrap(), "--graph", graph.to_str().unwrap()], None);
    assert_fails(&out, &dir, &[&loc]);
}

#[test]
fn missing_graph_file() {
    let dir = temp_dir("graph_missing");
    let graph = dir.join("nothere.ron");
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = render(&dir, &scene, &["--graph", graph.to_str().unwrap()], None);
    assert_fails(&out, &dir, &[graph.to_str().unwrap()]);
}

#[test]
fn wgsl_global_nothing_provides() {
    let dir = temp_dir("wgsl_global");
    let r = project_copy(&dir);
    let path = r.join("wgsl/composite.wgsl");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = replaced(
        &text,
        "var hdr: texture_2d<f32>;",
        "var hdr: texture_2d<f32>;\n@group(0) @binding(7) var<storage, read> mystery: array<f32>;",
    );
    let text = replaced(&text, "return vec4<f32>(c.rgb", "return mystery[0] * vec4<f32>(c.rgb");
    std::fs::write(&path, &text).unwrap();
    let graph = r.join("graphs/frame.ron");
    let graph_text = std::fs::read_to_string(&graph).unwrap();
    let loc = format!("error: {}:{}: ", graph.display(), line_col(&graph_text, "\"composite\""));
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = render(&dir, &scene, &[], Some(&r));
    assert_fails(&out, &dir, &[&loc, "`composite`", "`mystery`"]);
    // `plan` finds it too, without a GPU.
    let out = voltex(&["plan", scene.to_str().unwrap()], Some(&r));
    assert_fails(&out, &dir, &[&loc, "`composite`", "`mystery`"]);
}

// ---- success ----

#[test]
fn render_writes_exr_and_png_with_metadata() {
    let dir = temp_dir("ok");
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let exr = dir.join("out/out.exr");
    let out =
        voltex(&["render", scene.to_str().unwrap(), "-o", exr.to_str().unwrap(), "--size", "32x32"], None);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(entries(&dir.join("out")), ["out.exr", "out.png"]);
    let (image, meta) = voltex::io::exr::read(&exr).unwrap();
    assert_eq!((image.width, image.height), (32, 32));
    let keys: Vec<&str> = meta.iter().map(|(k, _)| k.as_str()).collect();
    for k in ["voltex_adapter", "voltex_scene"] {
        assert!(keys.contains(&k), "{k} not in {keys:?}");
    }
    assert!(keys.iter().any(|k| k.starts_with("voltex_object_")), "{keys:?}");
    // Some fog is visible: the centre is not the black background.
    let c = image.get(16, 16);
    assert!(c[0] > 0.0 && c[3] > 0.0, "{c:?}");

    // Rendering again over existing files replaces them, still nothing else in the folder.
    let out =
        voltex(&["render", scene.to_str().unwrap(), "-o", exr.to_str().unwrap(), "--size", "16x16"], None);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(entries(&dir.join("out")), ["out.exr", "out.png"]);
    assert_eq!(voltex::io::exr::read(&exr).unwrap().0.width, 16);
}

#[test]
fn render_with_the_reference_method() {
    let dir = temp_dir("reference");
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = render(&dir, &scene, &["--method", "reference", "--step", "0.01"], None);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (image, meta) = voltex::io::exr::read(&dir.join("out/out.exr")).unwrap();
    let method = meta.iter().find(|(k, _)| k == "voltex_object_box").map(|(_, v)| v.as_str());
    assert_eq!(method, Some("Reference(step: 0.010000, lighting: Baked)"));
    assert!(image.get(32, 32)[0] > 0.0);
    // A step that is not a positive length, and one far too fine for the scene.
    for (step, words) in [("-1", &["--step -1", "positive"][..]), ("1e-9", &["too fine", "step"][..])] {
        let dir = temp_dir("reference-bad");
        let out = render(&dir, &scene, &["--method", "reference", "--step", step], None);
        assert_fails(&out, &dir, words);
    }
}

#[test]
fn failed_render_keeps_previous_output() {
    let dir = temp_dir("keep");
    std::fs::write(dir.join("out/out.exr"), "old").unwrap();
    let text = replaced(&flat_box(), "texel: \"fog\"", "texel: \"smoke\"");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, text).unwrap();
    let out = render(&dir, &scene, &[], None);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(entries(&dir.join("out")), ["out.exr"]);
    assert_eq!(std::fs::read_to_string(dir.join("out/out.exr")).unwrap(), "old");
}

// ---- plan ----

#[test]
fn plan_prints_passes_pruning_and_memory_without_a_gpu() {
    let scene = root().join("scenes/view_slices/flat_box.ron");
    // Hide every Vulkan driver: `info` then fails, `plan` must not care.
    let hide = |cmd: &mut Command| {
        cmd.env("VOLTEX_ROOT", root())
            .env("WGPU_BACKEND", "vulkan")
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json");
    };
    let mut info = Command::new(BIN);
    info.arg("info");
    hide(&mut info);
    let info = info.output().unwrap();
    let mut cmd = Command::new(BIN);
    cmd.args(["plan", scene.to_str().unwrap(), "--size", "64x48"]);
    hide(&mut cmd);
    let out = cmd.output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if info.status.code() == Some(0) {
        eprintln!("note: an adapter was still found; the no-GPU part is not proven here");
    }
    for s in [
        "output 64x48",
        "passes (in order):",
        "pruned:",
        "pass(es) of methods and object kinds this scene does not use",
        "GPU memory:",
        "total",
    ] {
        assert!(text.contains(s), "{s:?} not in:\n{text}");
    }
    let passes = text.split("passes (in order):").nth(1).unwrap().split("\n\n").next().unwrap();
    let order: Vec<&str> = passes.lines().filter_map(|l| l.split_whitespace().next()).collect();
    assert_eq!(order, ["count_slices", "scan_plane_offsets", "emit_slices", "draw_slices", "composite"]);
    let total = text.lines().find(|l| l.trim_end().ends_with("MiB  total")).unwrap();
    let mib: f64 = total.split_whitespace().next().unwrap().parse().unwrap();
    assert!(mib > 0.0, "{total}");
}

#[test]
fn a_graph_that_samples_no_texel_bakes_nothing() {
    let scene = root().join("scenes/view_slices/torus_egg.ron");
    let graph = root().join("graphs/slices_only.ron");
    let out = voltex(&["plan", scene.to_str().unwrap(), "--graph", graph.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("bakes:\n  (none)") && !text.contains("texel torus_egg"), "{text}");
    let out = voltex(&["plan", scene.to_str().unwrap()], None);
    assert!(String::from_utf8_lossy(&out.stdout).contains("texel torus_egg"));
}

#[test]
fn plan_of_a_bad_scene_fails_like_render() {
    let dir = temp_dir("plan_bad");
    let text = replaced(&flat_box(), "ambient: 1.0", "ambient: NaN");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, &text).unwrap();
    let out = voltex(&["plan", scene.to_str().unwrap()], None);
    let loc = format!("{}:{}: ", scene.display(), line_col(&text, "NaN"));
    assert_fails(&out, &dir, &[&loc]);
}

/// `voltex compare`: an image against itself is error-free, against another image it is not, and
/// a missing file is an error naming it.
#[test]
fn compare_images() {
    let dir = temp_dir("compare");
    let golden = root().join("tests/golden");
    let (a, b) = (golden.join("view_slices_torus_egg.exr"), golden.join("view_slices_terrain.exr"));
    let heat = dir.join("out/heat.png");
    let same = voltex(&["compare", a.to_str().unwrap(), a.to_str().unwrap()], None);
    assert!(same.status.success(), "{}", stderr(&same));
    let text = String::from_utf8_lossy(&same.stdout).to_string();
    assert!(
        text.contains("FLIP (mean)         0.00000") && text.contains("largest difference  0.000e0"),
        "{text}"
    );
    let other = voltex(
        &["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--diff", heat.to_str().unwrap()],
        None,
    );
    assert!(other.status.success(), "{}", stderr(&other));
    let text = String::from_utf8_lossy(&other.stdout).to_string();
    let flip: f64 = text.lines().next().unwrap().split_whitespace().last().unwrap().parse().unwrap();
    assert!(flip > 0.05, "{text}");
    assert!(heat.is_file());
    let missing = dir.join("nothing.exr");
    let out = voltex(&["compare", missing.to_str().unwrap(), a.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("nothing.exr"), "{}", stderr(&out));
}

/// A reader that stops early (`| head`) ends voltex quietly, as other tools end, not in a panic.
#[test]
fn closed_stdout_is_no_panic() {
    let golden = root().join("tests/golden");
    let (a, b) = (golden.join("view_slices_torus_egg.exr"), golden.join("view_slices_terrain.exr"));
    let line = format!("'{BIN}' compare '{}' '{}' | head -c 0", a.display(), b.display());
    let out = Command::new("sh").args(["-c", &line]).env("VOLTEX_ROOT", root()).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{err}");
}

/// `--mipmaps on|off` switches the MIP-mapped slice images of every AxisSlices object (the
/// scene's `mipmaps` otherwise), and anything else is a usage error.
#[test]
fn mipmaps_flag_switches_every_axis_slices_object() {
    let scene = root().join("scenes/meyer_neyret/heightfield_plane.ron");
    let scene = scene.to_str().unwrap();
    for (args, expected) in [(&[][..], "mipmaps: true"), (&["--mipmaps", "off"][..], "mipmaps: false")] {
        let mut all = vec!["plan", scene];
        all.extend_from_slice(args);
        let text = common::ok(common::voltex(&all));
        assert!(text.contains(expected), "{args:?}: {text}");
    }
    let pear = root().join("scenes/meyer_neyret/pear.ron");
    let text = common::ok(common::voltex(&["plan", pear.to_str().unwrap(), "--mipmaps", "on"]));
    assert!(text.contains("mipmaps: true"), "{text}");
    let out = common::voltex(&["plan", scene, "--mipmaps", "maybe"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("possible values: on, off"), "{}", stderr(&out));
}

/// Where `-o` puts a render (issue 32, items 2 and 6): into folders that do not exist yet (made),
/// `x.png` as x.exr and x.png (the PNG no longer replaces the EXR under its name), a folder
/// (existing, or ending in `/`) as the scene's name in it, and an unknown extension refused
/// before any work.
#[test]
fn output_paths_make_folders_and_keep_both_images() {
    let dir = temp_dir("output_paths");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, flat_box()).unwrap();
    let render_to =
        |o: &Path| voltex(&["render", s(&scene), "--size", "16x16", "-o", o.to_str().unwrap()], None);
    let nested = dir.join("new/deeper/box.exr");
    let out = render_to(&nested);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        nested.exists() && nested.with_extension("png").exists(),
        "{:?}",
        entries(&dir.join("new/deeper"))
    );
    let png = dir.join("pictures/x.png");
    let out = render_to(&png);
    assert!(out.status.success(), "{}", stderr(&out));
    let said = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(said.contains("x.exr and ") && said.contains("x.png"), "{said}");
    let (exr, _) = voltex::io::exr::read(&png.with_extension("exr")).unwrap();
    assert_eq!((exr.width, exr.height), (16, 16));
    for folder in [dir.join("pictures"), dir.join("more/")] {
        let out = render_to(&folder);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(folder.join("scene.exr").exists(), "{:?}", entries(&folder));
    }
    let jpg = dir.join("y.jpg");
    let out = render_to(&jpg);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("expected an output ending in .exr or .png"), "{}", stderr(&out));
    assert!(!jpg.exists() && !jpg.with_extension("exr").exists());
}

/// One spelling for outputs (issue 32, item 7): every subcommand that writes files takes `-o`,
/// `--out` and `--output` (render's and import's differed, export's, bake's, pareto's and
/// regress's had no `-o`); and the short and the long forms do the same (an export with `-o`).
#[test]
fn every_output_takes_dash_o_out_and_output() {
    let help = |args: &[&str]| {
        let out = common::voltex(&[args, &["--help"]].concat());
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    for args in [
        &["render"][..],
        &["import"],
        &["export"],
        &["bake"],
        &["pareto"],
        &["regress"],
        &["farm", "submit"],
        &["farm", "manifest"],
    ] {
        let text = help(args);
        // The option's entry: its line and the description lines under it (clap's long help).
        let at = text.find("  -o, --out").unwrap_or_else(|| panic!("{args:?}: no -o, --out...:\n{text}"));
        let entry: String = text[at..].lines().take_while(|l| !l.trim_start().starts_with("--")).collect();
        let entry = entry + text[at..].lines().next().unwrap_or("");
        assert!(entry.contains("--output"), "{args:?}: -o, --out and --output:\n{entry}");
    }
    let dir = temp_dir("dash-o");
    let scene = dir.join("box.ron");
    std::fs::write(&scene, flat_box()).unwrap();
    let out = dir.join("vdb");
    let run = common::voltex(&["export", s(&scene), "-o", s(&out)]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(entries(&out), ["fog.vdb"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
