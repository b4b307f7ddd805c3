//! Typed errors. Everything a user wrote (scene, graph, OBJ, WGSL) is reported with `file:line:col`.

use std::fmt;
use std::path::{Path, PathBuf};

/// A position in a user file, 1-based, printed as `path:line:col`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileLoc {
    /// The user file.
    pub path: PathBuf,
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1.
    pub col: usize,
}

impl FileLoc {
    /// Line `line`, column `col` (both 1-based) of `path`.
    pub fn new(path: impl AsRef<Path>, line: usize, col: usize) -> Self {
        Self { path: path.as_ref().to_path_buf(), line, col }
    }
}

impl fmt::Display for FileLoc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.path.display(), self.line, self.col)
    }
}

/// The library's error: where it happened (a position or a whole file) and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Something wrong at a known place in a user file.
    #[error("{loc}: {message}")]
    At {
        /// Where.
        loc: FileLoc,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A file that cannot be read or written, or is wrong as a whole.
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The GPU, its adapter or its limits.
    #[error("GPU: {0}")]
    Gpu(String),
    /// The GPU device was lost (driver reset, removed GPU, `VOLTEX_FAULT`): nothing more can run on
    /// it; a new device must be opened.
    #[error("GPU device lost: {0}")]
    DeviceLost(String),
    /// Invalid input that has no single position (for example a mesh-wide check).
    #[error("{0}")]
    Invalid(String),
}

impl Error {
    /// An error at `loc` in a user file.
    pub fn at(loc: FileLoc, message: impl Into<String>) -> Self {
        Error::At { loc, message: message.into() }
    }

    /// An error about file `path` as a whole.
    pub fn file(path: impl AsRef<Path>, message: impl fmt::Display) -> Self {
        Error::File { path: path.as_ref().to_path_buf(), message: message.to_string() }
    }
}

/// `Result` with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Line and column (1-based) of byte `offset` in `source`.
pub fn line_col(source: &str, offset: usize) -> (usize, usize) {
    let before = &source[..offset.min(source.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map(|i| offset - i).unwrap_or(offset + 1);
    (line, col)
}

/// Byte offset of 1-based `line` and `col` in `source` (the inverse of [`line_col`]).
pub(crate) fn offset_of(source: &str, line: usize, col: usize) -> usize {
    let start: usize = source.split_inclusive('\n').take(line.saturating_sub(1)).map(str::len).sum();
    (start + col.saturating_sub(1)).min(source.len())
}

/// Position of the string literal `"text"` in a RON source (the first one at or after byte
/// `from`), for errors found after parsing, when serde no longer knows where a value was.
pub(crate) fn locate_literal(source: &str, text: &str, from: usize) -> Option<(usize, usize)> {
    let needle = format!("\"{text}\"");
    let start = from.min(source.len());
    source[start..].find(&needle).map(|i| line_col(source, start + i))
}

/// Turns a ron error into `path:line:col: message`.
pub(crate) fn ron_error(path: &Path, e: &ron::error::SpannedError) -> Error {
    Error::at(FileLoc::new(path, e.span.start.line, e.span.start.col), e.code.to_string())
}

/// Runs `f`, catching a panic without the panic hook's message (the caller reports it as the
/// file's error). The hook is process-wide: a lock keeps two callers from swapping it at once.
pub fn quietly<T>(f: impl FnOnce() -> T + std::panic::UnwindSafe) -> std::thread::Result<T> {
    static HOOK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _held = HOOK.lock().unwrap_or_else(|e| e.into_inner());
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = std::panic::catch_unwind(f);
    std::panic::set_hook(hook);
    result
}
