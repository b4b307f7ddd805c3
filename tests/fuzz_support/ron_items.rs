//! Where RON text can be edited structurally: the openings of parentheses (to insert an unknown
//! field), the items of structs and maps (`name: value` or `"key": value`, to duplicate one),
//! and the extent of a value. Works on byte offsets of the text, skipping comments and strings.

/// Byte offsets of every `(`, `[`, `{`, `)`, `]`, `}` and `,` outside comments and strings,
/// with the character.
fn punctuation(text: &str) -> Vec<(usize, u8)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i += 1;
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
            }
            c @ (b'(' | b'[' | b'{' | b')' | b']' | b'}' | b',') => out.push((i, c)),
            _ => {}
        }
        i += 1;
    }
    out
}

/// Offsets just after each `(` outside comments and strings.
pub fn openings(text: &str) -> Vec<usize> {
    punctuation(text).into_iter().filter(|&(_, c)| c == b'(').map(|(i, _)| i + 1).collect()
}

/// Offset of the bracket closing the one opened just before `after_open`.
pub fn closing(text: &str, after_open: usize) -> usize {
    let mut depth = 0;
    for (i, c) in punctuation(text).into_iter().filter(|&(i, _)| i >= after_open) {
        match c {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' if depth == 0 => return i,
            b')' | b']' | b'}' => depth -= 1,
            _ => {}
        }
    }
    text.len()
}

/// One item of a struct or map: its text spans `start..end` (without the separating comma).
#[derive(Debug, Clone, Copy)]
pub struct Item {
    pub start: usize,
    pub end: usize,
}

/// The named items (`name: value` in parentheses, `"key": value` in braces) of every struct
/// and map in `text`.
pub fn items(text: &str) -> Vec<Item> {
    let punct = punctuation(text);
    let mut out = Vec::new();
    // Per open bracket: its character and where its current item starts.
    let mut stack: Vec<(u8, usize)> = Vec::new();
    let close = |open: u8, start: usize, end: usize, out: &mut Vec<Item>| {
        let item = text[start..end].trim();
        let named = match open {
            b'(' => {
                let head = item.split(':').next().unwrap_or("");
                item.contains(':')
                    && !head.is_empty()
                    && head.trim().chars().all(|c| c.is_alphanumeric() || c == '_')
            }
            b'{' => item.starts_with('"') && item.contains(':'),
            _ => false,
        };
        if named {
            let lead = text[start..end].len() - text[start..end].trim_start().len();
            out.push(Item { start: start + lead, end: start + lead + item.len() });
        }
    };
    for (i, c) in punct {
        match c {
            b'(' | b'[' | b'{' => stack.push((c, i + 1)),
            b',' => {
                if let Some(top) = stack.last_mut() {
                    let (open, start) = *top;
                    top.1 = i + 1;
                    close(open, start, i, &mut out);
                }
            }
            _ => {
                if let Some((open, start)) = stack.pop() {
                    close(open, start, i, &mut out);
                }
            }
        }
    }
    out
}

/// `text` with `item` written twice.
pub fn duplicate(text: &str, item: Item) -> String {
    let item_text = &text[item.start..item.end];
    format!("{}{item_text}, {}", &text[..item.start], &text[item.start..])
}
