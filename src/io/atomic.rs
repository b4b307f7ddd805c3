//! Atomic file writes: write a temporary file beside the target, fsync it, rename it over the
//! target. A failed write removes the temporary file and leaves the target untouched.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::{Error, Result};

/// Distinguishes temporary files of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// The folder a file `path` would be written into (`.` for a bare file name).
fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Fails with [`Error::File`] naming `dir` unless it is an existing folder we can create files
/// in. Called before rendering starts so that a bad output folder fails early. It probes by
/// creating and removing a small hidden file, since permission bits alone lie (root, ACLs,
/// read-only mounts).
pub fn check_writable_dir(dir: &Path) -> Result<()> {
    let meta = fs::metadata(dir)
        .map_err(|e| Error::file(dir, format!("output folder does not exist or is unreadable: {e}")))?;
    if !meta.is_dir() {
        return Err(Error::file(dir, "output folder is not a folder"));
    }
    let probe =
        dir.join(format!(".voltex-probe-{}-{}", std::process::id(), COUNTER.fetch_add(1, Ordering::Relaxed)));
    fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|e| Error::file(dir, format!("output folder is not writable: {e}")))?;
    let _ = fs::remove_file(&probe);
    Ok(())
}

/// Writes `path` atomically. `write` gets the path of a fresh temporary file in the same folder
/// (`.NAME.tmp-PID-N`) and must write the whole content there. Then the temporary file is
/// fsynced and renamed over `path`. On any error the temporary file is removed and `path` is left
/// as it was. A missing or unwritable folder is an [`Error::File`] naming the folder, raised
/// before anything is written; parent folders are never created.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    stage(path, write)?.commit()
}

/// A file written to its temporary name and flushed, not yet renamed over its target: several
/// files can be staged and then committed together, so that a failure in any leaves none of
/// them written. Dropped uncommitted, the temporary file is removed.
pub struct Staged {
    tmp: PathBuf,
    path: PathBuf,
    dir: PathBuf,
    done: bool,
}

/// Writes `path`'s content to a temporary file beside it (see [`write_atomic`]) and flushes it.
pub fn stage(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<Staged> {
    let dir = parent_dir(path);
    let name = path.file_name().ok_or_else(|| Error::file(path, "output path has no file name"))?;
    check_writable_dir(&dir)?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}-{}",
        name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let staged = Staged { tmp, path: path.to_path_buf(), dir, done: false };
    write(&staged.tmp).and_then(|()| flush(&staged.tmp, path))?;
    Ok(staged)
}

impl Staged {
    /// Size of the staged file in bytes.
    pub fn bytes(&self) -> u64 {
        std::fs::metadata(&self.tmp).map_or(0, |m| m.len())
    }

    /// Renames the temporary file over the target.
    pub fn commit(mut self) -> Result<()> {
        let result = rename(&self.tmp, &self.path, &self.dir);
        self.done = result.is_ok();
        result
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.done {
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// fsync the finished temporary file.
fn flush(tmp: &Path, path: &Path) -> Result<()> {
    let file = fs::File::open(tmp).map_err(|e| Error::file(path, format!("writer produced no file: {e}")))?;
    file.sync_all().map_err(|e| Error::file(path, format!("cannot flush to disk: {e}")))
}

/// Rename the temporary file over the target, fsync the folder.
fn rename(tmp: &Path, path: &Path, dir: &Path) -> Result<()> {
    crate::fault::at_write();
    fs::rename(tmp, path).map_err(|e| Error::file(path, format!("cannot replace file: {e}")))?;
    // Make the rename itself durable; not all platforms can open a folder, so best effort.
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |tmp| {
        fs::write(tmp, bytes).map_err(|e| Error::file(path, format!("cannot write: {e}")))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_appear_only_when_committed() {
        let dir = std::env::temp_dir().join(format!("voltex-staged-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let write =
            |text: &'static str| move |tmp: &Path| fs::write(tmp, text).map_err(|e| Error::file(tmp, e));
        let a = stage(&dir.join("a.txt"), write("a")).unwrap();
        let b = stage(&dir.join("b.txt"), write("b")).unwrap();
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 2, "two temporary files");
        assert!(!dir.join("a.txt").exists());
        a.commit().unwrap();
        drop(b); // a later failure: b is never committed
        let names: Vec<_> = fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, ["a.txt"]);
        fs::remove_dir_all(&dir).unwrap();
    }
}
