//! Special and oversized files through the real binary: FIFOs, devices, folders, sparse giants
//! and invalid UTF-8 are refused by name before anything is read (issue 19). A FIFO must never
//! block, so each run has a generous deadline after which it is killed and the test fails.

use crate::common::{self, root, s, scratch_dir};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// `voltex ARGS` (with `VOLTEX_ROOT` and extra environment), killed if it runs past a deadline
/// far beyond what an error needs: a hang is a failure, not a slow test.
fn voltex_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_voltex"));
    cmd.args(args).env("VOLTEX_ROOT", root()).stdout(Stdio::piped()).stderr(Stdio::piped());
    for (k, v) in env {
        cmd.env(k, v);
    }
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let mut child = cmd.spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("voltex {args:?} hung (killed)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[track_caller]
fn fails(out: &Output, words: &[&str]) {
    let err = common::stderr(out);
    assert_eq!(out.status.code(), Some(1), "expected exit status 1; stderr:\n{err}");
    assert!(!err.contains("panicked"), "{err}");
    for w in words {
        assert!(err.contains(w), "expected {w:?} in stderr:\n{err}");
    }
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

fn flat_box_with(surface: &str) -> String {
    let text = std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap();
    text.replacen("Plane(size: (2.0, 2.0), cells: (4, 4))", surface, 1)
}

#[test]
fn fifo_scene_and_graph_are_refused_without_blocking() {
    let dir = scratch_dir("voltex-hostile-fifo");
    let fifo = dir.join("x.ron");
    mkfifo(&fifo);
    fails(&voltex_env(&["plan", s(&fifo)], &[]), &[s(&fifo), "found a FIFO"]);
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = voltex_env(&["plan", s(&scene), "--graph", s(&fifo)], &[]);
    fails(&out, &[s(&fifo), "expected a graph file", "found a FIFO"]);
}

#[test]
fn device_and_folder_as_a_scene() {
    fails(&voltex_env(&["plan", "/dev/zero"], &[]), &["/dev/zero", "found a character device"]);
    let dir = scratch_dir("voltex-hostile-folder");
    fails(&voltex_env(&["plan", s(&dir)], &[]), &["found a folder"]);
}

#[test]
fn fifo_included_by_a_kernel_is_an_error_at_the_include() {
    let dir = scratch_dir("voltex-hostile-include");
    let r = dir.join("root");
    common::copy_dir(&root().join("wgsl"), &r.join("wgsl"));
    common::copy_dir(&root().join("graphs"), &r.join("graphs"));
    let kernel = r.join("wgsl/composite.wgsl");
    let text = std::fs::read_to_string(&kernel).unwrap();
    std::fs::write(&kernel, format!("#include \"shared/pipe.wgsl\"\n{text}")).unwrap();
    mkfifo(&r.join("wgsl/shared/pipe.wgsl"));
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = voltex_env(&["plan", s(&scene)], &[("VOLTEX_ROOT", s(&r))]);
    fails(&out, &[&format!("{}:1:1: cannot include shared/pipe.wgsl", kernel.display()), "found a FIFO"]);
}

/// Issue 19: an include in a bake kernel passed `plan` and hung `render`; bake kernels are now
/// loaded and checked by `plan` too, so the error comes before any GPU work.
#[test]
fn fifo_included_by_a_bake_kernel_is_a_plan_error() {
    let dir = scratch_dir("voltex-hostile-bake-include");
    let r = dir.join("root");
    common::copy_dir(&root().join("wgsl"), &r.join("wgsl"));
    common::copy_dir(&root().join("graphs"), &r.join("graphs"));
    let kernel = r.join("wgsl/bake/bake_implicit.wgsl");
    let text = std::fs::read_to_string(&kernel).unwrap();
    std::fs::write(&kernel, format!("{text}#include \"shared/pipe.wgsl\"\n")).unwrap();
    mkfifo(&r.join("wgsl/shared/pipe.wgsl"));
    let line = text.lines().count() + 1;
    let scene = root().join("scenes/meyer_neyret/pear_grazing.ron");
    let at = format!("{}:{line}:1: cannot include shared/pipe.wgsl", kernel.display());
    let exr = dir.join("x.exr");
    for args in [&["plan", s(&scene)][..], &["render", s(&scene), "--size", "8x8", "-o", s(&exr)]] {
        fails(&voltex_env(args, &[("VOLTEX_ROOT", s(&r))]), &[&at, "found a FIFO"]);
    }
    assert!(!exr.exists());
}

#[test]
fn sparse_giant_and_fifo_as_obj_paths() {
    let dir = scratch_dir("voltex-hostile-obj");
    // Sparse: no disk is used, and nothing may read it.
    let big = std::fs::File::create(dir.join("big.obj")).unwrap();
    big.set_len(6 << 30).unwrap();
    mkfifo(&dir.join("pipe.obj"));
    for (name, words) in [
        ("big.obj", ["at most 256.0 MiB", "VOLTEX_MAX_FILE_BYTES"]),
        ("pipe.obj", ["found a FIFO", "mesh file"]),
    ] {
        let text = flat_box_with(&format!("Obj(path: \"{name}\")"));
        let scene = dir.join("scene.ron");
        std::fs::write(&scene, &text).unwrap();
        let out = voltex_env(&["plan", s(&scene)], &[]);
        let at = text.find(&format!("\"{name}\"")).unwrap();
        let line = text[..at].matches('\n').count() + 1;
        let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
        let loc = format!("{}:{line}:{col}: ", scene.display());
        fails(&out, &[&loc, name, words[0], words[1]]);
    }
}

#[test]
fn the_cap_is_stated_and_can_be_changed() {
    let scene = root().join("scenes/view_slices/flat_box.ron");
    let out = voltex_env(&["plan", s(&scene)], &[("VOLTEX_MAX_FILE_BYTES", "100")]);
    fails(&out, &["expected a scene file of at most 100 bytes", "VOLTEX_MAX_FILE_BYTES"]);
    let out = voltex_env(&["plan", s(&scene)], &[("VOLTEX_MAX_FILE_BYTES", "lots")]);
    fails(&out, &["VOLTEX_MAX_FILE_BYTES", "`lots`"]);
    let out = voltex_env(&["plan", s(&scene)], &[("VOLTEX_MAX_FILE_BYTES", "1G")]);
    assert!(out.status.success(), "{}", common::stderr(&out));
}

#[test]
fn invalid_utf8_is_reported_at_its_position() {
    let dir = scratch_dir("voltex-hostile-utf8");
    let mut text = flat_box_with("Plane(size: (2.0, 2.0), cells: (4, 4))").into_bytes();
    let at = text.iter().position(|&b| b == b'(').unwrap();
    text.insert(at + 1, 0xff);
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, &text).unwrap();
    let line = text[..at].iter().filter(|&&b| b == b'\n').count() + 1;
    let col = at + 1 - text[..at].iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1) + 1;
    let out = voltex_env(&["plan", s(&scene)], &[]);
    fails(&out, &[&format!("{}:{line}:{col}: expected UTF-8 text", scene.display())]);
}

/// Point sets of hypertexture `Points` objects (`voltex plan`): a FIFO refused without blocking,
/// a binary PLY cut short at its byte, a header over the point budget at its line:col, a
/// non-finite OBJ coordinate at its line:col; exit status 1, no panic.
#[test]
fn hostile_point_sets_are_refused_at_their_position() {
    let dir = scratch_dir("voltex-hostile-points");
    mkfifo(&dir.join("fifo.ply"));
    let head = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nend_header\n";
    let mut short = head.as_bytes().to_vec();
    short.extend([0u8; 20]);
    std::fs::write(dir.join("short.ply"), &short).unwrap();
    std::fs::write(dir.join("huge.ply"), head.replace("vertex 2", "vertex 2000000")).unwrap();
    std::fs::write(dir.join("inf.obj"), "v 0 0 0\nv 1 2 -inf\n").unwrap();
    for (file, words) in [
        ("fifo.ply", vec!["fifo.ply", "found a FIFO"]),
        ("short.ply", vec!["short.ply: byte ", "expected 2 vertices of 12 bytes, found 1"]),
        ("huge.ply", vec!["huge.ply:3:16: 2000000 points: at most 1048576 are allowed"]),
        ("inf.obj", vec!["inf.obj:2:7: expected `v x y z` with finite numbers, found `-inf`"]),
    ] {
        let scene = dir.join("scene.ron");
        let text = format!(
            "Scene(output: (width: 8, height: 8), camera: (eye: (0, -3, 0), target: (0, 0, 0)), hypertextures: {{ \
             \"h\": (object: Points(path: \"{file}\", radius: 0.1), noises: [(shape: Table([0.0, 1.0]), amplitude: \
             0.1, frequency: 2.0)], color: Step(threshold: 0.3, color: (1, 1, 1))) }}, nodes: [(name: \"n\", \
             hypertexture: \"h\", method: RayMarch(step: 0.05))])"
        );
        std::fs::write(&scene, text).unwrap();
        fails(&voltex_env(&["plan", s(&scene)], &[]), &words);
    }
}
