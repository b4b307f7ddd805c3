//! CPU twin (f64) of `wgsl/shared/prism_map.wgsl`: where a ray enters and leaves a prism, and the
//! inverse of the prism map. Prism `k` maps `(b, w)` (barycentrics, height) to
//! `sum_i b_i (p_i + w h_i)`; its faces are two triangles and three bilinear side patches.

use glam::DVec3;

/// Corners of one prism: bottom `p_i` and top `p_i + h_i`, in any common frame (camera-relative).
#[derive(Clone, Copy, Debug)]
pub struct PrismCorners {
    /// Bottom corners `p_i`.
    pub bottom: [DVec3; 3],
    /// Top corners `p_i + h_i`.
    pub top: [DVec3; 3],
    /// Welded vertex ids: a side patch is intersected with its endpoints in id order, so the two
    /// prisms sharing it get bit-identical hits (no crack, no double count).
    pub ids: [u32; 3],
}

/// Roots of `c0 + c1 x + c2 x^2` without dividing by a leading coefficient that may vanish: the
/// quadratic degrades to the linear case smoothly (the root far away leaves the range instead).
pub(crate) fn quadratic_roots(c0: f64, c1: f64, c2: f64) -> [Option<f64>; 2] {
    let disc = c1 * c1 - 4.0 * c2 * c0;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (c1 + disc.sqrt().copysign(c1));
    let r1 = if c2 != 0.0 { Some(q / c2) } else { None };
    let r2 = if q != 0.0 { Some(c0 / q) } else { None };
    [r1, r2]
}

/// Ray (origin 0, direction `d`) against triangle `a b c`: the hit distance (two-sided).
pub(crate) fn ray_triangle(d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None; // the ray lies in the triangle's plane: it only grazes the prism
    }
    let s = -a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) / det)
}

/// Ray (origin 0, direction `d`) against the bilinear patch with bottom edge `q00 q10` and top edge
/// `q01 q11`: up to two hit distances.
pub(crate) fn ray_patch(d: DVec3, q00: DVec3, q10: DVec3, q01: DVec3, q11: DVec3) -> [Option<f64>; 2] {
    // For each u the patch holds the segment A(u) + v B(u); the ray meets it where A(u), B(u) and d
    // are coplanar: a quadratic in u.
    let e10 = q10 - q00;
    let (e00, e11) = (q01 - q00, q11 - q10);
    let c0 = q00.cross(d).dot(e00);
    let c2 = e10.cross(d).dot(e11 - e00);
    let c1 = q10.cross(d).dot(e11) - c0 - c2;
    let mut out = [None, None];
    for (k, u) in quadratic_roots(c0, c1, c2).into_iter().enumerate() {
        let Some(u) = u.filter(|u| (0.0..=1.0).contains(u)) else { continue };
        let a = q00 + e10 * u;
        let b = e00 + (e11 - e00) * u;
        let n = d.cross(b);
        let nn = n.dot(n);
        if nn == 0.0 {
            continue;
        }
        let v = a.cross(d).dot(n) / nn;
        if (0.0..=1.0).contains(&v) {
            out[k] = Some(a.cross(b).dot(n) / nn);
        }
    }
    out
}

/// Every distance at which the ray crosses the prism's boundary.
pub(crate) fn boundary_hits(d: DVec3, p: &PrismCorners) -> Vec<f64> {
    let mut hits = Vec::with_capacity(8);
    hits.extend(ray_triangle(d, p.bottom[0], p.bottom[1], p.bottom[2]));
    hits.extend(ray_triangle(d, p.top[0], p.top[1], p.top[2]));
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let (i, j) = if p.ids[i] <= p.ids[j] { (i, j) } else { (j, i) };
        hits.extend(ray_patch(d, p.bottom[i], p.bottom[j], p.top[i], p.top[j]).into_iter().flatten());
    }
    hits
}

/// `f(w) = det(q1 - q0, q2 - q0, x - q0)` over the cross-section `q_i = p_i + w h_i` at height w, as
/// cubic coefficients (relative to `p_0` for precision). `f` vanishes where the section holds x.
pub(crate) fn section_cubic(x: DVec3, p: &PrismCorners) -> [f64; 4] {
    let h = [0, 1, 2].map(|i| p.top[i] - p.bottom[i]);
    let (e1, e2) = (p.bottom[1] - p.bottom[0], p.bottom[2] - p.bottom[0]);
    let (g1, g2) = (h[1] - h[0], h[2] - h[0]);
    let r = x - p.bottom[0];
    let n0 = e1.cross(e2);
    let n1 = e1.cross(g2) + g1.cross(e2);
    let n2 = g1.cross(g2);
    [n0.dot(r), n1.dot(r) - n0.dot(h[0]), n2.dot(r) - n1.dot(h[0]), -n2.dot(h[0])]
}

fn cubic(c: &[f64; 4], w: f64) -> f64 {
    ((c[3] * w + c[2]) * w + c[1]) * w + c[0]
}

/// Root of `f` in `[lo, hi]` given a sign change, by Newton steps kept inside the bracket (bisection
/// when a step leaves it): no division by a vanishing leading coefficient.
fn bracketed_root(c: &[f64; 4], mut lo: f64, mut hi: f64) -> f64 {
    let mut f_lo = cubic(c, lo);
    let mut w = 0.5 * (lo + hi);
    for _ in 0..64 {
        let f = cubic(c, w);
        if f == 0.0 {
            return w;
        }
        if (f < 0.0) == (f_lo < 0.0) {
            lo = w;
            f_lo = f;
        } else {
            hi = w;
        }
        let df = (3.0 * c[3] * w + 2.0 * c[2]) * w + c[1];
        let newton = w - f / df;
        let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if (next - w).abs() <= 1e-15 * (1.0 + w.abs()) || hi - lo <= 1e-15 {
            return next;
        }
        w = next;
    }
    w
}

/// Barycentrics of `x` (in the triangle's plane) in `q0 q1 q2`; `None` if the triangle is degenerate.
///
/// As ratios of areas against the normal `n = e1 x e2`: rounding is amplified by 1/sin of the
/// triangle's smallest angle. (The normal equations, `d11 d22 - d12^2`, amplify it by 1/sin^2:
/// a sliver of altitude 1e-6 lost all but 5 digits of its barycentrics in f64, all in f32.)
pub(crate) fn barycentrics(x: DVec3, q: [DVec3; 3]) -> Option<[f64; 3]> {
    let (e1, e2, e) = (q[1] - q[0], q[2] - q[0], x - q[0]);
    let n = e1.cross(e2);
    let nn = n.dot(n);
    if nn <= 1e-24 * e1.dot(e1) * e2.dot(e2) || nn == 0.0 {
        return None;
    }
    let b1 = e.cross(e2).dot(n) / nn;
    let b2 = e1.cross(e).dot(n) / nn;
    Some([1.0 - b1 - b2, b1, b2])
}

/// Tolerance on barycentrics for a point to count as inside a prism.
pub(crate) const INSIDE_EPS: f64 = 1e-9;
/// Relative to the section cubic's coefficients, what counts as a root at w = 0 or 1.
const ZERO_TOL: f64 = 1e-13;

/// The inverse prism map: `(b, w)` with `x = sum_i b_i (p_i + w h_i)`, if `x` lies in the prism.
///
/// `w` is a root of the section cubic. `[0, 1]` is cut at the cubic's critical points into
/// intervals where it is monotone; each sign change is solved by a bracketed Newton iteration and
/// the first root whose barycentrics lie in the triangle is taken. Nothing divides by the leading
/// coefficient, so the degenerate cases (parallel height vectors: quadratic or linear) are the
/// same code path.
pub fn inverse(x: DVec3, p: &PrismCorners) -> Option<([f64; 3], f64)> {
    let c = section_cubic(x, p);
    let mut cuts = vec![0.0];
    let mut crit: Vec<f64> = quadratic_roots(c[1], 2.0 * c[2], 3.0 * c[3])
        .into_iter()
        .flatten()
        .filter(|w| *w > 0.0 && *w < 1.0)
        .collect();
    crit.sort_by(f64::total_cmp);
    cuts.extend(crit);
    cuts.push(1.0);
    // Points on the bottom or top face give f(0) or f(1) = 0 up to rounding.
    let tol = ZERO_TOL * c.iter().map(|v| v.abs()).sum::<f64>();
    for k in 0..cuts.len() - 1 {
        let (lo, hi) = (cuts[k], cuts[k + 1]);
        let (f_lo, f_hi) = (cubic(&c, lo), cubic(&c, hi));
        let w = if f_lo.abs() <= tol {
            lo
        } else if f_hi.abs() <= tol {
            hi
        } else if (f_lo < 0.0) != (f_hi < 0.0) {
            bracketed_root(&c, lo, hi)
        } else {
            continue;
        };
        let q = [0, 1, 2].map(|i| p.bottom[i] + (p.top[i] - p.bottom[i]) * w);
        if let Some(b) = barycentrics(x, q) {
            if b.iter().all(|&b| b >= -INSIDE_EPS) {
                return Some((b, w));
            }
        }
    }
    None
}

/// The parts of the ray `[t_min, t_max]` inside the prism, as `(t0, t1)` intervals in order.
pub fn ray_intervals(d: DVec3, p: &PrismCorners, t_min: f64, t_max: f64) -> Vec<(f64, f64)> {
    let mut cuts: Vec<f64> = boundary_hits(d, p).into_iter().filter(|&t| t > t_min && t < t_max).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.insert(0, t_min);
    cuts.push(t_max);
    let mut out: Vec<(f64, f64)> = Vec::new();
    for k in 0..cuts.len() - 1 {
        let (t0, t1) = (cuts[k], cuts[k + 1]);
        if t1 <= t0 || !t1.is_finite() {
            continue;
        }
        // Between two consecutive crossings the ray is wholly inside or outside: test the middle.
        if inverse(d * (0.5 * (t0 + t1)), p).is_none() {
            continue;
        }
        match out.last_mut() {
            Some(last) if last.1 == t0 => last.1 = t1,
            _ => out.push((t0, t1)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prism(bottom: [DVec3; 3], heights: [DVec3; 3]) -> PrismCorners {
        PrismCorners { bottom, top: [0, 1, 2].map(|i| bottom[i] + heights[i]), ids: [0, 1, 2] }
    }

    fn forward(p: &PrismCorners, b: [f64; 3], w: f64) -> DVec3 {
        (0..3).map(|i| (p.bottom[i] + (p.top[i] - p.bottom[i]) * w) * b[i]).sum()
    }

    /// Splayed, sheared and parallel height vectors (the last two make the cubic a quadratic or
    /// a linear equation): the inverse recovers (b, w) everywhere inside.
    #[test]
    fn inverse_round_trips_including_degenerate_cubics() {
        let base = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.1, 0.0), DVec3::new(0.2, 0.9, 0.05)];
        let cases = [
            [DVec3::new(-0.3, -0.2, 1.0), DVec3::new(0.4, -0.1, 0.8), DVec3::new(0.0, 0.5, 1.2)],
            [DVec3::new(0.3, 0.1, 0.5); 3],
            [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.1, 0.0, 1.0)],
            [DVec3::new(0.0, 0.0, 1e-4); 3],
        ];
        for (c, h) in cases.iter().enumerate() {
            let p = prism(base, *h);
            for &b in &[[1.0 / 3.0; 3], [0.8, 0.1, 0.1], [0.0, 0.5, 0.5], [0.05, 0.05, 0.9]] {
                for &w in &[0.0, 0.01, 0.5, 0.99, 1.0] {
                    let x = forward(&p, b, w);
                    let (b2, w2) = inverse(x, &p).unwrap_or_else(|| panic!("case {c}: {b:?} {w} not found"));
                    assert!((w2 - w).abs() < 1e-9, "case {c}: w {w2} for {w}");
                    for i in 0..3 {
                        assert!((b2[i] - b[i]).abs() < 1e-9, "case {c}: b {b2:?} for {b:?}");
                    }
                }
            }
            // Points outside: beyond the top, and beside an edge.
            assert!(inverse(forward(&p, [1.0 / 3.0; 3], 1.2), &p).is_none(), "case {c}");
            assert!(inverse(forward(&p, [-0.1, 0.6, 0.5], 0.5), &p).is_none(), "case {c}");
        }
    }

    /// The intervals of rays through a right prism (a box-like wedge) are the exact chords.
    #[test]
    fn intervals_of_a_right_prism_are_its_chords() {
        let p = prism(
            [DVec3::new(-1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, 2.0), DVec3::new(-1.0, 1.0, 2.0)],
            [DVec3::new(0.0, 0.0, 1.0); 3],
        );
        // Straight down the z axis through the wedge: from z = 2 to z = 3.
        let d = DVec3::new(-0.2, -0.3, 1.0).normalize();
        let iv = ray_intervals(d, &p, 0.0, f64::INFINITY);
        let t_bottom = 2.0 / d.z;
        let t_top = 3.0 / d.z;
        assert_eq!(iv.len(), 1);
        assert!((iv[0].0 - t_bottom).abs() < 1e-12 && (iv[0].1 - t_top).abs() < 1e-12, "{iv:?}");
        // Through a side: enters the bottom, leaves by the side x = -1 (at z = 1 / 0.45).
        let d = DVec3::new(-0.45, 0.0, 1.0).normalize();
        let iv = ray_intervals(d, &p, 0.0, f64::INFINITY);
        assert_eq!(iv.len(), 1, "{iv:?}");
        let (t_in, t_out) = (2.0 / d.z, 1.0 / 0.45 / d.z);
        assert!((iv[0].0 - t_in).abs() < 1e-12 && (iv[0].1 - t_out).abs() < 1e-12, "{iv:?}");
        // A ray that misses.
        assert!(ray_intervals(DVec3::new(1.0, 0.0, 0.0), &p, 0.0, f64::INFINITY).is_empty());
    }

    /// A curved (twisted-free but non-planar) side patch: every reported hit lies on the patch.
    #[test]
    fn patch_hits_lie_on_the_patch() {
        let (q00, q10) = (DVec3::new(-1.0, 0.0, 3.0), DVec3::new(1.0, 0.2, 3.0));
        let (q01, q11) = (DVec3::new(-1.2, 0.5, 4.0), DVec3::new(1.0, -0.4, 4.2));
        let mut found = 0;
        for i in 0..40 {
            for j in 0..40 {
                let d = DVec3::new(-0.4 + 0.02 * i as f64, -0.3 + 0.02 * j as f64, 1.0).normalize();
                for t in ray_patch(d, q00, q10, q01, q11).into_iter().flatten() {
                    let x = d * t;
                    // Closest point on the patch by dense search must be (nearly) x.
                    let mut best = f64::INFINITY;
                    for u in 0..=200 {
                        for v in 0..=200 {
                            let (u, v) = (u as f64 / 200.0, v as f64 / 200.0);
                            let s = (q00 * (1.0 - u) + q10 * u) * (1.0 - v) + (q01 * (1.0 - u) + q11 * u) * v;
                            best = best.min((s - x).length());
                        }
                    }
                    assert!(best < 0.02, "hit {x:?} is {best} from the patch");
                    found += 1;
                }
            }
        }
        assert!(found > 100, "{found} hits");
    }
}
