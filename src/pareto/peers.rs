//! Rows measured by other renderers on the same scene (the scripts in `tools/peers/`), read from
//! CSV files so that `voltex pareto --peers` shows them beside voltex's settings. The file has a
//! header naming [`COLUMNS`] (any order, no others); each further line is one render; blank lines
//! and lines starting with `#` are skipped; fields hold no commas or quotes. A bad line is an
//! error at its `file:line:col`.

use std::path::Path;

use crate::error::{Error, FileLoc, Result};

/// The columns a peer CSV has.
pub(crate) const COLUMNS: [&str; 9] =
    ["renderer", "setting", "samples", "seconds", "threads", "version", "rmse", "rel_rmse", "flip"];

/// One render by another renderer, with its error against the same truth as voltex's rows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PeerRow {
    /// e.g. `Mitsuba volpath`, `Cycles`: a series of the chart.
    pub(crate) renderer: String,
    /// Its knobs, e.g. `max_depth=-1`.
    pub(crate) setting: String,
    /// Samples per pixel.
    pub(crate) samples: u64,
    /// Wall time of the render (seconds).
    pub(crate) seconds: f64,
    /// CPU threads it ran on.
    pub(crate) threads: u32,
    pub(crate) version: String,
    /// RMSE, relative RMSE and mean FLIP against the truth image.
    pub(crate) rmse: f64,
    pub(crate) rel_rmse: f64,
    pub(crate) flip: f64,
    /// Where it was read, `file:line`.
    pub(crate) at: String,
}

/// The rows of the peer CSV at `path`.
pub(crate) fn read(path: &Path) -> Result<Vec<PeerRow>> {
    let text = crate::input::read_text(path, "a peer CSV")?;
    parse(&text, path)
}

/// The rows of peer CSV `text`; `path` names it in errors.
pub(crate) fn parse(text: &str, path: &Path) -> Result<Vec<PeerRow>> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let at = |line: usize, col: usize, msg: String| Error::at(FileLoc::new(path, line + 1, col), msg);
    let (n, header) = lines.next().ok_or_else(|| {
        Error::file(path, format!("an empty peer CSV: expected a header ({})", COLUMNS.join(",")))
    })?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut index = [usize::MAX; COLUMNS.len()];
    for (i, name) in names.iter().enumerate() {
        let col = column(header, i);
        let Some(k) = COLUMNS.iter().position(|c| c == name) else {
            return Err(at(n, col, format!("unknown column `{name}`: expected {}", COLUMNS.join(","))));
        };
        if index[k] != usize::MAX {
            return Err(at(n, col, format!("column `{name}` appears twice")));
        }
        index[k] = i;
    }
    if let Some(k) = index.iter().position(|i| *i == usize::MAX) {
        return Err(at(n, 1, format!("no column `{}`: expected {}", COLUMNS[k], COLUMNS.join(","))));
    }
    let mut rows = Vec::new();
    for (n, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            let msg =
                format!("expected {} fields ({}), found {}", names.len(), names.join(","), fields.len());
            return Err(at(n, 1, msg));
        }
        let field = |k: usize| (fields[index[k]], column(line, index[k]));
        let text = |k: usize| -> Result<String> {
            let (v, col) = field(k);
            if v.is_empty() || v.contains('"') {
                return Err(at(n, col, format!("`{}`: expected text without quotes, not empty", COLUMNS[k])));
            }
            Ok(v.to_string())
        };
        let count = |k: usize| -> Result<u64> {
            let (v, col) = field(k);
            v.parse::<u64>().ok().filter(|c| *c >= 1).ok_or_else(|| {
                at(n, col, format!("`{}` is `{v}`: expected a whole number, 1 or more", COLUMNS[k]))
            })
        };
        let number = |k: usize, positive: bool| -> Result<f64> {
            let (v, col) = field(k);
            let ok = |x: &f64| x.is_finite() && if positive { *x > 0.0 } else { *x >= 0.0 };
            v.parse::<f64>().ok().filter(ok).ok_or_else(|| {
                let want = if positive { "a finite number above 0" } else { "a finite number, 0 or more" };
                at(n, col, format!("`{}` is `{v}`: expected {want}", COLUMNS[k]))
            })
        };
        rows.push(PeerRow {
            renderer: text(0)?,
            setting: text(1)?,
            samples: count(2)?,
            seconds: number(3, true)?,
            threads: count(4)?.min(u32::MAX as u64) as u32,
            version: text(5)?,
            rmse: number(6, false)?,
            rel_rmse: number(7, false)?,
            flip: number(8, false)?,
            at: format!("{}:{}", path.display(), n + 1),
        });
    }
    if rows.is_empty() {
        return Err(Error::file(
            path,
            "a peer CSV without rows: expected one line per render under the header",
        ));
    }
    Ok(rows)
}

/// 1-based column of field `i` of a comma-separated `line`.
fn column(line: &str, i: usize) -> usize {
    line.split(',').take(i).map(|f| f.len() + 1).sum::<usize>() + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "renderer,setting,samples,seconds,threads,version,rmse,rel_rmse,flip\n\
        # a comment\n\
        Mitsuba volpath,max_depth=-1,16,0.5,2,3.9.1,0.01,0.02,0.03\n\n";

    fn err(text: &str) -> String {
        parse(text, Path::new("p.csv")).unwrap_err().to_string()
    }

    #[test]
    fn reads_rows_and_names_their_lines() {
        let rows = parse(GOOD, Path::new("p.csv")).unwrap();
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert_eq!((r.renderer.as_str(), r.samples, r.threads, r.flip), ("Mitsuba volpath", 16, 2, 0.03));
        assert_eq!(r.at, "p.csv:3");
        // Columns in another order.
        let swapped =
            "flip,renderer,setting,samples,seconds,threads,version,rmse,rel_rmse\n0.5,C,s,1,2,3,v,0,0\n";
        assert_eq!(parse(swapped, Path::new("p.csv")).unwrap()[0].flip, 0.5);
    }

    #[test]
    fn bad_lines_are_errors_at_their_place() {
        let head = "renderer,setting,samples,seconds,threads,version,rmse,rel_rmse,flip\n";
        let e = err(&format!("{head}M,s,16,0.5,2,3,0.01,0.02\n"));
        assert!(e.starts_with("p.csv:2:1: expected 9 fields"), "{e}");
        let e = err(&format!("{head}M,s,16,-1,2,3,0.01,0.02,0.03\n"));
        assert!(e.starts_with("p.csv:2:8: `seconds` is `-1`"), "{e}");
        let e = err(&format!("{head}M,s,0,1,2,3,0.01,0.02,0.03\n"));
        assert!(e.starts_with("p.csv:2:5: `samples` is `0`"), "{e}");
        let e = err(&format!("{head}M,s,1,1,2,3,0.01,0.02,NaN\n"));
        assert!(e.starts_with("p.csv:2:") && e.contains("`flip` is `NaN`"), "{e}");
        let e = err("renderer,setting,samples,seconds,threads,version,rmse,rel_rmse,flip,extra\n");
        assert!(e.starts_with("p.csv:1:") && e.contains("unknown column `extra`"), "{e}");
        assert!(err("renderer,setting\n").contains("no column `samples`"));
        assert!(err(head).contains("without rows"));
        assert!(err("").contains("empty peer CSV"));
    }
}
