//! Watching the files a preview depends on: folders, recursively (editors save by writing a
//! temporary file and renaming it over the original, which a watch on the file itself loses), with
//! a debouncer that merges such a save and bursts of saves into one change.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use notify::event::{AccessKind, AccessMode, EventKind};
use notify::{RecommendedWatcher, RecursiveMode};
use notify_debouncer_full::{new_debouncer, DebounceEventResult, Debouncer, RecommendedCache};

use crate::error::{Error, Result};

/// Debounce time: peers use 100 to 300 ms; a save rarely takes longer than this.
pub const DEBOUNCE: Duration = Duration::from_millis(100);

/// File kinds a rebuild reads: scenes and graphs, kernels, meshes, height images.
const RELEVANT: &[&str] = &["ron", "wgsl", "obj", "png"];

pub struct Watcher {
    debouncer: Debouncer<RecommendedWatcher, RecommendedCache>,
    events: Receiver<DebounceEventResult>,
    dirs: Vec<PathBuf>,
    /// Folders whose changes are ours (recordings, screenshots), not the user's.
    pub ignore: Vec<PathBuf>,
}

impl Watcher {
    pub fn new(dirs: &[PathBuf]) -> Result<Self> {
        let (tx, events) = channel();
        let debouncer = new_debouncer(DEBOUNCE, None, move |r: DebounceEventResult| {
            let _ = tx.send(r);
        })
        .map_err(|e| Error::Invalid(format!("cannot watch files: {e}")))?;
        let mut w = Watcher { debouncer, events, dirs: Vec::new(), ignore: Vec::new() };
        w.watch(dirs)?;
        Ok(w)
    }

    /// Watches exactly `dirs` from now on.
    pub fn watch(&mut self, dirs: &[PathBuf]) -> Result<()> {
        for d in self.dirs.clone() {
            if !dirs.contains(&d) {
                let _ = self.debouncer.unwatch(&d);
                self.dirs.retain(|x| x != &d);
            }
        }
        for d in dirs {
            if !self.dirs.contains(d) {
                self.debouncer
                    .watch(d, RecursiveMode::Recursive)
                    .map_err(|e| Error::file(d, format!("cannot watch: {e}")))?;
                self.dirs.push(d.clone());
            }
        }
        Ok(())
    }

    /// Relevant paths changed since the last call, waiting up to `timeout` for the first.
    pub fn changes(&self, timeout: Duration) -> Vec<PathBuf> {
        let deadline = Instant::now() + timeout;
        let mut out = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.events.recv_timeout(if out.is_empty() { left } else { Duration::ZERO }) {
                Ok(Ok(events)) => {
                    for e in events.iter().filter(|e| changes_content(&e.event.kind)) {
                        let ours = |p: &PathBuf| self.ignore.iter().any(|d| p.starts_with(d));
                        out.extend(e.event.paths.iter().filter(|p| relevant(p) && !ours(p)).cloned());
                    }
                }
                Ok(Err(errors)) => {
                    for e in errors {
                        eprintln!("warning: file watch: {e}");
                    }
                }
                Err(RecvTimeoutError::Timeout) | Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        out.sort();
        out.dedup();
        out
    }
}

/// Whether an event can change what a rebuild reads: creations, modifications (renames and
/// metadata included: `touch` is a save), removals, and a writer closing the file. Opens and
/// reads are not: the rebuild's own reads of the files it watches come back as such events, and
/// counting them made a preview rebuild for ever after one save.
fn changes_content(kind: &EventKind) -> bool {
    match kind {
        EventKind::Create(_) | EventKind::Modify(_) | EventKind::Remove(_) => true,
        EventKind::Access(AccessKind::Close(AccessMode::Write)) => true,
        EventKind::Access(_) | EventKind::Any | EventKind::Other => false,
    }
}

fn relevant(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    // Editors' swap and backup files, and temporary files of atomic saves (ours included).
    if name.starts_with('.') || name.ends_with('~') || name.contains(".tmp") {
        return false;
    }
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| RELEVANT.contains(&e))
}
