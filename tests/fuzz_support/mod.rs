//! Helpers of the fuzz targets: token-level mutations of example files, the error-position
//! property, and an allocator that records the peak of live bytes per thread.

pub mod ron_items;
pub mod runner;
pub mod slice;
pub mod special;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::Error;

/// One edit of a token list.
#[derive(Debug, Clone)]
pub enum Mutation {
    Delete(Index),
    Duplicate(Index),
    Swap(Index, Index),
    /// Replaces a number token with an awkward value.
    Number(Index, &'static str),
    /// Replaces a word token with another word of the file or a made-up one.
    Rename(Index, Index, &'static str),
    Insert(Index, String),
    Truncate(Index),
}

/// Awkward numbers a mutation puts in place of a number.
pub const NUMBERS: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e39",
    "-1",
    "0",
    "-0.0",
    "1e-45",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999999",
    "0.0",
    "1",
    "16384",
    "16385",
    "1024",
    "1025",
    "65536",
];
const WORDS: &[&str] = &["", "x", "Some", "None", "true", "NaN", "_", "é", "objects", "name", "0"];

impl Arbitrary for Mutation {
    type Parameters = ();
    type Strategy = BoxedStrategy<Mutation>;

    fn arbitrary_with((): ()) -> Self::Strategy {
        let text = prop::collection::vec(any::<char>(), 0..6).prop_map(|c| c.into_iter().collect::<String>());
        prop_oneof![
            2 => any::<Index>().prop_map(Mutation::Delete),
            1 => any::<Index>().prop_map(Mutation::Duplicate),
            1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::Swap(a, b)),
            3 => (any::<Index>(), prop::sample::select(NUMBERS)).prop_map(|(i, n)| Mutation::Number(i, n)),
            2 => (any::<Index>(), any::<Index>(), prop::sample::select(WORDS))
                .prop_map(|(i, j, w)| Mutation::Rename(i, j, w)),
            1 => (any::<Index>(), text).prop_map(|(i, t)| Mutation::Insert(i, t)),
            1 => any::<Index>().prop_map(Mutation::Truncate),
        ]
        .boxed()
    }
}

/// Splits RON or OBJ text into words (identifiers and numbers), string literals, single
/// punctuation characters and whitespace runs; concatenating the tokens gives the text back.
pub fn tokens(text: &str) -> Vec<String> {
    let word = |c: char| c.is_alphanumeric() || "_.+-".contains(c);
    let mut out: Vec<String> = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let mut t = String::from(c);
        if c == '"' {
            for n in chars.by_ref() {
                t.push(n);
                if n == '"' {
                    break;
                }
            }
        } else if word(c) || c.is_whitespace() {
            let same = |n: char| if word(c) { word(n) } else { n.is_whitespace() };
            while let Some(&n) = chars.peek() {
                if !same(n) {
                    break;
                }
                t.push(n);
                chars.next();
            }
        }
        out.push(t);
    }
    out
}

fn is_number(t: &str) -> bool {
    t.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+' || c == '.')
        && t.chars().any(|c| c.is_ascii_digit())
}

fn is_word(t: &str) -> bool {
    t.starts_with(|c: char| c.is_alphabetic() || c == '_')
}

/// Index of the `i`-th token (modulo) among those satisfying `keep`.
fn pick(toks: &[String], i: &Index, keep: impl Fn(&str) -> bool) -> Option<usize> {
    let idx: Vec<usize> = (0..toks.len()).filter(|&k| keep(&toks[k])).collect();
    (!idx.is_empty()).then(|| idx[i.index(idx.len())])
}

/// `text` with the mutations applied in order to its tokens (non-whitespace tokens for the
/// positional edits).
pub fn mutate(text: &str, muts: &[Mutation]) -> String {
    let mut toks = tokens(text);
    let solid = |t: &str| !t.trim().is_empty();
    for m in muts {
        match m {
            Mutation::Delete(i) => {
                if let Some(k) = pick(&toks, i, solid) {
                    toks.remove(k);
                }
            }
            Mutation::Duplicate(i) => {
                if let Some(k) = pick(&toks, i, solid) {
                    let t = toks[k].clone();
                    toks.insert(k, t);
                }
            }
            Mutation::Swap(i, j) => {
                if let (Some(a), Some(b)) = (pick(&toks, i, solid), pick(&toks, j, solid)) {
                    toks.swap(a, b);
                }
            }
            Mutation::Number(i, n) => {
                if let Some(k) = pick(&toks, i, is_number) {
                    toks[k] = n.to_string();
                }
            }
            Mutation::Rename(i, j, w) => {
                if let Some(k) = pick(&toks, i, is_word) {
                    // Half the time another word of the file, else a made-up one.
                    toks[k] = match pick(&toks, j, is_word) {
                        Some(o) if j.index(2) == 0 => toks[o].clone(),
                        _ => w.to_string(),
                    };
                }
            }
            Mutation::Insert(i, t) => {
                let k = if toks.is_empty() { 0 } else { i.index(toks.len() + 1) };
                toks.insert(k, t.clone());
            }
            Mutation::Truncate(i) => {
                let k = if toks.is_empty() { 0 } else { i.index(toks.len()) };
                toks.truncate(k);
            }
        }
    }
    toks.concat()
}

/// The error property: an error about `path` whose source is `text` names `path` and a
/// `line:col` inside the text. `strict`: the parse stage, where every error must be positioned
/// (or name a whole file); later stages may also report errors without a position.
pub fn check_error(e: &Error, path: &Path, text: &str, strict: bool) -> Result<(), String> {
    let shown = e.to_string();
    if shown.trim().is_empty() {
        return Err("empty error message".into());
    }
    match e {
        Error::At { loc, .. } if loc.path == path => {
            let lines: Vec<&str> = text.split('\n').collect();
            let line_ok = loc.line >= 1 && loc.line <= lines.len().max(1);
            let width = lines.get(loc.line.wrapping_sub(1)).map_or(0, |l| l.chars().count());
            if !line_ok || loc.col < 1 || loc.col > width + 2 {
                return Err(format!("position {}:{} is outside the text: {shown}", loc.line, loc.col));
            }
            Ok(())
        }
        // Another file (an asset the scene names) or a whole file.
        Error::At { .. } | Error::File { .. } => Ok(()),
        Error::Invalid(_) if !strict => Ok(()),
        Error::Invalid(_) => Err(format!("parse error without file:line:col: {shown}")),
        Error::Gpu(_) | Error::DeviceLost(_) => Err(format!("a parser raised a GPU error: {shown}")),
    }
}

/// System allocator that keeps, per thread, the live byte count and its peak.
pub struct Tracked;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn track(delta: isize) {
    // `try_with`: allocations during thread teardown are not counted.
    let _ = LIVE.try_with(|l| {
        let v = l.get() + delta;
        l.set(v);
        let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
    });
}

impl Tracked {
    /// Resets the thread's peak; returns the live count the case starts from.
    pub fn begin_case() -> isize {
        let live = LIVE.with(Cell::get);
        PEAK.with(|p| p.set(live));
        live
    }

    /// Most bytes live at once since [`Tracked::begin_case`] returned `start`, above `start`.
    pub fn peak_since(start: isize) -> usize {
        (PEAK.with(Cell::get) - start).max(0) as usize
    }
}

unsafe impl GlobalAlloc for Tracked {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            track(layout.size() as isize);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            track(layout.size() as isize);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        track(-(layout.size() as isize));
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            track(new_size as isize - layout.size() as isize);
        }
        p
    }
}
