//! Golden-image harness: compares a render with `tests/golden/NAME.exr`.
//!
//! - `VOLTEX_UPDATE_GOLDEN=1`: (re)writes the reference and passes.
//! - Missing reference: panics, telling to run with `VOLTEX_UPDATE_GOLDEN=1`.
//! - Metric over threshold: writes `target/golden-failures/NAME.{actual.png,actual.exr,diff.png}`
//!   and panics with the value, the threshold and those paths.

use std::path::{Path, PathBuf};

use voltex::io::Image;
use voltex::metrics;

/// Pass condition, inclusive: the metric must be `<=` the number (NaN always fails).
#[derive(Debug, Clone, Copy)]
pub enum Threshold {
    /// Mean LDR FLIP of the tonemapped images (0 identical … 1).
    Flip(f64),
    /// Relative RMSE of the linear HDR values, see `voltex::metrics::relative_rmse`.
    RelRmse(f64),
}

fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Where the reference for `name` lives.
pub fn golden_path(name: &str) -> PathBuf {
    manifest_dir().join("tests/golden").join(format!("{name}.exr"))
}

/// Where failure artefacts for `name` go.
pub fn failure_dir() -> PathBuf {
    manifest_dir().join("target/golden-failures")
}

fn update_requested() -> bool {
    std::env::var("VOLTEX_UPDATE_GOLDEN").is_ok_and(|v| v == "1")
}

/// Compares `actual` with the reference `tests/golden/NAME.exr` (see the module doc).
pub fn check_golden(name: &str, actual: &Image, threshold: Threshold) {
    assert!(
        !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)),
        "golden name {name:?}: use letters, digits, '-', '_', '.'"
    );
    let path = golden_path(name);
    if update_requested() {
        let dir = path.parent().unwrap();
        std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        let meta = [("voltex.golden", name.to_string())];
        voltex::io::exr::write(&path, actual, &meta)
            .unwrap_or_else(|e| panic!("writing golden reference: {e}"));
        eprintln!("golden {name}: wrote reference {}", path.display());
        return;
    }
    if !path.exists() {
        panic!(
            "golden {name}: reference {} is missing; run the test with VOLTEX_UPDATE_GOLDEN=1 \
             to create it (then look at it and commit it)",
            path.display()
        );
    }
    let (reference, _) =
        voltex::io::exr::read(&path).unwrap_or_else(|e| panic!("golden {name}: cannot read reference: {e}"));
    if !actual.same_size(&reference) {
        let paths = write_failure(name, actual, None);
        panic!(
            "golden {name}: size {}x{} differs from reference {}x{} ({}); \
             run with VOLTEX_UPDATE_GOLDEN=1 if the change is intended\n{paths}",
            actual.width,
            actual.height,
            reference.width,
            reference.height,
            path.display()
        );
    }
    let (label, value, limit, map) = match threshold {
        Threshold::Flip(limit) => {
            let r = metrics::flip(actual, &reference).expect("FLIP");
            ("mean FLIP", r.mean, limit, r.map)
        }
        Threshold::RelRmse(limit) => {
            let v = metrics::relative_rmse(actual, &reference).expect("relative RMSE");
            let map = metrics::relative_error_map(actual, &reference).expect("error map");
            ("relative RMSE", v, limit, map)
        }
    };
    if value.is_nan() || value > limit {
        let paths = write_failure(name, actual, Some(&map));
        let nonfinite = metrics::count_nonfinite(actual);
        panic!(
            "golden {name}: {label} = {value:.6} exceeds threshold {limit} \
             ({nonfinite} non-finite pixels; reference {})\n{paths}\n\
             run with VOLTEX_UPDATE_GOLDEN=1 if the change is intended",
            path.display()
        );
    }
}

/// Writes the failure artefacts; returns a printable list of what was written (or why not).
fn write_failure(name: &str, actual: &Image, map: Option<&[f32]>) -> String {
    let dir = failure_dir();
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return format!("(could not create {}: {e})", dir.display());
    }
    let mut lines = Vec::new();
    let mut record = |path: &Path, result: voltex::Result<()>| match result {
        Ok(()) => lines.push(format!("  wrote {}", path.display())),
        Err(e) => lines.push(format!("  could not write {}: {e}", path.display())),
    };
    let png = dir.join(format!("{name}.actual.png"));
    record(&png, voltex::io::png::write_tonemapped(&png, actual));
    let exr = dir.join(format!("{name}.actual.exr"));
    record(&exr, voltex::io::exr::write(&exr, actual, &[]));
    if let Some(map) = map {
        let diff = dir.join(format!("{name}.diff.png"));
        let heat = metrics::diff_heatmap(map, actual.width, actual.height);
        record(&diff, voltex::io::png::write_rgba8(&diff, actual.width, actual.height, &heat));
    }
    lines.join("\n")
}
