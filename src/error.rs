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

    /// The error as the command line prints it: `error: ` and the error's line, then, for a
    /// position in a text file that can still be read, its source line with a caret under the
    /// word at the position (codespan-reporting).
    pub fn report(&self) -> String {
        let mut out = format!("error: {self}\n");
        if let Some(snippet) = match self {
            Error::At { loc, .. } => source_snippet(loc),
            _ => None,
        } {
            out.push_str(&snippet);
        }
        out
    }
}

/// Source lines longer than this are not quoted (a minified JSON or a binary file).
const SNIPPET_MAX_LINE: usize = 400;

/// `loc`'s source line with carets under the word there, or `None` where the file is not a
/// readable text file or has no such position.
fn source_snippet(loc: &FileLoc) -> Option<String> {
    use codespan_reporting::diagnostic::{Diagnostic, Label};
    use codespan_reporting::files::SimpleFile;
    use codespan_reporting::term;
    if !std::fs::metadata(&loc.path).ok()?.is_file() {
        return None;
    }
    let source = std::fs::read_to_string(&loc.path).ok()?;
    let line = source.lines().nth(loc.line.checked_sub(1)?)?;
    if line.len() > SNIPPET_MAX_LINE || loc.col == 0 || loc.col > line.len() + 1 {
        return None;
    }
    let start = offset_of(&source, loc.line, loc.col);
    // The word (name, number, string) at the position, or its one character.
    let rest = &source[start..];
    let word = |c: char| c.is_alphanumeric() || matches!(c, '_' | '.' | '-' | '+');
    let len = match rest.chars().next() {
        Some('"') => rest[1..].find(['"', '\n']).map_or(1, |n| n + 2),
        Some(c) if word(c) => rest.find(|c: char| !word(c)).unwrap_or(rest.len()),
        Some(c) if c != '\n' => c.len_utf8(),
        _ => 0,
    };
    let file = SimpleFile::new(loc.path.display().to_string(), source.as_str());
    // The header line is ours (printed above); the snippet is the diagnostic's body.
    let diagnostic = Diagnostic::error().with_label(Label::primary((), start..start + len));
    let config = term::Config { chars: term::Chars::ascii(), ..term::Config::default() };
    let text = term::emit_into_string(&config, &file, &diagnostic).ok()?;
    // Drop codespan's own `error` header line: the position is already in ours.
    Some(text.split_once('\n')?.1.to_string())
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
