//! Progress on stderr: a `\r`-updated bar when stderr is a terminal (failures printed above it as
//! they come), one line per finished scene otherwise (logs, CI, tests).

use std::io::{IsTerminal, Write};

use super::record::{Record, Status};

pub(super) struct Progress {
    total: usize,
    done: usize,
    running: Vec<String>,
    tty: bool,
}

const WIDTH: usize = 100;

impl Progress {
    pub fn new(total: usize) -> Self {
        let p = Self { total, done: 0, running: Vec::new(), tty: std::io::stderr().is_terminal() };
        p.draw();
        p
    }

    pub fn started(&mut self, scene: &str) {
        self.running.push(scene.to_string());
        self.draw();
    }

    /// `skipped`: the record is an earlier run's, still current.
    pub fn finished(&mut self, rec: &Record, skipped: bool) {
        self.done += 1;
        self.running.retain(|s| s != &rec.scene);
        let current = if skipped { " (current, not rendered again)" } else { "" };
        let line = format!("[{}/{}] {}{current}", self.done, self.total, result_line(rec));
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
            "[{}{}] {}/{} {}",
            "#".repeat(filled),
            "-".repeat(BAR - filled),
            self.done,
            self.total,
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
        s += ")";
    }
    if let Some(m) = rec.message.as_ref().filter(|_| rec.status != Status::Pass || rec.updated) {
        s += &format!(": {m}");
    }
    s
}
