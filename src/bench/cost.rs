//! The cost model: frame time against work, `ms = a + b work`, fitted by least squares over the
//! rows of a benchmark table that share a method and a unit of work (slice triangles for
//! slicing, density evaluations for marching, evaluations for light-volume bakes), with its R^2.
//! A fit under 0.95 says the work measure misses what the time depends on.

use serde::{Deserialize, Serialize};

use super::json::Row;

/// R^2 under this is a finding to explain.
pub(crate) const GOOD_FIT: f64 = 0.95;

/// A cost model fitted to one table's rows: frame ms as a line of the work they did.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Fit {
    pub(crate) table: String,
    pub(crate) method: String,
    /// RayMarch: fitted per segment strategy (their costs per evaluation differ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) segments: Option<String>,
    /// ViewSlices: fitted per compositor (raster and tiles spend differently per triangle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) compositor: Option<String>,
    pub(crate) work_unit: String,
    /// Rows the line is fitted to.
    pub rows: usize,
    /// ms = intercept_ms + ms_per_unit * work
    pub(crate) intercept_ms: f64,
    pub(crate) ms_per_unit: f64,
    /// Coefficient of determination of the fit (under `GOOD_FIT` is a finding to explain).
    pub r2: f64,
}

impl Fit {
    pub(crate) fn describe(&self) -> String {
        format!(
            "cost model, table `{}`, {}{}: frame ms = {:.2} + {:.3e} x {} over {} rows: R^2 = {:.3}{}",
            self.table,
            self.method,
            [&self.segments, &self.compositor]
                .iter()
                .filter_map(|s| s.as_ref())
                .map(|s| format!(" {s}"))
                .collect::<String>(),
            self.intercept_ms,
            self.ms_per_unit,
            self.work_unit,
            self.rows,
            self.r2,
            if self.r2 < GOOD_FIT { " (under 0.95: the work measure misses part of the cost)" } else { "" }
        )
    }
}

/// Least squares of `y = a + b x`: (a, b, R^2); R^2 is 1 when y does not vary and the line fits it.
pub(crate) fn fit_line(points: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in points {
        sxx += (x - mx) * (x - mx);
        sxy += (x - mx) * (y - my);
        syy += (y - my) * (y - my);
    }
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let a = my - b * mx;
    let ss_res: f64 = points.iter().map(|&(x, y)| (y - a - b * x).powi(2)).sum();
    let r2 = if syy > 0.0 { 1.0 - ss_res / syy } else { 1.0 };
    (a, b, r2)
}

/// One fit per (table, method, segments, compositor, work unit) over the rows that have work,
/// with at least three rows.
pub fn fit(rows: &[Row]) -> Vec<Fit> {
    let key = |r: &Row| {
        (r.table.clone(), r.method.clone(), r.segments.clone(), r.compositor.clone(), r.work_unit.clone())
    };
    let mut groups = Vec::new();
    for r in rows.iter().filter(|r| r.work.is_some() && r.work_unit.is_some()) {
        if !groups.contains(&key(r)) {
            groups.push(key(r));
        }
    }
    groups
        .into_iter()
        .filter_map(|g| {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| key(r) == g)
                .filter_map(|r| Some((r.work?, r.frame_ms)))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            let (table, method, segments, compositor, work_unit) = g;
            (points.len() >= 3).then(|| {
                let (intercept_ms, ms_per_unit, r2) = fit_line(&points);
                let work_unit = work_unit.unwrap_or_default();
                Fit {
                    table,
                    method,
                    segments,
                    compositor,
                    work_unit,
                    rows: points.len(),
                    intercept_ms,
                    ms_per_unit,
                    r2,
                }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_fits_exactly_and_noise_lowers_r2() {
        let exact: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 2.0 + 3.0 * i as f64)).collect();
        let (a, b, r2) = fit_line(&exact);
        assert!((a - 2.0).abs() < 1e-12 && (b - 3.0).abs() < 1e-12 && (r2 - 1.0).abs() < 1e-12);
        let noisy = [(0.0, 0.0), (1.0, 3.0), (2.0, 1.0), (3.0, 4.0)];
        let (_, _, r2) = fit_line(&noisy);
        assert!(r2 > 0.0 && r2 < 0.95, "{r2}");
        let rows: Vec<Row> = exact
            .iter()
            .map(|&(x, y)| Row { work: Some(x), work_unit: Some("u".into()), ..Row::new("t", "M", y) })
            .collect();
        let fits = fit(&rows);
        assert_eq!(fits.len(), 1);
        assert!((fits[0].r2 - 1.0).abs() < 1e-12 && fits[0].rows == 5);
        assert!(fits[0].describe().contains("R^2 = 1.000"));
    }
}
