//! The real preview window under Xvfb with software Vulkan: it shows the scene, and after the
//! scene file changes on disk the next frame it shows differs. Needs `xvfb-run` (package `xvfb`;
//! `.ci/run` installs it).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

fn wait_for(path: &Path, child: &mut std::process::Child) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while !path.exists() {
        if let Ok(Some(status)) = child.try_wait() {
            panic!("the preview exited ({status}) before writing {}", path.display());
        }
        assert!(Instant::now() < deadline, "no {} within a minute", path.display());
        std::thread::sleep(Duration::from_millis(50));
    }
    // The PNG is written atomically; give the window a moment before the next step.
    std::thread::sleep(Duration::from_millis(200));
}

#[test]
fn window_shows_the_scene_and_follows_its_file() {
    let have_xvfb =
        Command::new("xvfb-run").arg("--help").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok();
    assert!(have_xvfb, "xvfb-run is missing: apt-get install -y xvfb (.ci/run installs it)");
    let dir = std::env::temp_dir().join(format!("voltex-window-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("scenes/view_slices/flat_box.ron")).unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, &text).unwrap();
    let record = dir.join("frames");
    // Its own process group, so that the window under xvfb-run ends with it.
    use std::os::unix::process::CommandExt;
    let mut child = Command::new("xvfb-run")
        .process_group(0)
        .args(["-a", "-s", "-screen 0 1280x800x24", BIN, "preview"])
        .arg(&scene)
        .args(["--size", "64x64", "--quit-after", "60", "--record"])
        .arg(&record)
        .env("VOLTEX_ROOT", root)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = record.join("frame-0.png");
    wait_for(&first, &mut child);
    let t = Instant::now();
    std::fs::write(&scene, text.replacen("color: (0.8, 0.6, 0.4)", "color: (0.2, 0.4, 0.9)", 1)).unwrap();
    // A watcher may see the file half written (truncated, then filled) and redraw the last good
    // state first; the change shows in one of the next frames.
    let (_, _, a) = voltex::io::png::read_rgba8(&first).unwrap();
    let mut n = 1;
    let second = loop {
        let next = record.join(format!("frame-{n}.png"));
        wait_for(&next, &mut child);
        let (_, _, b) = voltex::io::png::read_rgba8(&next).unwrap();
        if n == 4 || a.iter().zip(&b).filter(|(p, q)| p != q).count() > a.len() / 10 {
            break next;
        }
        n += 1;
    };
    eprintln!("window: save to recorded frame {n} in {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
    let _ = Command::new("kill").args(["-TERM", "--", &format!("-{}", child.id())]).status();
    let out = child.wait_with_output().unwrap();
    let (w, h, a) = voltex::io::png::read_rgba8(&first).unwrap();
    let (_, _, b) = voltex::io::png::read_rgba8(&second).unwrap();
    assert!(w >= 64 && h >= 64);
    // The fog turned from orange to blue: many pixels change, blue rises.
    let changed = a.iter().zip(&b).filter(|(p, q)| p != q).count();
    let blue = |img: &[[u8; 4]]| img.iter().map(|p| p[2] as u64).sum::<u64>();
    assert!(
        changed > a.len() / 10,
        "{changed} of {} pixels changed; stderr: {}",
        a.len(),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(blue(&b) > blue(&a));
    std::fs::remove_dir_all(&dir).ok();
}

/// `VOLTEX_FAULT` destroys the device in the first frame: the window opens a new device and
/// shows the scene rendered on it (frames are recorded only after a successful render).
#[test]
fn window_recovers_from_a_lost_device() {
    let dir = std::env::temp_dir().join(format!("voltex-window-lost-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let record = dir.join("frames");
    use std::os::unix::process::CommandExt;
    let mut child = Command::new("xvfb-run")
        .process_group(0)
        .args(["-a", "-s", "-screen 0 1280x800x24", BIN, "preview"])
        .arg(root.join("scenes/view_slices/flat_box.ron"))
        .args(["--size", "64x64", "--quit-after", "60", "--record"])
        .arg(&record)
        .env("VOLTEX_ROOT", root)
        .env("VOLTEX_FAULT", "device-lost@pass:1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = record.join("frame-0.png");
    wait_for(&first, &mut child);
    let _ = Command::new("kill").args(["-TERM", "--", &format!("-{}", child.id())]).status();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("VOLTEX_FAULT: destroying the GPU device"), "{err}");
    assert!(err.contains("GPU device lost") && err.contains("opening a new one"), "{err}");
    let (w, h, pixels) = voltex::io::png::read_rgba8(&first).unwrap();
    // The box covers the middle of the frame: bright, not the black background.
    let centre = pixels[(h / 2 * w + w / 2) as usize];
    assert!(centre[0] > 100 && centre[1] > 80, "centre pixel {centre:?}; stderr: {err}");
    std::fs::remove_dir_all(&dir).ok();
}

fn frames_in(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok()).filter(|e| e.path().extension().is_some_and(|x| x == "png")).count()
        })
        .unwrap_or(0)
}

/// One save (`touch`) rebuilds once and the preview then settles: the rebuild's own reads of
/// the files it watches must not come back as changes (they once made it rebuild for ever).
#[test]
fn window_settles_after_one_save() {
    let dir = std::env::temp_dir().join(format!("voltex-window-idle-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = dir.join("scene.ron");
    std::fs::copy(root.join("scenes/view_slices/flat_box.ron"), &scene).unwrap();
    let record = dir.join("frames");
    use std::os::unix::process::CommandExt;
    let mut child = Command::new("xvfb-run")
        .process_group(0)
        .args(["-a", "-s", "-screen 0 1280x800x24", BIN, "preview"])
        .arg(&scene)
        .args(["--size", "32x32", "--quit-after", "60", "--record"])
        .arg(&record)
        .env("VOLTEX_ROOT", root)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&record.join("frame-0.png"), &mut child);
    std::thread::sleep(Duration::from_secs(2));
    let idle = frames_in(&record);
    let status = Command::new("touch").arg(&scene).status().unwrap();
    assert!(status.success());
    std::thread::sleep(Duration::from_secs(6));
    let after_save = frames_in(&record);
    std::thread::sleep(Duration::from_secs(4));
    let settled = frames_in(&record);
    let _ = Command::new("kill").args(["-TERM", "--", &format!("-{}", child.id())]).status();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(idle, 1, "an idle preview draws one frame; stderr: {err}");
    assert!(after_save - idle <= 2, "one save drew {} frames; stderr: {err}", after_save - idle);
    assert_eq!(settled, after_save, "still drawing 6 s after the save; stderr: {err}");
    std::fs::remove_dir_all(&dir).ok();
}
