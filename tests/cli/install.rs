//! An installed voltex: a binary copied away from the source tree renders with its embedded
//! kernels and graphs, and a graph copied elsewhere brings its own WGSL beside it (see
//! `voltex::gpu::sources`).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{root, s};

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-install-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `bin ARGS` in `cwd` with `VOLTEX_ROOT=voltex_root`.
fn run(bin: &Path, cwd: &Path, voltex_root: &Path, args: &[&str]) -> Output {
    let mut cmd = Command::new(bin);
    cmd.args(args).current_dir(cwd).env("VOLTEX_ROOT", voltex_root);
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    // A binary just copied can be briefly "busy": another test thread forking at that moment
    // inherits the copy's open file until it execs. Try again.
    for _ in 0..50 {
        match cmd.output() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy => {
                std::thread::sleep(std::time::Duration::from_millis(100))
            }
            out => return out.unwrap(),
        }
    }
    cmd.output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `dir/frame.ron`: the default graph with a `tint` pass (shader `tint.wgsl`, written beside it)
/// that adds 0.25 of premultiplied red over the frame before compositing.
fn graph_with_tint(dir: &Path, tint_wgsl: &str) -> PathBuf {
    let text = std::fs::read_to_string(root().join("graphs/frame.ron")).unwrap();
    let composite = "        Raster(\n            name: \"composite\",";
    assert!(text.contains(composite), "graphs/frame.ron changed: update this test");
    let tint =
        "        Raster(\n            name: \"tint\",\n            shader: \"tint.wgsl\",\n            \
                targets: [(resource: \"hdr\", blend: PremultipliedOver)],\n            \
                draw: Vertices(\"3\"),\n        ),\n";
    let graph = dir.join("frame.ron");
    std::fs::write(&graph, text.replacen(composite, &format!("{tint}{composite}"), 1)).unwrap();
    std::fs::write(dir.join("tint.wgsl"), tint_wgsl).unwrap();
    graph
}

const TINT: &str = "// Test pass: premultiplied red over the frame.
#include \"shared/fullscreen.wgsl\"

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(index);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(0.25, 0.0, 0.0, 0.0);
}
";

#[test]
fn copied_binary_renders_the_demo_from_embedded_files() {
    let dir = temp_dir("copied");
    let (bin_dir, work, empty) = (dir.join("bin"), dir.join("work"), dir.join("empty"));
    for d in [&bin_dir, &work, &empty] {
        std::fs::create_dir_all(d).unwrap();
    }
    let bin = bin_dir.join("voltex");
    std::fs::copy(env!("CARGO_BIN_EXE_voltex"), &bin).unwrap();
    std::fs::copy(root().join("scenes/view_slices/torus_egg.ron"), work.join("torus_egg.ron")).unwrap();
    // `VOLTEX_ROOT` at a folder without wgsl/ or graphs/: the build's source tree is ignored.
    let out = run(&bin, &work, &empty, &["render", "torus_egg.ron", "--size", "64x64", "-o", "egg.exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(work.join("egg.png").is_file());
    let (image, _) = voltex::io::exr::read(&work.join("egg.exr")).unwrap();
    assert_eq!((image.width, image.height), (64, 64));
    // The orange torus and blue egg, not the dark background (0.02, 0.025, 0.035) alone.
    let lit = (0..64).flat_map(|y| (0..64).map(move |x| (x, y))).filter(|&(x, y)| image.get(x, y)[0] > 0.1);
    assert!(lit.count() > 64 * 64 / 20, "the image is (nearly) background");

    // Its plan lists the embedded kernels' work like the project's (no GPU needed).
    let out = run(&bin, &work, &empty, &["plan", "torus_egg.ron", "--size", "64x64"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("draw_slices"));

    // A missing VOLTEX_ROOT is an error, not a silent fallback.
    let out = run(&bin, &work, &dir.join("nothere"), &["plan", "torus_egg.ron"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("VOLTEX_ROOT"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn graph_copied_elsewhere_finds_its_own_wgsl_and_project_includes() {
    let dir = temp_dir("graph");
    let graph = graph_with_tint(&dir, TINT);
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let (plain, tinted) = (dir.join("plain.exr"), dir.join("tinted.exr"));
    let render = |extra: &[&str], o: &Path| {
        let mut args = vec!["render", s(&scene), "--size", "32x32", "-o", s(o)];
        args.extend_from_slice(extra);
        run(Path::new(env!("CARGO_BIN_EXE_voltex")), &dir, &root(), &args)
    };
    let out = render(&[], &plain);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = render(&["--graph", s(&graph)], &tinted);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("tint"), "{stdout}");
    let (a, _) = voltex::io::exr::read(&plain).unwrap();
    let (b, _) = voltex::io::exr::read(&tinted).unwrap();
    for (y, x) in (0..32).flat_map(|y| (0..32).map(move |x| (y, x))) {
        let (p, q) = (a.get(x, y), b.get(x, y));
        assert!((q[0] - p[0] - 0.25).abs() < 1e-3 && (q[1] - p[1]).abs() < 1e-5, "{x},{y}: {p:?} -> {q:?}");
    }
}

#[test]
fn errors_in_embedded_files_name_them_with_line_and_column() {
    let dir = temp_dir("embedded_error");
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    // Defined before the include: the redefinition is reported in the embedded file.
    let tint = TINT.replace(
        "#include",
        "fn fullscreen_position(index: u32) -> vec4<f32> { return vec4<f32>(0.0); }\n#include",
    );
    let graph = graph_with_tint(&dir, &tint);
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let bin = Path::new(env!("CARGO_BIN_EXE_voltex"));
    let out = run(bin, &dir, &empty, &["plan", s(&scene), "--graph", s(&graph)]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("error: <embedded>/wgsl/shared/fullscreen.wgsl:2:4: "), "{err}");
    // A missing include names the including file and where it was looked for.
    std::fs::write(dir.join("tint.wgsl"), TINT.replace("shared/fullscreen", "shared/nothere")).unwrap();
    let out = run(bin, &dir, &empty, &["plan", s(&scene), "--graph", s(&graph)]);
    let err = stderr(&out);
    let tint_path = dir.join("tint.wgsl");
    assert!(
        err.contains(&format!("error: {}:2:1: cannot include shared/nothere.wgsl", tint_path.display())),
        "{err}"
    );
    assert!(err.contains("the embedded kernels"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn only_folders_on_disk_are_watched() {
    let dir = temp_dir("watch");
    let graph = graph_with_tint(&dir, TINT);
    // The project tree on disk: the graph's folder and wgsl/.
    let sources = voltex::gpu::sources::Sources::project().unwrap().beside(&graph);
    assert_eq!(sources.watched_dirs(), vec![dir.clone(), root().join("wgsl")]);
    let kernel = voltex::gpu::shader::load_from(&sources, "tint.wgsl").unwrap();
    assert_eq!(kernel.files, vec![dir.join("tint.wgsl"), root().join("wgsl/shared/fullscreen.wgsl")]);
    std::fs::remove_dir_all(&dir).ok();
}
