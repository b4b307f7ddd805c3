//! The summary table (stdout) and the static `index.html` report, built from records only, so that
//! shards written into one folder (or folders copied together) make one report.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::merge::Problem;
use super::record::{Found, Record, Status, IMAGES};
use crate::io::atomic;
use crate::{Error, Result};

/// File name of the report inside the output folder.
pub(crate) const INDEX_FILE: &str = "index.html";

fn metric(v: Option<f64>) -> String {
    v.map(|v| format!("{v:.5}")).unwrap_or_else(|| "-".into())
}

/// A plain-text table: scene, status, FLIP, rel RMSE, GPU ms, then counts per status.
pub(crate) fn summary_table<'a>(records: impl IntoIterator<Item = &'a Record>) -> String {
    let records: Vec<&Record> = records.into_iter().collect();
    let w = records.iter().map(|r| r.scene.len()).max().unwrap_or(0).max(5);
    let mut s = format!(
        "{:<w$}  {:<22} {:>9} {:>9} {:>9} {:>9}\n",
        "scene", "status", "FLIP", "rel RMSE", "GPU ms", "truth"
    );
    for r in &records {
        let status =
            if r.updated { format!("{} (updated)", r.status.label()) } else { r.status.label().into() };
        let gpu = r.gpu_ms.map(|g| format!("{g:.1}")).unwrap_or_else(|| "-".into());
        let _ = writeln!(
            s,
            "{:<w$}  {status:<22} {:>9} {:>9} {gpu:>9} {:>9}",
            r.scene,
            metric(r.flip),
            metric(r.rel_rmse),
            metric(r.truth_flip)
        );
    }
    s + &counts(&records) + "\n"
}

/// `5 scenes: 3 pass, 1 regressed, 1 new (1 reference updated)`.
pub(crate) fn counts(records: &[&Record]) -> String {
    let mut parts = Vec::new();
    for status in [Status::Pass, Status::Regressed, Status::New, Status::BrokenScene, Status::BrokenReference]
    {
        let n = records.iter().filter(|r| r.status == status).count();
        if n > 0 {
            parts.push(format!("{n} {}", status.label()));
        }
    }
    let updated = records.iter().filter(|r| r.updated).count();
    let mut s =
        format!("{} scene{}: {}", records.len(), if records.len() == 1 { "" } else { "s" }, parts.join(", "));
    if updated > 0 {
        let _ = write!(s, " ({updated} reference{} updated)", if updated == 1 { "" } else { "s" });
    }
    s
}

/// Writes `out/index.html` from the records found under `out` (and the unreadable ones, and what
/// the merge found wrong).
pub(crate) fn write_index(
    out: &Path,
    found: &[Found],
    bad: &[Error],
    problems: &[Problem],
) -> Result<PathBuf> {
    let path = out.join(INDEX_FILE);
    atomic::write_bytes(&path, html(found, bad, problems).as_bytes())?;
    Ok(path)
}

fn html(found: &[Found], bad: &[Error], problems: &[Problem]) -> String {
    let records: Vec<&Record> = found.iter().map(|f| &f.record).collect();
    let failed = records.iter().filter(|r| r.failed()).count();
    let mut h = String::from(HEAD);
    let verdict = if failed == 0 && bad.is_empty() && problems.is_empty() { "ok" } else { "failed" };
    let _ = writeln!(h, "<h1>voltex regress: <span class=\"{verdict}\">{verdict}</span></h1>");
    let _ = writeln!(h, "<p>{}</p>", esc(&counts(&records)));
    for e in bad {
        let _ = writeln!(h, "<p class=\"failed\">unreadable record: {}</p>", esc(&e.to_string()));
    }
    for p in problems {
        let _ = writeln!(h, "<p class=\"failed\">merge: {}</p>", esc(&p.to_string()));
    }
    h += "<table>\n<tr><th>scene</th><th>status</th><th>FLIP / max</th><th>rel RMSE / max</th><th>truth FLIP / max</th><th>size</th>\
          <th>GPU ms</th><th>wall ms</th><th>shard</th><th>finished (UTC)</th></tr>\n";
    for (i, f) in found.iter().enumerate() {
        let r = &f.record;
        let size = r.size.map(|[w, h]| format!("{w}x{h}")).unwrap_or_else(|| "-".into());
        let gpu = r.gpu_ms.map(|g| format!("{g:.1}")).unwrap_or_else(|| "-".into());
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#s{i}\">{}</a></td><td>{}</td><td>{} / {}</td><td>{} / {}</td><td>{} / {}</td><td>{size}</td>\
             <td>{gpu}</td><td>{:.0}</td><td>{}</td><td>{}</td></tr>",
            esc(&r.scene),
            badge(r),
            metric(r.flip),
            r.max_flip,
            metric(r.rel_rmse),
            r.max_rel_rmse,
            metric(r.truth_flip),
            r.max_truth_flip.map_or("-".into(), |m| m.to_string()),
            r.wall_ms,
            esc(&r.shard),
            utc(r.finished_unix)
        );
    }
    h += "</table>\n";
    for (i, f) in found.iter().enumerate() {
        card(&mut h, i, f);
    }
    h + "</body>\n</html>\n"
}

fn card(h: &mut String, i: usize, f: &Found) {
    let r = &f.record;
    let _ = writeln!(h, "<section id=\"s{i}\">\n<h2>{} {}</h2>", esc(&r.scene), badge(r));
    let _ = writeln!(
        h,
        "<p>scene <code>{}</code>, reference <code>{}</code></p>",
        esc(&r.scene_path),
        esc(&r.reference_path)
    );
    if let Some(m) = &r.message {
        let _ = writeln!(h, "<pre>{}</pre>", esc(m));
    }
    for w in &r.warnings {
        let _ = writeln!(h, "<p class=\"warn\">warning: {}</p>", esc(w));
    }
    let _ = writeln!(h, "<p>adapter: {}</p>", esc(&r.adapter));
    if let Some(a) = r.reference_adapter.as_ref().filter(|a| **a != r.adapter) {
        let _ = writeln!(h, "<p class=\"warn\">reference rendered on: {}</p>", esc(a));
    }
    h.push_str("<div class=\"images\">\n");
    for name in IMAGES.iter().filter(|n| r.images.iter().any(|i| i == *n)) {
        let link = href(&f.folder.join(name));
        let mut caption = name.trim_end_matches(".png").replace("diff", "FLIP heat map");
        let mut legend = String::new();
        if *name == "diff.png" {
            if let Some(f) = r.flip {
                caption += &format!(", mean {f:.5}");
            }
            legend = heat_legend();
        }
        let _ = writeln!(
            h,
            "<figure><a href=\"{link}\"><img src=\"{link}\" alt=\"{caption}\"></a><figcaption>{caption}</figcaption>{legend}</figure>"
        );
    }
    h.push_str("</div>\n</section>\n");
}

/// The heat map's colour scale: per-pixel FLIP from 0 to 1, as a gradient with ticks.
fn heat_legend() -> String {
    let stops = crate::metrics::heatmap_scale(9);
    let gradient: Vec<String> =
        stops.iter().enumerate().map(|(i, c)| format!("{c} {:.1}%", i as f64 * 100.0 / 8.0)).collect();
    format!(
        "<div class=\"scale\" style=\"background: linear-gradient(to right, {})\"></div>\
         <div class=\"ticks\"><span>0</span><span>0.25</span><span>0.5</span><span>0.75</span><span>1</span></div>",
        gradient.join(", ")
    )
}

fn badge(r: &Record) -> String {
    let class = if r.status == Status::Pass {
        "ok"
    } else if r.failed() {
        "failed"
    } else {
        "warn"
    };
    let updated = if r.updated { ", reference updated" } else { "" };
    format!("<span class=\"badge {class}\">{}{updated}</span>", r.status.label())
}

/// HTML-escapes text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A relative URL to `path` (relative to the output folder), percent-encoding what URLs reserve.
fn href(path: &Path) -> String {
    let segments: Vec<String> = path
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .bytes()
                .map(|b| match b {
                    b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                        (b as char).to_string()
                    }
                    _ => format!("%{b:02X}"),
                })
                .collect()
        })
        .collect();
    segments.join("/")
}

/// `YYYY-MM-DD HH:MM` of Unix seconds (H. Hinnant's days-to-civil algorithm).
pub(crate) fn utc(secs: u64) -> String {
    let days = (secs / 86400) as i64;
    let (hh, mm) = ((secs % 86400) / 3600, (secs % 3600) / 60);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02} {hh:02}:{mm:02}")
}

const HEAD: &str = r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>voltex regress</title>
<style>
body { font-family: system-ui, sans-serif; margin: 1.5em; background: #fafafa; color: #222; }
table { border-collapse: collapse; }
td, th { border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: left; }
section { border-top: 1px solid #ccc; margin-top: 1.5em; }
.images { display: flex; gap: 1em; flex-wrap: wrap; }
figure { margin: 0; }
img { width: 256px; image-rendering: pixelated; border: 1px solid #888; }
figcaption { text-align: center; }
.scale { width: 256px; height: 10px; border: 1px solid #888; margin-top: 0.3em; }
.ticks { width: 258px; display: flex; justify-content: space-between; font-size: 0.8em; }
pre { white-space: pre-wrap; background: #eee; padding: 0.5em; }
.badge { padding: 0.1em 0.5em; border-radius: 0.3em; font-size: 0.9em; }
.ok { color: #060; } .badge.ok { background: #cfc; }
.failed { color: #a00; } .badge.failed { background: #fcc; }
.warn { color: #850; } .badge.warn { background: #fe9; }
</style>
</head>
<body>
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_and_links() {
        assert_eq!(utc(0), "1970-01-01 00:00");
        assert_eq!(utc(951_782_400 + 3600 * 13 + 60 * 7), "2000-02-29 13:07");
        assert_eq!(href(Path::new("a b/c#d/diff.png")), "a%20b/c%23d/diff.png");
        assert_eq!(esc("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
    }
}
