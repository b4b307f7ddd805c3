//! The preview window under Xvfb with software Vulkan (`xvfb-run`, package `xvfb`; `.ci/run`
//! installs it): started with `--record`, waited on frame by frame, stopped.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A running `voltex preview` recording its frames into `record`.
pub struct Preview {
    child: Child,
    pub record: PathBuf,
}

impl Preview {
    /// `voltex preview scene --size size --quit-after 60 --record record`, with `env` set, in its
    /// own process group so that the window under xvfb-run ends with it.
    pub fn start(scene: &Path, size: &str, record: PathBuf, env: &[(&str, &str)]) -> Preview {
        use std::os::unix::process::CommandExt;
        let child = Command::new("xvfb-run")
            .process_group(0)
            .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_voltex"), "preview"])
            .arg(scene)
            .args(["--size", size, "--quit-after", "60", "--record"])
            .arg(&record)
            .env("VOLTEX_ROOT", super::root())
            .envs(env.iter().copied())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        Preview { child, record }
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
                d.filter_map(|e| e.ok()).filter(|e| e.path().extension().is_some_and(|x| x == "png")).count()
            })
            .unwrap_or(0)
    }

    /// Ends the window (its whole process group) and returns what it printed.
    pub fn stop(self) -> Output {
        let _ = Command::new("kill").args(["-TERM", "--", &format!("-{}", self.child.id())]).status();
        self.child.wait_with_output().unwrap()
    }
}
