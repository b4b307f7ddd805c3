//! Watching the files a preview depends on: folders, recursively (editors save by writing a
//! temporary file and renaming it over the original, which a watch on the file itself loses). A
//! change is reported once its files have been quiet for [`DEBOUNCE`], so that the steps of one
//! save (truncate, write, close; write a temporary file, rename it) and bursts of saves come as one.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use notify::event::{AccessKind, AccessMode, EventKind};
use notify::{Event, RecommendedWatcher, RecursiveMode, Watcher as _};

use crate::error::{Error, Result};

/// Quiet time after a save's last event. Editors write a save's steps within microseconds to a
/// few milliseconds of each other; a slower one may see its first step rebuilt alone (failing, or
/// not, on a half-written file), and its last step (a writer closing the file, a rename) always
/// triggers the rebuild that reads the finished file.
pub const DEBOUNCE: Duration = Duration::from_millis(10);
/// The longest a change waits for quiet (a file written without pause is still reported).
pub(crate) const SETTLE_MAX: Duration = Duration::from_millis(100);

/// File kinds a rebuild reads: scenes and graphs, kernels, meshes, height images.
const RELEVANT: &[&str] = &["ron", "wgsl", "obj", "png"];

/// Watches folders for changes to the files a rebuild reads (scenes, graphs, kernels, meshes,
/// images).
pub struct Watcher {
    watcher: RecommendedWatcher,
    events: Receiver<notify::Result<Event>>,
    dirs: Vec<PathBuf>,
    /// Folders whose changes are ours (recordings, screenshots), not the user's.
    pub(crate) ignore: Vec<PathBuf>,
}

impl Watcher {
    /// Watches `dirs` recursively.
    pub fn new(dirs: &[PathBuf]) -> Result<Self> {
        Self::with_wake(dirs, || {})
    }

    /// Like [`Watcher::new`], calling `wake` (from the watcher's thread) on every event that may
    /// be a change, so that a window's event loop looks at once.
    pub(crate) fn with_wake(dirs: &[PathBuf], wake: impl Fn() + Send + 'static) -> Result<Self> {
        let (tx, events) = channel();
        let watcher = notify::recommended_watcher(move |e: notify::Result<Event>| {
            let change = e.as_ref().map_or(true, |e| changes_content(&e.kind) || e.need_rescan());
            let _ = tx.send(e);
            if change {
                wake();
            }
        })
        .map_err(|e| Error::Invalid(format!("cannot watch files: {e}")))?;
        let mut w = Watcher { watcher, events, dirs: Vec::new(), ignore: Vec::new() };
        w.watch(dirs)?;
        Ok(w)
    }

    /// Watches exactly `dirs` from now on.
    pub(crate) fn watch(&mut self, dirs: &[PathBuf]) -> Result<()> {
        for d in self.dirs.clone() {
            if !dirs.contains(&d) {
                let _ = self.watcher.unwatch(&d);
                self.dirs.retain(|x| x != &d);
            }
        }
        for d in dirs {
            if !self.dirs.contains(d) {
                self.watcher
                    .watch(d, RecursiveMode::Recursive)
                    .map_err(|e| Error::file(d, format!("cannot watch: {e}")))?;
                self.dirs.push(d.clone());
            }
        }
        Ok(())
    }

    /// Relevant paths changed since the last call, waiting up to `timeout` for the first; once
    /// one came, until they are quiet for [`DEBOUNCE`] (at most `SETTLE_MAX`).
    pub fn changes(&self, timeout: Duration) -> Vec<PathBuf> {
        let deadline = Instant::now() + timeout;
        let mut out = Vec::new();
        let mut settle: Option<Instant> = None;
        loop {
            let now = Instant::now();
            let wait = match settle {
                None => deadline.saturating_duration_since(now),
                Some(first) => DEBOUNCE.min((first + SETTLE_MAX).saturating_duration_since(now)),
            };
            match self.events.recv_timeout(wait) {
                Ok(Ok(e)) => {
                    let before = out.len();
                    if e.need_rescan() {
                        // Events were lost: anything may have changed.
                        out.extend(self.dirs.iter().cloned());
                    } else if changes_content(&e.kind) {
                        let ours = |p: &PathBuf| self.ignore.iter().any(|d| p.starts_with(d));
                        out.extend(e.paths.iter().filter(|p| relevant(p) && !ours(p)).cloned());
                    }
                    if out.len() > before && settle.is_none() {
                        settle = Some(Instant::now());
                    }
                }
                Ok(Err(e)) => eprintln!("warning: file watch: {e}"),
                Err(RecvTimeoutError::Timeout) if settle.is_none() && Instant::now() < deadline => {}
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
