//! The panel's tooltips: what the scene-file reference (`docs/src/scene-reference.md`, built into
//! the binary) says of a field, from its tables (`| field | type | default | limits, meaning |`
//! and, per variant, `| variant | field | default | limits |`), so the panel and the book say the
//! same.

use std::collections::HashMap;
use std::sync::OnceLock;

const REFERENCE: &str = include_str!("../../docs/src/scene-reference.md");

/// A row of the reference: where it is (a variant's name, or the section's heading) and what it
/// says.
struct Row {
    context: String,
    text: String,
}

/// The reference's rows by field name.
fn rows() -> &'static HashMap<String, Vec<Row>> {
    static ROWS: OnceLock<HashMap<String, Vec<Row>>> = OnceLock::new();
    ROWS.get_or_init(|| index(REFERENCE))
}

fn index(page: &str) -> HashMap<String, Vec<Row>> {
    let mut out: HashMap<String, Vec<Row>> = HashMap::new();
    let (mut heading, mut header): (String, Vec<String>) = (String::new(), Vec::new());
    for line in page.lines() {
        if let Some(h) = line.strip_prefix("## ").or_else(|| line.strip_prefix("### ")) {
            heading = plain(h);
            continue;
        }
        let Some(cells) = line.strip_prefix('|').map(|l| l.trim_end().trim_end_matches('|')) else {
            header.clear();
            continue;
        };
        let cells: Vec<String> = cells.split('|').map(plain).collect();
        if header.is_empty() {
            header = cells;
            continue;
        }
        if cells.iter().all(|c| c.chars().all(|ch| ch == '-' || ch == ':')) {
            continue;
        }
        let at = |name: &str| header.iter().position(|h| h == name).and_then(|i| cells.get(i));
        let Some(field) = at("field") else { continue };
        let context = at("variant").cloned().unwrap_or_else(|| heading.clone());
        let parts: Vec<String> = header
            .iter()
            .zip(&cells)
            .filter(|(h, c)| !matches!(h.as_str(), "field" | "variant") && !c.is_empty())
            .map(|(h, c)| format!("{h}: {c}"))
            .collect();
        out.entry(field.clone()).or_default().push(Row { context, text: parts.join("\n") });
    }
    out
}

/// Markdown to plain text: backticks and link targets dropped.
fn plain(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s.trim();
    while let Some(open) = rest.find('[') {
        let Some(mid) = rest[open..].find("](").map(|i| open + i) else { break };
        let Some(close) = rest[mid..].find(')').map(|i| mid + i) else { break };
        out.push_str(&rest[..open]);
        out.push_str(&rest[open + 1..mid]);
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    out.replace('`', "")
}

/// What the reference says of `field` of a value of type `owner` (a variant or struct name):
/// the row of that variant, else the field's only row, else each section's row.
pub(crate) fn tooltip(field: &str, owner: Option<&str>) -> Option<String> {
    let rows = rows().get(field)?;
    if let Some(row) = rows.iter().find(|r| Some(r.context.as_str()) == owner) {
        return Some(row.text.clone());
    }
    match rows.as_slice() {
        [row] => Some(row.text.clone()),
        rows => {
            Some(rows.iter().map(|r| format!("{}: {}", r.context, r.text)).collect::<Vec<_>>().join("\n\n"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_have_the_references_words() {
        let planes = tooltip("output", None).unwrap();
        assert!(planes.contains("each 1..=16384 pixels"), "{planes}");
        // A variant's own row wins over other sections' rows of the same field name.
        let freq = tooltip("frequency", Some("PerlinHeight")).unwrap();
        assert!(freq.contains("lattice cells per tile"), "{freq}");
        assert!(!freq.contains("`"), "backticks are dropped: {freq}");
        assert!(tooltip("planes", Some("ViewSlices")).unwrap().contains("1..=16384"));
        assert!(tooltip("no_such_field", None).is_none());
    }

    #[test]
    fn links_keep_their_words() {
        assert_eq!(plain("see [Hypertextures](#hypertextures) here"), "see Hypertextures here");
        assert_eq!(plain("`a` and `b`"), "a and b");
    }
}
