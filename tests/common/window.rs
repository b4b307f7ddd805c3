//! The preview window under Xvfb with software Vulkan (`xvfb-run`, package `xvfb`; `.ci/run`
//! installs it): started with `--record`, waited on frame by frame, stopped.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A running `voltex preview` recording its frames into `record`.
pub struct Preview {
    child: Child,
    pub record: PathBuf,
    /// `DISPLAY` and `XAUTHORITY` of its X server (written by the wrapper into this file).
    display: PathBuf,
}

impl Preview {
    /// `voltex preview scene --size size --quit-after 60 --record record`, with `env` set, in its
    /// own process group so that the window under xvfb-run ends with it.
    pub fn start(scene: &Path, size: &str, record: PathBuf, env: &[(&str, &str)]) -> Preview {
        use std::os::unix::process::CommandExt;
        let display = record.with_extension("display");
        let _ = std::fs::remove_file(&display);
        // A shell between xvfb-run and voltex notes the server for `xdo`.
        let script = format!("echo \"$DISPLAY $XAUTHORITY\" > '{}'; exec \"$@\"", display.display());
        let child = Command::new("xvfb-run")
            .process_group(0)
            .args(["-a", "-s", "-screen 0 1280x800x24", "sh", "-c", &script, "sh"])
            .args([env!("CARGO_BIN_EXE_voltex"), "preview"])
            .arg(scene)
            .args(["--size", size, "--quit-after", "90", "--record"])
            .arg(&record)
            .current_dir(scene.parent().unwrap())
            .env("VOLTEX_ROOT", super::root())
            .envs(env.iter().copied())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        Preview { child, record, display }
    }

    /// Runs `xdotool args` on the window's X server (synthetic input, as a user's).
    pub fn xdo(&self, args: &[&str]) -> String {
        let text = std::fs::read_to_string(&self.display).expect("the X server's display");
        let mut it = text.split_whitespace();
        let (d, a) = (it.next().unwrap(), it.next().unwrap_or(""));
        let out = Command::new("xdotool").args(args).env("DISPLAY", d).env("XAUTHORITY", a).output().unwrap();
        assert!(out.status.success(), "xdotool {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    /// Focuses the preview's window (Xvfb has no window manager to do it).
    pub fn focus(&self) -> String {
        let id = self.xdo(&["search", "--sync", "--name", "voltex preview"]);
        let id = id.lines().next().unwrap().to_string();
        self.xdo(&["windowfocus", "--sync", &id]);
        id
    }

    /// Does `act`, then waits for the frames it causes to end (none for `quiet` ms): the last
    /// frame's number.
    pub fn after(&mut self, act: impl FnOnce(&Self)) -> usize {
        let before = self.frames();
        act(self);
        let deadline = Instant::now() + Duration::from_secs(60);
        while self.frames() == before {
            if let Ok(Some(status)) = self.child.try_wait() {
                panic!("the preview exited ({status})");
            }
            assert!(Instant::now() < deadline, "no new frame within a minute");
            std::thread::sleep(Duration::from_millis(50));
        }
        let mut n = self.frames();
        loop {
            std::thread::sleep(Duration::from_millis(700));
            let now = self.frames();
            if now == n {
                return n - 1;
            }
            n = now;
        }
    }

    /// Waits (30 s at most) until `cond` holds for the last recorded frame; returns its number.
    pub fn until(&mut self, what: &str, cond: impl Fn(&Self, usize) -> bool) -> usize {
        match self.within(30, what, cond) {
            Ok(n) => n,
            Err(n) => panic!("not within 30 s: {what}; last frame: {}", self.state(n)),
        }
    }

    /// Waits `secs` at most until `cond` holds for the last recorded frame: its number, or the
    /// last frame's number as the error.
    pub fn within(
        &mut self,
        secs: u64,
        what: &str,
        cond: impl Fn(&Self, usize) -> bool,
    ) -> Result<usize, usize> {
        let deadline = Instant::now() + Duration::from_secs(secs);
        loop {
            let n = self.frames().saturating_sub(1);
            // A frame's PNG is renamed into place after its JSON: both are there.
            if self.frames() > 0 && cond(self, n) {
                return Ok(n);
            }
            if let Ok(Some(status)) = self.child.try_wait() {
                panic!("the preview exited ({status}) waiting for {what}");
            }
            if Instant::now() > deadline {
                return Err(n);
            }
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// What recorded frame `n` shows besides its pixels (`frame-n.json`).
    pub fn state(&self, n: usize) -> serde_json::Value {
        let text = std::fs::read_to_string(self.record.join(format!("frame-{n}.json"))).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    /// Recorded frame `n` (`frame-n.png`), waited for (a minute at most).
    pub fn frame(&mut self, n: usize) -> PathBuf {
        let path = self.record.join(format!("frame-{n}.png"));
        let deadline = Instant::now() + Duration::from_secs(60);
        while !path.exists() {
            if let Ok(Some(status)) = self.child.try_wait() {
                panic!("the preview exited ({status}) before writing {}", path.display());
            }
            assert!(Instant::now() < deadline, "no {} within a minute", path.display());
            std::thread::sleep(Duration::from_millis(50));
        }
        // The PNG is written atomically; give the window a moment before the next step.
        std::thread::sleep(Duration::from_millis(200));
        path
    }

    /// How many frames have been recorded so far.
    pub fn frames(&self) -> usize {
        std::fs::read_dir(&self.record)
            .map(|d| {
                d.filter_map(|e| e.ok())
                    .filter(|e| {
                        let name = e.file_name();
                        let name = name.to_string_lossy();
                        name.starts_with("frame-") && name.ends_with(".png")
                    })
                    .count()
            })
            .unwrap_or(0)
    }

    /// Ends the window (its whole process group) and returns what it printed.
    pub fn stop(self) -> Output {
        let _ = Command::new("kill").args(["-TERM", "--", &format!("-{}", self.child.id())]).status();
        self.child.wait_with_output().unwrap()
    }
}
