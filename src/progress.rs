//! Progress of a long command on stderr (regress, pareto, bake, export, a render's frame): a
//! `\r`-updated bar with an ETA when stderr is a terminal (notable lines printed above it as they
//! come), one line per finished item (or tenth of a frame) otherwise (logs, CI, tests); nothing
//! with `--quiet` but errors.

use std::io::{IsTerminal, Write};
use std::time::Instant;

/// How much a command says on stderr.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verbosity {
    /// Errors only (`--quiet`).
    Quiet,
    /// One line per finished item, or the bar on a terminal.
    Normal,
    /// Each item's warnings too (`--verbose`).
    Verbose,
}

impl Verbosity {
    /// Whether a long frame shows its progress (rendered in steps to do so): on a terminal, or
    /// when verbose (a line at each tenth).
    pub fn frame_progress(self) -> bool {
        self == Verbosity::Verbose || (self == Verbosity::Normal && std::io::stderr().is_terminal())
    }

    /// From the `--quiet` and `--verbose` flags (`--quiet` wins).
    pub fn from_flags(quiet: bool, verbose: bool) -> Self {
        match (quiet, verbose) {
            (true, _) => Verbosity::Quiet,
            (_, true) => Verbosity::Verbose,
            _ => Verbosity::Normal,
        }
    }
}

/// The progress of one command's items on stderr.
pub struct Progress {
    total: usize,
    done: usize,
    /// Items that did their work (not skipped as current): the ETA is their mean time.
    worked: usize,
    running: Vec<String>,
    tty: bool,
    pub(crate) verbosity: Verbosity,
    start: Instant,
}

const WIDTH: usize = 100;

impl Progress {
    /// Progress over `total` items, drawn at once on a terminal.
    pub fn new(total: usize, verbosity: Verbosity) -> Self {
        let tty = std::io::stderr().is_terminal() && verbosity != Verbosity::Quiet;
        let p =
            Self { total, done: 0, worked: 0, running: Vec::new(), tty, verbosity, start: Instant::now() };
        p.draw();
        p
    }

    /// `, ETA 1:05` from the mean time of the items worked so far (none before the first).
    fn eta(&self) -> String {
        let left = self.total - self.done;
        if left == 0 || self.worked == 0 {
            return String::new();
        }
        let secs = self.start.elapsed().as_secs_f64() / self.worked as f64 * left as f64;
        let secs = secs.round() as u64;
        format!(", ETA {}:{:02}", secs / 60, secs % 60)
    }

    /// `item` started (shown in the bar while it runs).
    pub fn started(&mut self, item: &str) {
        self.running.push(item.to_string());
        self.draw();
    }

    /// `item` is done and `line` says how. `worked`: it did its work (counts for the ETA);
    /// `notable`: on a terminal the line stays above the bar (else only the bar moves).
    pub fn finished(&mut self, item: &str, line: &str, worked: bool, notable: bool) {
        self.done += 1;
        self.worked += usize::from(worked);
        if let Some(i) = self.running.iter().position(|s| s == item) {
            self.running.remove(i);
        }
        if self.verbosity == Verbosity::Quiet {
            return;
        }
        let line = format!("[{}/{}{}] {line}", self.done, self.total, self.eta());
        if self.tty {
            if notable {
                eprint!("\r{:WIDTH$}\r{line}\n", "");
            }
            self.draw();
        } else {
            eprintln!("{line}");
        }
    }

    /// One piece of work measured in units (a frame's dispatches) is `done` of the `total` units:
    /// the bar shows `what` on a terminal; otherwise a line at each tenth of the work.
    pub(crate) fn reach(&mut self, done: usize, what: &str) {
        let tenth = |n: usize| (n * 10).checked_div(self.total).unwrap_or(10);
        let before = tenth(self.done);
        self.done = done.min(self.total);
        self.worked = self.done;
        if self.verbosity == Verbosity::Quiet {
            return;
        }
        if self.tty {
            self.running = vec![what.to_string()];
            self.draw();
        } else if tenth(self.done) > before {
            let share = (self.done * 100).checked_div(self.total).unwrap_or(100);
            eprintln!("[{share}%{}] {what}: {} of {} units", self.eta(), self.done, self.total);
        }
    }

    /// A line that is not about one item (a fatal error, say); errors show even with `--quiet`.
    pub(crate) fn note(&self, text: &str) {
        if self.verbosity == Verbosity::Quiet && !text.starts_with("error") {
            return;
        }
        if self.tty {
            eprint!("\r{:WIDTH$}\r", "");
        }
        eprintln!("{text}");
        self.draw();
    }

    /// Clears the bar: the command is done.
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
