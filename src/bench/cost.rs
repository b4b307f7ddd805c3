//! The cost model: frame time against work, `ms = a + b work`, fitted by least squares over the
//! rows of a benchmark table that share a method and a unit of work (slice triangles for
//! slicing, density evaluations for marching, evaluations for light-volume bakes), with its R^2.
//! Where the rows also count the fragments they drew (slicing), a second term is fitted too,
//! `ms = a + b work + c fragments`, when the rows tell the two apart: a triangle's setup and a
//! fragment's shading are separate costs, and their ratio differs from scene to scene and size to
//! size. A fit under 0.95 says the work measure misses what the time depends on.

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
    /// ViewSlices: fitted per trivial reject (off, every prism is classified against every
    /// plane: a cost the slice triangles do not count).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) trivial_reject: Option<bool>,
    pub(crate) work_unit: String,
    /// Rows the line is fitted to.
    pub rows: usize,
    /// ms = intercept_ms + ms_per_unit * work (+ the second term's)
    pub(crate) intercept_ms: f64,
    pub(crate) ms_per_unit: f64,
    /// The second work measure's term, where one was fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) second: Option<Term>,
    /// Coefficient of determination of the fit (under `GOOD_FIT` is a finding to explain).
    pub r2: f64,
    /// With a second term: R^2 of the line in `work_unit` alone over the same rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) r2_first_alone: Option<f64>,
}

/// A further term of a cost model: its unit and its ms per unit.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(crate) struct Term {
    pub(crate) unit: String,
    pub(crate) ms_per_unit: f64,
}

/// Per-row measures a second term may use: the key in a row's `extra`.
const SECOND_MEASURES: &[&str] = &["fragments"];

impl Fit {
    pub(crate) fn describe(&self) -> String {
        let second =
            self.second.as_ref().map_or(String::new(), |t| format!(" + {:.3e} x {}", t.ms_per_unit, t.unit));
        let alone = self
            .r2_first_alone
            .map_or(String::new(), |r2| format!(" ({} alone: R^2 = {r2:.3})", self.work_unit));
        format!(
            "cost model, table `{}`, {}{}: frame ms = {:.2} + {:.3e} x {}{second} over {} rows: R^2 = {:.3}{alone}{}",
            self.table,
            self.method,
            [&self.segments, &self.compositor, &self.trivial_reject.map(|r| format!("reject {}", if r { "on" } else { "off" }))]
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

/// Least squares of `y = c0 + c1 x1 + ... + ck xk` over `points` (the x's, then y): the
/// coefficients and R^2, or `None` where the x's do not tell their terms apart (a column
/// constant or a combination of the others, to 1e-9) or there are no more points than
/// coefficients. Columns are centred and scaled first, so slice triangles (1e5) and fragments
/// (1e7) condition alike.
pub(crate) fn fit_terms(points: &[Vec<f64>]) -> Option<(Vec<f64>, f64)> {
    let k = points.first()?.len().checked_sub(1)?;
    let n = points.len();
    if n <= k + 1 {
        return None;
    }
    let mean = |j: usize| points.iter().map(|p| p[j]).sum::<f64>() / n as f64;
    let means: Vec<f64> = (0..=k).map(mean).collect();
    let scales: Vec<f64> = (0..k)
        .map(|j| (points.iter().map(|p| (p[j] - means[j]).powi(2)).sum::<f64>() / n as f64).sqrt())
        .collect();
    if scales.iter().any(|&s| s.is_nan() || s <= 0.0) {
        return None;
    }
    let z = |p: &[f64], j: usize| (p[j] - means[j]) / scales[j];
    // Normal equations of the centred, scaled columns: a k x k system, augmented with X^T y.
    let mut m: Vec<Vec<f64>> = (0..k)
        .map(|i| {
            let mut row: Vec<f64> = (0..k).map(|j| points.iter().map(|p| z(p, i) * z(p, j)).sum()).collect();
            row.push(points.iter().map(|p| z(p, i) * (p[k] - means[k])).sum());
            row
        })
        .collect();
    for c in 0..k {
        let pivot = (c..k).max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))?;
        // Scaled columns have diagonal n: a pivot this small is a dependent column.
        if m[pivot][c].abs() < 1e-9 * n as f64 {
            return None;
        }
        m.swap(c, pivot);
        let pivot_row = m[c].clone();
        for (r, row) in m.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / pivot_row[c];
                for (x, p) in row.iter_mut().zip(&pivot_row).skip(c) {
                    *x -= f * p;
                }
            }
        }
    }
    let slopes: Vec<f64> = (0..k).map(|j| m[j][k] / m[j][j] / scales[j]).collect();
    let intercept = means[k] - (0..k).map(|j| slopes[j] * means[j]).sum::<f64>();
    let predict = |p: &[f64]| intercept + (0..k).map(|j| slopes[j] * p[j]).sum::<f64>();
    let ss_res: f64 = points.iter().map(|p| (p[k] - predict(p)).powi(2)).sum();
    let ss_tot: f64 = points.iter().map(|p| (p[k] - means[k]).powi(2)).sum();
    let r2 = if ss_tot > 0.0 { 1.0 - ss_res / ss_tot } else { 1.0 };
    Some((std::iter::once(intercept).chain(slopes).collect(), r2))
}

/// One fit per (table, method, segments, compositor, trivial reject, work unit) over the rows
/// that have work, with at least three rows; with a second term where every row has its measure
/// and the rows tell the two apart.
pub fn fit(rows: &[Row]) -> Vec<Fit> {
    let key = |r: &Row| {
        (
            r.table.clone(),
            r.method.clone(),
            r.segments.clone(),
            r.compositor.clone(),
            r.trivial_reject,
            r.work_unit.clone(),
        )
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
            let group: Vec<&Row> = rows.iter().filter(|r| key(r) == g).collect();
            let (table, method, segments, compositor, trivial_reject, work_unit) = g;
            (points.len() >= 3).then(|| {
                let (intercept_ms, ms_per_unit, r2) = fit_line(&points);
                let line = Fit {
                    table,
                    method,
                    segments,
                    compositor,
                    trivial_reject,
                    work_unit: work_unit.unwrap_or_default(),
                    rows: points.len(),
                    intercept_ms,
                    ms_per_unit,
                    second: None,
                    r2,
                    r2_first_alone: None,
                };
                SECOND_MEASURES.iter().find_map(|m| with_second(&line, &group, m)).unwrap_or(line)
            })
        })
        .collect()
}

/// `line` refitted with the measure `extra[measure]` as a second term, where every row of
/// `group` has it, the rows tell the terms apart and both cost something.
fn with_second(line: &Fit, group: &[&Row], measure: &str) -> Option<Fit> {
    let points: Vec<Vec<f64>> = group
        .iter()
        .map(|r| Some(vec![r.work?, *r.extra.get(measure)?, r.frame_ms]))
        .collect::<Option<_>>()?;
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return None;
    }
    let (c, r2) = fit_terms(&points)?;
    // A negative cost per unit is the two measures rising together (one scene, one size), not
    // a finding: the line stays.
    if c[1] < 0.0 || c[2] < 0.0 {
        return None;
    }
    Some(Fit {
        intercept_ms: c[0],
        ms_per_unit: c[1],
        second: Some(Term { unit: measure.into(), ms_per_unit: c[2] }),
        r2,
        r2_first_alone: Some(line.r2),
        ..line.clone()
    })
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

    /// ms = 5 + 2e-3 triangles + 1e-5 fragments over two scenes whose fragments per triangle
    /// differ: the two-term fit finds the three coefficients, the line in triangles alone does
    /// not explain the rows; where fragments are proportional to triangles (one scene), the
    /// terms cannot be told apart and the line stays.
    #[test]
    fn a_second_term_is_fitted_where_the_rows_tell_it_apart() {
        let row = |tri: f64, frag: f64| {
            let mut r = Row {
                work: Some(tri),
                work_unit: Some("slice triangles".into()),
                ..Row::new("t", "V", 5.0 + 2e-3 * tri + 1e-5 * frag)
            };
            r.extra.insert("fragments".into(), frag);
            r
        };
        let rows: Vec<Row> = [(3e4, 3e6), (6e4, 6e6), (1.2e5, 1.2e7), (4e4, 1e6), (8e4, 2e6), (1.6e5, 4e6)]
            .iter()
            .map(|&(t, f)| row(t, f))
            .collect();
        let fits = fit(&rows);
        assert_eq!(fits.len(), 1);
        let f = &fits[0];
        let second = f.second.as_ref().expect("a second term");
        assert!((f.intercept_ms - 5.0).abs() < 1e-6 && (f.ms_per_unit - 2e-3).abs() < 1e-12, "{f:?}");
        assert!((second.ms_per_unit - 1e-5).abs() < 1e-14 && (f.r2 - 1.0).abs() < 1e-12, "{f:?}");
        assert!(f.r2_first_alone.unwrap() < 0.95, "{f:?}");
        assert!(f.describe().contains("x fragments over 6 rows"), "{}", f.describe());
        let one_scene: Vec<Row> = [3e4, 6e4, 9e4, 1.2e5].iter().map(|&t| row(t, 100.0 * t)).collect();
        let fits = fit(&one_scene);
        assert!(fits[0].second.is_none() && fits[0].r2_first_alone.is_none(), "{:?}", fits[0]);
    }
}
