//! The scene file's text as a tree of values with byte spans, and edits made at a value's span so
//! that everything else (comments, order, layout) stays byte for byte: what the panel writes back.
//!
//! A small span-tracking pass over RON of our own (ron's `Value` drops spans and comments): it only
//! needs to find values, so it accepts any well-bracketed RON; the scene parser judges the result.

use std::ops::Range;
use std::path::Path;

use crate::error::{Error, Result};

/// One value of the text.
#[derive(Debug, Clone, PartialEq)]
pub struct Value {
    /// Byte range of the value in the text.
    pub span: Range<usize>,
    /// What the value is.
    pub kind: Kind,
}

/// The shape of a [`Value`].
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// A number, bool, identifier (unit variant), string or char: its text is the span.
    Atom,
    /// `Name(..)` or `(..)`: a struct when its fields are named, else a tuple.
    Paren {
        /// The struct's name (`None` for `(..)`).
        name: Option<String>,
        /// Its fields, in order.
        fields: Vec<ParenField>,
    },
    /// `[..]`: a list.
    List(Vec<Value>),
    /// `{..}`: a map's keys and values.
    Map(Vec<(Value, Value)>),
}

/// A field of a `Paren` value.
#[derive(Debug, Clone, PartialEq)]
pub struct ParenField {
    /// The field's name (`None` in a tuple).
    pub(crate) name: Option<String>,
    pub(crate) value: Value,
}

/// One step of a path from the root value down to the value an edit changes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Step {
    /// A named field of a struct.
    Field(String),
    /// An item of a tuple or a list.
    Index(usize),
    /// The value of a map entry whose key is this string.
    Key(String),
}

/// Shows a path as `nodes[0].method.planes`.
pub fn show(path: &[Step]) -> String {
    let mut s = String::new();
    for step in path {
        match step {
            Step::Field(f) if s.is_empty() => s.push_str(f),
            Step::Field(f) => {
                s.push('.');
                s.push_str(f);
            }
            Step::Index(i) => s.push_str(&format!("[{i}]")),
            Step::Key(k) => s.push_str(&format!("[{k:?}]")),
        }
    }
    s
}

impl Value {
    /// The value's text in `src`.
    pub fn text<'a>(&self, src: &'a str) -> &'a str {
        &src[self.span.clone()]
    }

    /// The child at `step`.
    pub fn child(&self, step: &Step, src: &str) -> Option<&Value> {
        match (&self.kind, step) {
            (Kind::Paren { fields, .. }, Step::Field(n)) => {
                fields.iter().find(|f| f.name.as_deref() == Some(n)).map(|f| &f.value)
            }
            (Kind::Paren { fields, .. }, Step::Index(i)) => {
                fields.get(*i).filter(|f| f.name.is_none()).map(|f| &f.value)
            }
            (Kind::List(items), Step::Index(i)) => items.get(*i),
            (Kind::Map(entries), Step::Key(k)) => {
                entries.iter().find(|(key, _)| unquote(key.text(src)).as_deref() == Some(k)).map(|(_, v)| v)
            }
            _ => None,
        }
    }

    /// The value at `path` below this one, if there is one.
    pub fn at(&self, path: &[Step], src: &str) -> Option<&Value> {
        path.iter().try_fold(self, |v, s| v.child(s, src))
    }

    /// The variant or struct name of `Name(..)`, or the identifier of a unit variant.
    pub fn name<'a>(&'a self, src: &'a str) -> Option<&'a str> {
        match &self.kind {
            Kind::Paren { name, .. } => name.as_deref(),
            Kind::Atom => {
                Some(self.text(src)).filter(|t| t.starts_with(|c: char| c.is_alphabetic() || c == '_'))
            }
            _ => None,
        }
    }

    /// The items of a list, or of a tuple.
    pub fn items(&self) -> Vec<&Value> {
        match &self.kind {
            Kind::List(items) => items.iter().collect(),
            Kind::Paren { fields, .. } if fields.iter().all(|f| f.name.is_none()) => {
                fields.iter().map(|f| &f.value).collect()
            }
            _ => Vec::new(),
        }
    }

    /// The value as a number, if it is one.
    pub fn number(&self, src: &str) -> Option<f64> {
        matches!(self.kind, Kind::Atom).then(|| parse_number(self.text(src))).flatten()
    }
}

/// A RON number's value (decimal, with `_` separators, or 0x/0b/0o integers).
pub(crate) fn parse_number(t: &str) -> Option<f64> {
    let t = t.replace('_', "");
    let (neg, body) = match t.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, t.strip_prefix('+').unwrap_or(&t)),
    };
    let radix =
        |p: &str, r| body.strip_prefix(p).and_then(|d| u64::from_str_radix(d, r).ok()).map(|v| v as f64);
    let v = radix("0x", 16).or_else(|| radix("0b", 2)).or_else(|| radix("0o", 8)).or_else(|| {
        body.parse::<f64>().ok().filter(|_| body.starts_with(|c: char| c.is_ascii_digit() || c == '.'))
    })?;
    Some(if neg { -v } else { v })
}

/// The content of a plain string literal (escapes of `\"` and `\\` undone).
pub fn unquote(t: &str) -> Option<String> {
    let inner = t.strip_prefix('"')?.strip_suffix('"')?;
    Some(inner.replace("\\\"", "\"").replace("\\\\", "\\"))
}

/// A number written for the file: an integer where `like` (the text it replaces) is one and the
/// value is whole, else a decimal of about seven significant digits, trailing zeros dropped.
pub fn format_number(x: f64, like: &str) -> String {
    let integer_like = !like.contains(['.', 'e', 'E']);
    if integer_like && x.fract() == 0.0 && x.abs() < 1e15 {
        return format!("{}", x as i64);
    }
    if x == 0.0 {
        return "0.0".into();
    }
    let decimals = (7 - (x.abs().log10().floor() as i32 + 1)).clamp(1, 15) as usize;
    let s = format!("{x:.decimals$}");
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    }
}

/// Parses `src` (its `#![enable(..)]` attributes skipped) into the tree of its root value.
pub fn parse(src: &str) -> std::result::Result<Value, String> {
    let mut p = Parser { src, b: src.as_bytes(), i: 0 };
    p.skip();
    while p.b[p.i..].starts_with(b"#!") {
        p.i += 2;
        p.skip();
        p.value()?;
        p.skip();
    }
    let v = p.value()?;
    p.skip();
    if p.i < p.b.len() {
        return Err(p.err("expected the end of the file after the scene"));
    }
    Ok(v)
}

struct Parser<'a> {
    src: &'a str,
    b: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn err(&self, what: &str) -> String {
        let line = self.src[..self.i.min(self.src.len())].matches('\n').count() + 1;
        let col = self.i - self.src[..self.i.min(self.src.len())].rfind('\n').map_or(0, |n| n + 1) + 1;
        format!("{line}:{col}: {what}")
    }

    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    /// Skips white space and comments (`//` to the end of the line, nested `/* */`).
    fn skip(&mut self) {
        loop {
            while self.peek().is_some_and(|c| c.is_ascii_whitespace()) {
                self.i += 1;
            }
            if self.b[self.i..].starts_with(b"//") {
                self.i = self.src[self.i..].find('\n').map_or(self.b.len(), |n| self.i + n);
            } else if self.b[self.i..].starts_with(b"/*") {
                let mut depth = 0;
                while self.i < self.b.len() {
                    if self.b[self.i..].starts_with(b"/*") {
                        depth += 1;
                        self.i += 2;
                    } else if self.b[self.i..].starts_with(b"*/") {
                        depth -= 1;
                        self.i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        self.i += 1;
                    }
                }
            } else {
                return;
            }
        }
    }

    fn ident(&mut self) -> Option<Range<usize>> {
        let start = self.i;
        if self.b[self.i..].starts_with(b"r#") {
            self.i += 2;
        }
        if !self.peek().is_some_and(|c| c.is_ascii_alphabetic() || c == b'_') {
            self.i = start;
            return None;
        }
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
            self.i += 1;
        }
        Some(start..self.i)
    }

    fn value(&mut self) -> std::result::Result<Value, String> {
        let start = self.i;
        let Some(c) = self.peek() else {
            return Err(self.err("expected a value, found the end of the file"));
        };
        let kind = match c {
            b'(' => self.paren(None)?,
            b'[' => {
                self.i += 1;
                Kind::List(self.items(b']', |p| p.value())?)
            }
            b'{' => {
                self.i += 1;
                Kind::Map(self.items(b'}', |p| {
                    let k = p.value()?;
                    p.skip();
                    if p.peek() != Some(b':') {
                        return Err(p.err("expected `:` after a map key"));
                    }
                    p.i += 1;
                    p.skip();
                    Ok((k, p.value()?))
                })?)
            }
            b'"' => {
                self.string()?;
                Kind::Atom
            }
            b'\'' => {
                self.i += 1;
                while self.peek().is_some_and(|c| c != b'\'') {
                    self.i += if self.peek() == Some(b'\\') { 2 } else { 1 };
                }
                self.i += 1;
                Kind::Atom
            }
            b'r' if matches!(self.b.get(self.i + 1), Some(b'"') | Some(b'#'))
                && self.b[self.i + 1..].iter().find(|&&c| c != b'#') == Some(&b'"') =>
            {
                self.raw_string()?;
                Kind::Atom
            }
            c if c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.') => {
                self.i += 1;
                while let Some(c) = self.peek() {
                    let exp_sign = matches!(c, b'+' | b'-') && matches!(self.b[self.i - 1], b'e' | b'E');
                    if c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || exp_sign {
                        self.i += 1;
                    } else {
                        break;
                    }
                }
                Kind::Atom
            }
            _ => {
                let Some(name) = self.ident() else { return Err(self.err("expected a value")) };
                let after = self.i;
                self.skip();
                if self.peek() == Some(b'(') {
                    self.paren(Some(self.src[name].to_string()))?
                } else {
                    self.i = after;
                    Kind::Atom
                }
            }
        };
        Ok(Value { span: start..self.i, kind })
    }

    fn string(&mut self) -> std::result::Result<(), String> {
        self.i += 1;
        while let Some(c) = self.peek() {
            self.i += if c == b'\\' { 2 } else { 1 };
            if c == b'"' {
                return Ok(());
            }
        }
        Err(self.err("unterminated string"))
    }

    fn raw_string(&mut self) -> std::result::Result<(), String> {
        self.i += 1;
        let hashes = self.b[self.i..].iter().take_while(|&&c| c == b'#').count();
        self.i += hashes + 1;
        let end = format!("\"{}", "#".repeat(hashes));
        match self.src[self.i..].find(&end) {
            Some(n) => {
                self.i += n + end.len();
                Ok(())
            }
            None => Err(self.err("unterminated raw string")),
        }
    }

    /// `(` .. `)` after an optional name: named fields or tuple items.
    fn paren(&mut self, name: Option<String>) -> std::result::Result<Kind, String> {
        self.i += 1;
        let fields = self.items(b')', |p| {
            let at = p.i;
            if let Some(id) = p.ident() {
                p.skip();
                if p.peek() == Some(b':') && p.b.get(p.i + 1) != Some(&b':') {
                    p.i += 1;
                    p.skip();
                    let field = p.src[id].trim_start_matches("r#").to_string();
                    return Ok(ParenField { name: Some(field), value: p.value()? });
                }
            }
            p.i = at;
            Ok(ParenField { name: None, value: p.value()? })
        })?;
        Ok(Kind::Paren { name, fields })
    }

    /// Comma-separated items up to `close` (a trailing comma allowed).
    fn items<T>(
        &mut self,
        close: u8,
        mut item: impl FnMut(&mut Self) -> std::result::Result<T, String>,
    ) -> std::result::Result<Vec<T>, String> {
        let mut out = Vec::new();
        loop {
            self.skip();
            if self.peek() == Some(close) {
                self.i += 1;
                return Ok(out);
            }
            out.push(item(self)?);
            self.skip();
            match self.peek() {
                Some(b',') => self.i += 1,
                Some(c) if c == close => {}
                _ => return Err(self.err(&format!("expected `,` or `{}`", close as char))),
            }
        }
    }
}

/// One change of the text: the value at `path` went from `before` to `after` (for insertions
/// and removals of list items, `path` is the list; for an added field, the struct).
#[derive(Debug, Clone, PartialEq)]
pub struct Edit {
    /// Where the edit applies: the value's path from the root.
    pub path: Vec<Step>,
    pub(crate) before: String,
    /// The text after the edit.
    pub after: String,
}

impl Edit {
    /// Applies the edit to `src`: the value at `path` must read `before` (else the text changed
    /// since the edit was made).
    pub fn apply(&self, src: &str) -> Result<String> {
        splice(src, &self.path, &self.before, &self.after)
    }

    /// The edit that undoes this one.
    pub fn inverse(&self) -> Edit {
        Edit { path: self.path.clone(), before: self.after.clone(), after: self.before.clone() }
    }
}

/// The text's tree, or an error saying it does not parse (for edits, which need it).
pub(crate) fn tree(src: &str) -> Result<Value> {
    parse(src).map_err(|e| Error::Invalid(format!("the scene text does not parse: {e}")))
}

fn locate(src: &str, path: &[Step]) -> Result<Range<usize>> {
    let root = tree(src)?;
    root.at(path, src)
        .map(|v| v.span.clone())
        .ok_or_else(|| Error::Invalid(format!("no `{}` in the scene text", show(path))))
}

/// `src` with the value at `path`, which must read `before`, replaced by `after`.
pub(crate) fn splice(src: &str, path: &[Step], before: &str, after: &str) -> Result<String> {
    let span = locate(src, path)?;
    if &src[span.clone()] != before {
        return Err(Error::Invalid(format!(
            "`{}` is `{}` in the file, not `{before}`: it changed outside the panel",
            show(path),
            &src[span]
        )));
    }
    Ok(format!("{}{after}{}", &src[..span.start], &src[span.end..]))
}

/// The edit setting the value at `path` to `text`.
pub fn set(src: &str, path: &[Step], text: &str) -> Result<Edit> {
    let span = locate(src, path)?;
    Ok(Edit { path: path.to_vec(), before: src[span].to_string(), after: text.to_string() })
}

/// The edit changing the list (or tuple) at `path` by `change` on its own text, given the
/// spans of its items relative to that text.
fn on_items(
    src: &str,
    path: &[Step],
    change: impl FnOnce(&str, &[Range<usize>]) -> Result<String>,
) -> Result<Edit> {
    let root = tree(src)?;
    let v =
        root.at(path, src).ok_or_else(|| Error::Invalid(format!("no `{}` in the scene text", show(path))))?;
    let base = v.span.start;
    let spans: Vec<Range<usize>> = v.items().iter().map(|i| i.span.start - base..i.span.end - base).collect();
    let text = v.text(src);
    Ok(Edit { path: path.to_vec(), before: text.to_string(), after: change(text, &spans)? })
}

/// The edit inserting `item` into the list at `path` before its item `index` (at the end for
/// the length), separated from its neighbours as the list's own items are (one per line stays one
/// per line).
pub fn insert_item(src: &str, path: &[Step], index: usize, item: &str) -> Result<Edit> {
    on_items(src, path, |text, spans| {
        let n = spans.len();
        if index > n {
            return Err(Error::Invalid(format!("`{}` has {n} items, not {index}", show(path))));
        }
        if n == 0 {
            return Ok(format!("{}{item}{}", &text[..1], &text[1..]));
        }
        // The separator between two existing items (`, ` or `,\n    `).
        let sep = if n >= 2 { &text[spans[0].end..spans[1].start] } else { ", " };
        Ok(if index < n {
            let at = spans[index].start;
            format!("{}{item}{sep}{}", &text[..at], &text[at..])
        } else {
            let at = spans[n - 1].end;
            format!("{}{sep}{item}{}", &text[..at], &text[at..])
        })
    })
}

/// The edit removing item `index` of the list at `path` with one of its separators.
pub fn remove_item(src: &str, path: &[Step], index: usize) -> Result<Edit> {
    on_items(src, path, |text, spans| {
        let n = spans.len();
        if index >= n {
            return Err(Error::Invalid(format!("`{}` has {n} items, no item {index}", show(path))));
        }
        let cut = if index > 0 {
            spans[index - 1].end..spans[index].end
        } else if n > 1 {
            spans[0].start..spans[1].start
        } else {
            spans[0].clone()
        };
        Ok(format!("{}{}", &text[..cut.start], &text[cut.end..]))
    })
}

/// The edit setting `field` of the struct at `path` to `text`, adding the field when the text
/// leaves it out.
pub(crate) fn set_field(src: &str, path: &[Step], field: &str, text: &str) -> Result<Edit> {
    let p = [path, &[Step::Field(field.into())]].concat();
    match tree(src)?.at(&p, src) {
        Some(_) => set(src, &p, text),
        None => add_field(src, path, field, text),
    }
}

/// The edit adding `name: value` as the last field of the struct at `path`, separated as its
/// other fields are.
pub fn add_field(src: &str, path: &[Step], name: &str, value: &str) -> Result<Edit> {
    let root = tree(src)?;
    let v =
        root.at(path, src).ok_or_else(|| Error::Invalid(format!("no `{}` in the scene text", show(path))))?;
    let Kind::Paren { fields, .. } = &v.kind else {
        return Err(Error::Invalid(format!("`{}` is not a struct", show(path))));
    };
    if fields.iter().any(|f| f.name.as_deref() == Some(name)) {
        return Err(Error::Invalid(format!("`{}` already has `{name}`", show(path))));
    }
    let text = v.text(src);
    let base = v.span.start;
    let new = match fields.as_slice() {
        [] => {
            let open = text.find('(').unwrap_or(0) + 1;
            format!("{}{name}: {value}{}", &text[..open], &text[open..])
        }
        [.., last] => {
            let sep = match fields.as_slice() {
                [.., a, b] => &src[a.value.span.end..field_start(src, b)],
                _ => ", ",
            };
            let at = last.value.span.end - base;
            format!("{}{sep}{name}: {value}{}", &text[..at], &text[at..])
        }
    };
    Ok(Edit { path: path.to_vec(), before: text.to_string(), after: new })
}

/// Where a named field's name starts (its value's span starts after `name:`).
fn field_start(src: &str, f: &ParenField) -> usize {
    let Some(name) = &f.name else { return f.value.span.start };
    src[..f.value.span.start].rfind(name.as_str()).unwrap_or(f.value.span.start)
}

/// Writes `text` as the scene file `path`, atomically (temporary file, then rename) and keeping
/// its permissions. A read-only file is refused (renaming over it would succeed, but the user
/// made it read-only); a symbolic link is written through.
pub(crate) fn write(path: &Path, text: &str) -> Result<()> {
    let target = std::fs::canonicalize(path).map_err(|e| Error::file(path, e))?;
    let meta = std::fs::metadata(&target).map_err(|e| Error::file(path, e))?;
    if meta.permissions().readonly() {
        return Err(Error::file(path, "the scene file is read-only: edits stay in the panel, unsaved"));
    }
    crate::io::atomic::write_bytes(&target, text.as_bytes())?;
    std::fs::set_permissions(&target, meta.permissions()).map_err(|e| Error::file(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "// head (comment)\n#![enable(implicit_some)]\nScene(\n    a: 1, /* b: 2 */ s: \"x)\",\n    list: [\n        (0.0, 1.0),\n        (0.5, 0.25), // mid\n    ],\n    m: {\"k\": V(q: 2)},\n)\n";

    fn p(s: &str) -> Vec<Step> {
        s.split('.')
            .map(|t| match t.parse() {
                Ok(i) => Step::Index(i),
                Err(_) if t.starts_with('"') => Step::Key(t.trim_matches('"').into()),
                Err(_) => Step::Field(t.into()),
            })
            .collect()
    }

    #[test]
    fn finds_values_past_comments_and_strings() {
        let root = parse(SRC).unwrap();
        assert_eq!(root.name(SRC), Some("Scene"));
        assert_eq!(root.at(&p("a"), SRC).unwrap().text(SRC), "1");
        assert_eq!(root.at(&p("s"), SRC).unwrap().text(SRC), "\"x)\"");
        assert_eq!(root.at(&p("list.1.0"), SRC).unwrap().number(SRC), Some(0.5));
        assert_eq!(root.at(&p("m.\"k\".q"), SRC).unwrap().text(SRC), "2");
        assert!(root.at(&p("b"), SRC).is_none());
    }

    #[test]
    fn edits_change_only_their_span() {
        let e = set(SRC, &p("list.1.1"), "0.75").unwrap();
        let out = e.apply(SRC).unwrap();
        assert_eq!(out, SRC.replace("(0.5, 0.25)", "(0.5, 0.75)"));
        assert_eq!(e.inverse().apply(&out).unwrap(), SRC);
        // The text changed under the edit: refused.
        assert!(e.apply(&out).is_err());
    }

    #[test]
    fn items_are_inserted_and_removed_in_the_lists_style() {
        let e = insert_item(SRC, &p("list"), 1, "(0.2, 0.4)").unwrap();
        let out = e.apply(SRC).unwrap();
        assert!(out.contains("(0.0, 1.0),\n        (0.2, 0.4),\n        (0.5, 0.25), // mid"), "{out}");
        let e = insert_item(SRC, &p("list"), 2, "(1.0, 0.0)").unwrap();
        let out = e.apply(SRC).unwrap();
        assert!(out.contains("(0.5, 0.25),\n        (1.0, 0.0), // mid\n    ],"), "{out}");
        let e = remove_item(SRC, &p("list"), 0).unwrap();
        assert!(e.apply(SRC).unwrap().contains("list: [\n        (0.5, 0.25), // mid"));
        let e = remove_item(SRC, &p("list"), 1).unwrap();
        assert!(e.apply(SRC).unwrap().contains("(0.0, 1.0), // mid"));
    }

    #[test]
    fn fields_are_added_after_the_last() {
        let e = add_field(SRC, &p("m.\"k\""), "r", "3").unwrap();
        assert!(e.apply(SRC).unwrap().contains("V(q: 2, r: 3)"));
        let e = add_field(SRC, &[], "t", "4").unwrap();
        let out = e.apply(SRC).unwrap();
        assert!(out.contains("m: {\"k\": V(q: 2)},\n    t: 4,\n)"), "{out}");
    }

    #[test]
    fn numbers_keep_their_kind() {
        assert_eq!(format_number(24.0, "12"), "24");
        assert_eq!(format_number(2.0, "1.0"), "2.0");
        assert_eq!(format_number(0.00025, "0.002"), "0.00025");
        assert_eq!(format_number(1.0 / 3.0, "1"), "0.3333333");
        assert_eq!(parse_number("-1e-3"), Some(-0.001));
        assert_eq!(parse_number("Phong"), None);
    }
}
