//! Faults during a render or a regression run: a lost device and out-of-memory (injected with
//! `VOLTEX_FAULT`, see `src/gpu/fault.rs`), an update of references killed at any point, and
//! output folders nobody (root included) can write into.

use crate::common;

use common::{entries, root, s, scratch_dir, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

use voltex::gpu::GpuContext;
use voltex::io::Image;
use voltex::preview::{Outcome, Session};
use voltex::regress::{Record, Status};
use voltex::render::RenderOptions;

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

/// A fresh folder for a test.
fn temp(test: &str) -> PathBuf {
    scratch_dir(&format!("voltex-faults-{test}"))
}

fn flat_box() -> String {
    std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap()
}

/// `n` copies of the flat box scene named a.ron, b.ron, ... in `dir`.
fn scenes(dir: &Path, n: usize) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    (0..n)
        .map(|i| {
            let p = dir.join(format!("{}.ron", (b'a' + i as u8) as char));
            std::fs::write(&p, flat_box()).unwrap();
            p
        })
        .collect()
}

fn voltex(args: &[&str], fault: Option<&str>) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args).env("VOLTEX_ROOT", root()).env_remove("VOLTEX_FAULT");
    if let Some(f) = fault {
        cmd.env("VOLTEX_FAULT", f);
    }
    cmd.output().unwrap()
}

#[test]
fn render_fails_cleanly_on_a_lost_device_and_out_of_memory() {
    let dir = temp("render");
    let scene = scenes(&dir.join("scenes"), 1).remove(0);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let exr = out.join("a.exr");
    for (fault, words) in [
        ("device-lost@pass:1", &["error: GPU device lost", "destroyed"][..]),
        ("device-lost@pass:3", &["error: GPU device lost"][..]),
        ("oom@pass:2", &["error: GPU: Out of Memory", "smaller --size"][..]),
    ] {
        let run = voltex(&["render", s(&scene), "-o", s(&exr), "--size", "32x32"], Some(fault));
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{fault}: {err}");
        for w in words {
            assert!(err.contains(w), "{fault}: expected {w:?} in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
        assert!(entries(&out).is_empty(), "{fault}: wrote {:?}", entries(&out));
    }
    // The same command without a fault renders.
    let run = voltex(&["render", s(&scene), "-o", s(&exr), "--size", "32x32"], None);
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(entries(&out), ["a.exr", "a.png"]);
    let _ = std::fs::remove_dir_all(&dir);
}

fn record(out: &Path, name: &str) -> Record {
    Record::read(&out.join(name).join("result.json")).unwrap()
}

#[test]
fn regress_records_the_scene_a_fault_hit_and_goes_on() {
    let dir = temp("regress");
    let scene_dir = dir.join("scenes");
    scenes(&scene_dir, 3);
    let out = dir.join("out");
    let size = ["--size", "32x32"];
    let first =
        voltex(&[&["regress", s(&scene_dir), "--out", s(&out), "--update"][..], &size].concat(), None);
    assert!(first.status.success(), "{}", stderr(&first));
    for (fault, words) in [("device-lost@pass:1", "GPU device lost"), ("oom@pass:1", "Out of Memory")] {
        let run = voltex(&[&["regress", s(&scene_dir), "--out", s(&out)][..], &size].concat(), Some(fault));
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(3), "{fault}: a broken scene: {err}");
        assert!(!err.contains("panicked"), "{err}");
        // The first scene met the fault; a new device (after a loss) or the same one checked the rest.
        let a = record(&out, "a");
        assert_eq!(a.status, Status::BrokenScene, "{fault}");
        assert!(a.message.as_deref().unwrap_or("").contains(words), "{fault}: {:?}", a.message);
        assert!(!out.join("a/actual.exr").exists(), "{fault}: no image of the broken render");
        for name in ["b", "c"] {
            assert_eq!(record(&out, name).status, Status::Pass, "{fault}: {name}");
        }
        let text = String::from_utf8_lossy(&run.stdout);
        assert!(text.contains("2 pass, 1 broken scene"), "{fault}: {text}");
        assert!(out.join("index.html").exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn regress_stops_cleanly_when_no_new_device_opens() {
    let dir = temp("no_device");
    let scene_dir = dir.join("scenes");
    scenes(&scene_dir, 3);
    let out = dir.join("out");
    let run = voltex(
        &["regress", s(&scene_dir), "--out", s(&out), "--size", "32x32"],
        Some("device-lost@pass:1,no-device@open:2"),
    );
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(4), "no device is an engine failure: {err}");
    assert!(err.contains("error: GPU device lost") && err.contains("opening a new device failed"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // The scene that lost the device is recorded and reported; the others were not started.
    assert_eq!(record(&out, "a").status, Status::BrokenScene);
    assert!(!out.join("b").exists() && !out.join("c").exists());
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("a.ron"), "{index}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene folder whose references all differ from what `regress --update` will write, the old
/// reference bytes, and the render the update writes (read from a complete update of a copy).
struct UpdateSetup {
    scenes: PathBuf,
    old: Vec<(PathBuf, Vec<u8>)>,
    new: Image,
}

fn update_setup(dir: &Path, n: usize) -> UpdateSetup {
    let scene_dir = dir.join("scenes");
    scenes(&scene_dir, n);
    let run = voltex(
        &["regress", s(&scene_dir), "--out", s(&dir.join("first")), "--update", "--size", "32x32"],
        None,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let new = voltex::io::exr::read(&scene_dir.join("a.ref.exr")).unwrap().0;
    // Old references: darker versions of the render, so every scene regresses and is rewritten.
    let mut old = Vec::new();
    for i in 0..n {
        let path = scene_dir.join(format!("{}.ref.exr", (b'a' + i as u8) as char));
        let mut img = new.clone();
        for p in &mut img.pixels {
            for c in &mut p[..3] {
                *c *= 0.5 + 0.05 * i as f32;
            }
        }
        voltex::io::exr::write(&path, &img, &[]).unwrap();
        old.push((path.clone(), std::fs::read(&path).unwrap()));
    }
    UpdateSetup { scenes: scene_dir, old, new }
}

impl UpdateSetup {
    fn restore(&self) {
        for (path, bytes) in &self.old {
            std::fs::write(path, bytes).unwrap();
        }
    }

    /// Every reference is its old bytes or a complete new image; returns how many are new.
    fn check(&self, when: &str) -> usize {
        let mut updated = 0;
        for (path, bytes) in &self.old {
            let now = std::fs::read(path).unwrap_or_else(|e| panic!("{when}: {}: {e}", path.display()));
            if now == *bytes {
                continue;
            }
            let (img, meta) = voltex::io::exr::read(path)
                .unwrap_or_else(|e| panic!("{when}: {} is neither old nor readable: {e}", path.display()));
            assert!(meta.iter().any(|(k, _)| k == "voltex_regress_scene"), "{when}: {}", path.display());
            assert!(
                img.same_size(&self.new) && img.pixels == self.new.pixels,
                "{when}: {} differs",
                path.display()
            );
            updated += 1;
        }
        updated
    }

    fn update(&self, out: &Path, fault: Option<&str>) -> std::process::Child {
        let mut cmd = Command::new(BIN);
        cmd.args(["regress", s(&self.scenes), "--out", s(out), "--update", "--size", "32x32"])
            .env("VOLTEX_ROOT", root())
            .env_remove("VOLTEX_FAULT")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null());
        if let Some(f) = fault {
            cmd.env("VOLTEX_FAULT", f);
        }
        cmd.spawn().unwrap()
    }
}

#[test]
fn update_aborted_at_every_write_leaves_references_old_or_new() {
    let dir = temp("abort");
    let setup = update_setup(&dir, 2);
    // Abort inside the k-th atomic write (temporary file complete, not yet renamed), for every k
    // until a run gets through all its writes.
    let mut points = 0;
    for k in 1..100 {
        setup.restore();
        let status = setup.update(&dir.join("out"), Some(&format!("abort@write:{k}"))).wait().unwrap();
        let when = format!("abort at write {k}");
        let updated = setup.check(&when);
        if status.success() || status.code() == Some(1) {
            assert_eq!(updated, 2, "{when}: a completed update rewrites both references");
            break;
        }
        points += 1;
    }
    eprintln!("aborted at {points} write points");
    assert!(points >= 6, "only {points} write points were tried");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn update_killed_at_any_time_leaves_references_old_or_new() {
    let dir = temp("kill");
    let setup = update_setup(&dir, 3);
    setup.restore();
    let start = Instant::now();
    assert!(setup.update(&dir.join("out"), None).wait().unwrap().code() == Some(0));
    let whole = start.elapsed();
    assert_eq!(setup.check("complete run"), 3);
    // SIGKILL at fractions of a whole run's wall time (not asserted; it only spreads the kills).
    let mut seen = std::collections::BTreeSet::new();
    for k in 1..=8 {
        setup.restore();
        let mut child = setup.update(&dir.join("out"), None);
        std::thread::sleep(whole.mul_f64(k as f64 / 9.0));
        let _ = child.kill();
        let _ = child.wait();
        seen.insert(setup.check(&format!("killed at {k}/9 of a run")));
    }
    eprintln!("references updated when killed: {seen:?} (of 3)");
    // Leftover temporary files of killed writes are hidden and never taken for references.
    for name in entries(&setup.scenes) {
        assert!(name.ends_with(".ron") || name.ends_with(".ref.exr") || name.starts_with('.'), "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `/proc/self` is a folder in which no one, root included, can create a file.
const READ_ONLY: &str = "/proc/self";

#[test]
fn read_only_output_folder_fails_before_rendering() {
    assert!(std::fs::File::create(Path::new(READ_ONLY).join("probe")).is_err());
    let dir = temp("readonly");
    let scene = scenes(&dir.join("scenes"), 1).remove(0);
    let target = Path::new(READ_ONLY).join("x.exr");
    let run = voltex(&["render", s(&scene), "-o", s(&target), "--size", "32x32"], None);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: /proc/self: output folder is not writable"), "{err}");
    assert!(run.stdout.is_empty(), "nothing rendered");

    let run = voltex(&["regress", s(&dir.join("scenes")), "--out", READ_ONLY, "--size", "32x32"], None);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(3), "{err}");
    assert!(err.starts_with("error: /proc/self: output folder is not writable"), "{err}");
    assert!(!err.contains("[1/1]") && run.stdout.is_empty(), "nothing rendered: {err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn preview_session_re_renders_the_last_good_state_on_a_new_device() {
    let dir = temp("session");
    let scene = scenes(&dir, 1).remove(0);
    let options = RenderOptions { size: Some((32, 32)), ..Default::default() };
    let old = GpuContext::new().unwrap();
    let mut session = Session::open(&old, &scene, options);
    let good = session.render(&old).unwrap().unwrap().image;
    // The file breaks: the last good renderer stays.
    std::fs::write(&scene, "Scene(").unwrap();
    assert!(matches!(session.rebuild(&old), Outcome::Failed(_)));
    old.device.destroy();
    let Some(Err(err)) = session.render(&old) else { panic!("a render on a destroyed device succeeded") };
    assert!(matches!(err, voltex::Error::DeviceLost(_)), "{err}");
    assert!(old.lost().is_some());
    let new = GpuContext::new().unwrap();
    assert!(matches!(session.recover(&new), Outcome::Rebuilt(_)));
    let again = session.render(&new).unwrap().unwrap().image;
    assert!(again.same_size(&good) && again.pixels == good.pixels);
    assert!(
        session.error.as_deref().is_some_and(|e| e.contains("unexpected end of file")),
        "{:?}",
        session.error
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Found by `regress_stops_cleanly_when_no_new_device_opens`: the bake's parameter buffers were
/// made with wgpu's `create_buffer_init`, which panics on a lost device. Now building a renderer
/// (bakes included) on a lost device is an error.
#[test]
fn building_a_renderer_on_a_lost_device_is_an_error() {
    let scene = voltex::scene::load(&root().join("scenes/view_slices/flat_box.ron")).unwrap();
    let options = RenderOptions { size: Some((32, 32)), ..Default::default() };
    let bp = voltex::render::Blueprint::new(&scene, &options).unwrap();
    let ctx = GpuContext::new().unwrap();
    ctx.device.destroy();
    let err = voltex::render::Renderer::new(&ctx, bp).err().expect("no renderer on a lost device");
    assert!(matches!(err, voltex::Error::DeviceLost(_)), "{err}");
}

/// A camera move re-plans the last good scene without reading a file: with the scene file gone
/// (and so any asset it names unreadable), the view still moves and the frame changes; the
/// file's next read is what reports its absence.
#[test]
fn a_camera_move_reads_no_file() {
    let dir = temp("camera-move");
    let scene = scenes(&dir, 1).remove(0);
    let options = RenderOptions { size: Some((32, 32)), ..Default::default() };
    let ctx = GpuContext::new().unwrap();
    let mut session = Session::open(&ctx, &scene, options);
    let before = session.render(&ctx).unwrap().unwrap().image;
    let mut camera = *session.scene().unwrap().camera;
    std::fs::remove_file(&scene).unwrap();
    camera.eye = camera.target + (camera.eye - camera.target) * 1.5;
    session.options.camera = Some(camera);
    assert!(matches!(session.replan(&ctx), Outcome::Rebuilt(_)), "{:?}", session.error);
    let after = session.render(&ctx).unwrap().unwrap().image;
    assert!(after.same_size(&before) && after.pixels != before.pixels, "the view moved");
    assert!(session.error.is_none());
    assert!(matches!(session.rebuild(&ctx), Outcome::Failed(_)), "a rebuild reads the file");
    let _ = std::fs::remove_dir_all(&dir);
}
