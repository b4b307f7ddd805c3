//! Checks that a base surface's prisms (triangle `i` extruded along its height vectors,
//! `P(b, w) = sum b_i (p_i + w h_i)`) are usable: no NaN, heights on the outer side, no twisted or
//! self-intersecting prisms. Degenerate triangles and zero heights only warn.

use super::BaseSurface;
use glam::DVec3;

/// What [`check`] found wrong with a base surface's prisms.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PrismReport {
    /// Questionable but drawable: degenerate triangles, zero-length height vectors.
    pub warnings: Vec<String>,
    /// Not drawable: missing vertices, non-finite values, inward-flipped height vectors, twisted prisms.
    pub errors: Vec<String>,
}

impl PrismReport {
    /// Whether no error was found.
    pub fn is_ok(&self) -> bool {
        self.errors.is_empty()
    }
}

/// Heights sampled along the prism for the twist test.
const TWIST_W: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// Largest coordinate of a position, height vector or prism corner: kernels square f32
/// distances, which overflow near 1e19.
pub(crate) const MAX_COORD: f64 = 1e15;
/// A triangle is degenerate when its smallest altitude is below this fraction of its longest edge.
const SLIVER: f64 = 1e-3;

/// "3, 8, 12" for the first 10 items, then "and N more".
fn list(items: &[usize]) -> String {
    let shown: Vec<String> = items.iter().take(10).map(|i| i.to_string()).collect();
    let mut s = shown.join(", ");
    if items.len() > 10 {
        s += &format!(" and {} more", items.len() - 10);
    }
    s
}

/// Checks every prism of `s`, listing the triangles at fault.
pub fn check(s: &BaseSurface) -> PrismReport {
    let mut r = PrismReport::default();
    if s.heights.len() != s.positions.len() || s.corner_uvs.len() != s.triangles.len() {
        r.errors.push(format!(
            "inconsistent sizes: {} positions, {} heights, {} triangles, {} corner uv triples",
            s.positions.len(),
            s.heights.len(),
            s.triangles.len(),
            s.corner_uvs.len()
        ));
        return r;
    }
    if let Some(t) = s.triangles.iter().position(|t| t.iter().any(|&i| i as usize >= s.positions.len())) {
        r.errors.push(format!("triangle {t} references a missing vertex"));
        return r;
    }
    // Kernels work in f32 (camera-relative): beyond MAX_COORD products overflow to infinity.
    let usable = |v: DVec3| v.is_finite() && v.abs().max_element() <= MAX_COORD;
    let bad_v: Vec<usize> = (0..s.positions.len())
        .filter(|&i| {
            !usable(s.positions[i]) || !usable(s.heights[i]) || !usable(s.positions[i] + s.heights[i])
        })
        .collect();
    let bad_uv: Vec<usize> =
        (0..s.triangles.len()).filter(|&t| s.corner_uvs[t].iter().any(|uv| !uv.is_finite())).collect();
    if !bad_v.is_empty() {
        r.errors.push(format!(
            "non-finite or huge (beyond ±{MAX_COORD:e}) position or height at vertices {}",
            list(&bad_v)
        ));
    }
    if !bad_uv.is_empty() {
        r.errors.push(format!("non-finite uv at triangles {}", list(&bad_uv)));
    }
    if !r.errors.is_empty() {
        return r;
    }

    // Smallest altitude = twice the area / longest edge.
    let base_ok: Vec<bool> = s
        .triangles
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| s.positions[i as usize]);
            let area2 = (b - a).cross(c - a).length();
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            longest > 0.0 && area2 / longest >= SLIVER * longest
        })
        .collect();
    let degenerate: Vec<usize> = (0..base_ok.len()).filter(|&t| !base_ok[t]).collect();
    if s.triangles.is_empty() || degenerate.len() == s.triangles.len() {
        // Nothing could be drawn: an error rather than a silently empty image.
        r.errors.push(format!(
            "no usable triangle: all {} triangles are degenerate or missing",
            s.triangles.len()
        ));
        return r;
    }
    if !degenerate.is_empty() {
        r.warnings.push(format!(
            "{} degenerate (zero-area or sliver) triangles: {}",
            degenerate.len(),
            list(&degenerate)
        ));
    }

    let zero_h: Vec<usize> = (0..s.heights.len()).filter(|&i| s.heights[i] == DVec3::ZERO).collect();
    if !zero_h.is_empty() {
        r.warnings.push(format!(
            "{} zero-length height vectors at vertices: {}",
            zero_h.len(),
            list(&zero_h)
        ));
    }

    // Heights on the inner side of an adjacent face, and prisms whose cross-section at some w
    // flips or collapses (twisted or self-intersecting).
    let mut inward = Vec::new();
    let mut twisted = Vec::new();
    for t in (0..s.triangles.len()).filter(|&t| base_ok[t]) {
        let n0 = s.face_normal(t);
        let ids = s.triangles[t].map(|i| i as usize);
        if ids.iter().any(|&i| s.heights[i] != DVec3::ZERO && s.heights[i].dot(n0) <= 0.0) {
            inward.push(t);
            continue;
        }
        let p = s.prism(t);
        let flips = TWIST_W.iter().any(|&w| {
            let q = [0, 1, 2].map(|k| p[k] + (p[k + 3] - p[k]) * w);
            let n = (q[1] - q[0]).cross(q[2] - q[0]);
            n.dot(n0) <= 1e-12 * n0.length_squared()
        });
        if flips {
            twisted.push(t);
        }
    }
    if !inward.is_empty() {
        r.errors.push(format!(
            "height vectors point inward (against the face normal) at {} triangles: {}",
            inward.len(),
            list(&inward)
        ));
    }
    if !twisted.is_empty() {
        r.errors.push(format!(
            "twisted or self-intersecting prisms (height vectors too long for the curvature?) at {} triangles: {}",
            twisted.len(),
            list(&twisted)
        ));
    }
    r
}

/// A sphere containing a prism's six corners: centroid and largest distance to it.
pub fn bounding_sphere(p: [DVec3; 6]) -> (DVec3, f64) {
    let c = p.iter().copied().sum::<DVec3>() / 6.0;
    let r = p.iter().map(|q| (*q - c).length()).fold(0.0, f64::max);
    (c, r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn quad() -> BaseSurface {
        BaseSurface {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            heights: vec![DVec3::Z * 0.1; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            corner_uvs: vec![[DVec2::ZERO; 3]; 2],
        }
    }

    #[test]
    fn clean_surface_passes() {
        assert_eq!(check(&quad()), PrismReport::default());
        for seed in 0..16 {
            let torus = crate::mesh::generate::torus(1.0, 0.45, [24, 12], 0.15, seed);
            let r = check(&torus.to_base(0.35, None, DVec2::ONE));
            assert!(r.errors.is_empty() && r.warnings.is_empty(), "{r:?}");
        }
        // Heights longer than the inner radius cross over the axis.
        let torus = crate::mesh::generate::torus(1.0, 0.45, [24, 12], 0.0, 0);
        let r = check(&torus.to_base(0.7, None, DVec2::ONE));
        assert!(r.errors[0].contains("twisted"), "{r:?}");
    }

    #[test]
    fn flipped_height_is_an_error() {
        let mut s = quad();
        s.heights[1] = -DVec3::Z * 0.1;
        let r = check(&s);
        assert!(r.errors[0].contains("inward") && r.errors[0].ends_with(": 0"), "{r:?}");
    }

    #[test]
    fn twisted_prism_is_an_error() {
        let mut s = quad();
        // Heights that cross over: the top triangle of prism 1 is mirrored.
        s.heights[2] = DVec3::new(-2.0, 0.0, 0.1);
        s.heights[3] = DVec3::new(2.0, 0.0, 0.1);
        let r = check(&s);
        assert!(r.errors.iter().any(|e| e.contains("twisted") && e.ends_with(": 1")), "{r:?}");
    }

    #[test]
    fn zero_area_and_zero_height_warn_nan_errors() {
        let mut s = quad();
        s.positions[3] = DVec3::new(0.5, 0.5, 0.0); // on the diagonal: triangle 1 has no area
        s.heights[0] = DVec3::ZERO;
        let r = check(&s);
        assert!(r.errors.is_empty(), "{r:?}");
        assert!(r.warnings[0].contains("degenerate") && r.warnings[0].ends_with(": 1"));
        assert!(r.warnings[1].contains("zero-length") && r.warnings[1].ends_with(": 0"));
        s.heights[2].x = f64::NAN;
        assert!(check(&s).errors[0].contains("non-finite"));
    }

    #[test]
    fn list_truncates() {
        assert_eq!(list(&(0..13).collect::<Vec<_>>()), "0, 1, 2, 3, 4, 5, 6, 7, 8, 9 and 3 more");
    }

    #[test]
    fn sphere_contains_corners() {
        let (c, r) = bounding_sphere(quad().prism(0));
        assert!(quad().prism(0).iter().all(|p| (*p - c).length() <= r + 1e-12));
    }
}
