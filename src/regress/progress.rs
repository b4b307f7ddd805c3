//! One regress record as a progress line.

use super::record::{Record, Status};
use crate::progress::{Progress, Verbosity};

/// Reports `rec` as finished; `skipped`: it is an earlier run's, still current. Failing scenes
/// stay on screen above the bar; with `--verbose`, each scene's warnings too.
pub(super) fn finished(progress: &mut Progress, rec: &Record, skipped: bool) {
    let current = if skipped { " (current, not rendered again)" } else { "" };
    let mut line = format!("{}{current}", result_line(rec));
    if progress.verbosity == Verbosity::Verbose {
        for w in &rec.warnings {
            line += &format!("\n    warning: {w}");
        }
    }
    progress.finished(&rec.scene, &line, !skipped, rec.status != Status::Pass);
}

/// `scene: status (FLIP x, rel RMSE y, z ms GPU): message`.
fn result_line(rec: &Record) -> String {
    let mut s = format!("{}: {}", rec.scene, rec.status.label());
    if rec.updated {
        s += " (reference updated)";
    }
    if let (Some(f), Some(r)) = (rec.flip, rec.rel_rmse) {
        s += &format!(" (FLIP {f:.5}, rel RMSE {r:.5}");
        if let Some(g) = rec.gpu_ms {
            s += &format!(", {g:.1} ms GPU");
        }
        if let Some(t) = rec.truth_flip {
            s += &format!(", FLIP {t:.5} against the truth");
        }
        s += ")";
    }
    if let Some(m) = rec.message.as_ref().filter(|_| rec.status != Status::Pass || rec.updated) {
        s += &format!(": {m}");
    }
    s
}
