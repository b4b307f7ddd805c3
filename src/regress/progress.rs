//! Progress on stderr: a `\r`-updated bar with an ETA when stderr is a terminal (failures printed
//! above it as they come), one line per finished scene otherwise (logs, CI, tests); nothing with
//! `--quiet`, and each scene's warnings too with `--verbose`.

use std::io::{IsTerminal, Write};
use std::time::Instant;

use super::record::{Record, Status};

/// How much a run says on stderr.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verbosity {
    Quiet,
    Normal,
    Verbose,
}

pub(super) struct Progress {
    total: usize,
    done: usize,
    /// Scenes rendered (not kept as current): the ETA is their mean time.
    rendered: usize,
    running: Vec<String>,
    tty: bool,
    verbosity: Verbosity,
    start: Instant,
}

const WIDTH: usize = 100;

impl Progress {
    pub fn new(total: usize, verbosity: Verbosity) -> Self {
        let tty = std::io::stderr().is_terminal() && verbosity != Verbosity::Quiet;
        let p =
            Self { total, done: 0, rendered: 0, running: Vec::new(), tty, verbosity, start: Instant::now() };
        p.draw();
        p
    }

    /// `, ETA 1:05` from the mean time of the scenes rendered so far (none before the first).
    fn eta(&self) -> String {
        let left = self.total - self.done;
        if left == 0 || self.rendered == 0 {
            return String::new();
        }
        let secs = self.start.elapsed().as_secs_f64() / self.rendered as f64 * left as f64;
        let secs = secs.round() as u64;
        format!(", ETA {}:{:02}", secs / 60, secs % 60)
    }

    pub fn started(&mut self, scene: &str) {
        self.running.push(scene.to_string());
        self.draw();
    }

    /// `skipped`: the record is an earlier run's, still current.
    pub fn finished(&mut self, rec: &Record, skipped: bool) {
        self.done += 1;
        self.rendered += usize::from(!skipped);
        self.running.retain(|s| s != &rec.scene);
        if self.verbosity == Verbosity::Quiet {
            return;
        }
        let current = if skipped { " (current, not rendered again)" } else { "" };
        let mut line = format!("[{}/{}{}] {}{current}", self.done, self.total, self.eta(), result_line(rec));
        if self.verbosity == Verbosity::Verbose {
            for w in &rec.warnings {
                line += &format!("\n    warning: {w}");
            }
        }
        if self.tty {
            // Passing scenes only move the bar; the others stay on screen.
            if rec.status != Status::Pass {
                eprint!("\r{:WIDTH$}\r{line}\n", "");
            }
            self.draw();
        } else {
            eprintln!("{line}");
        }
    }

    /// A line that is not about one scene (a fatal error, say).
    pub fn note(&self, text: &str) {
        if self.verbosity == Verbosity::Quiet && !text.starts_with("error") {
            return;
        }
        if self.tty {
            eprint!("\r{:WIDTH$}\r", "");
        }
        eprintln!("{text}");
        self.draw();
    }

    pub fn end(&self) {
        if self.tty {
            eprint!("\r{:WIDTH$}\r", "");
            let _ = std::io::stderr().flush();
        }
    }

    fn draw(&self) {
        if !self.tty {
            return;
        }
        const BAR: usize = 24;
        let filled = (self.done * BAR).checked_div(self.total).unwrap_or(BAR);
        let mut line = format!(
            "[{}{}] {}/{}{} {}",
            "#".repeat(filled),
            "-".repeat(BAR - filled),
            self.done,
            self.total,
            self.eta(),
            self.running.join(", ")
        );
        if line.chars().count() > WIDTH {
            line = line.chars().take(WIDTH - 3).collect::<String>() + "...";
        }
        eprint!("\r{line:WIDTH$}");
        let _ = std::io::stderr().flush();
    }
}

/// `scene: status (FLIP x, rel RMSE y, z ms GPU): message`.
pub(super) fn result_line(rec: &Record) -> String {
    let mut s = format!("{}: {}", rec.scene, rec.status.label());
    if rec.updated {
        s += " (reference updated)";
    }
    if let (Some(f), Some(r)) = (rec.flip, rec.rel_rmse) {
        s += &format!(" (FLIP {f:.5}, rel RMSE {r:.5}");
        if let Some(g) = rec.gpu_ms {
            s += &format!(", {g:.1} ms GPU");
        }
        if let Some(t) = rec.truth_flip {
            s += &format!(", FLIP {t:.5} against the truth");
        }
        s += ")";
    }
    if let Some(m) = rec.message.as_ref().filter(|_| rec.status != Status::Pass || rec.updated) {
        s += &format!(": {m}");
    }
    s
}
