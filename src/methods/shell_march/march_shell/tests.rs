//! The twin's geometry: folds found, neighbours' crossings identical, and the interpolated
//! (s, t, w) within the tolerance of the exact map.

use super::*;
use crate::methods::reference::trace_reference::DecodedTexel;

/// A small deterministic generator (xorshift), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn prism(bottom: [DVec3; 3], heights: [DVec3; 3], ids: [u32; 3]) -> PrismCorners {
    PrismCorners { bottom, top: [0, 1, 2].map(|i| bottom[i] + heights[i]), ids }
}

/// One prism drawn with these knobs, over a 32^3 texel with uvs spanning one tile.
fn object(p: PrismCorners, tolerance: f64) -> ShellObject {
    let uvs = vec![[DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)]];
    let volume = DecodedTexel { resolution: [32, 32, 32], texels: vec![[0.0; 4]; 32 * 32 * 32] };
    let trace = TraceObject {
        prisms: vec![p],
        uvs,
        volume,
        per_pixel: None,
        opacity_length: 1.0,
        step: 0.01,
        opaque_base: false,
    };
    ShellObject { trace, step: 1.0, tolerance, bands: vec![[0.0, 1.0]], filter: None }
}

/// Base triangle in front of a camera at the origin looking down +y.
fn base() -> [DVec3; 3] {
    [DVec3::new(-1.0, 4.0, -1.0), DVec3::new(1.0, 4.2, -1.0), DVec3::new(0.0, 3.8, 1.0)]
}

/// Rays from the origin at the prism's interior points (so they cross it).
fn rays(p: &PrismCorners, rng: &mut Rng, n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|_| {
            let (a, b) = (rng.next(), rng.next());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let w = rng.next();
            let at = |q: &[DVec3; 3]| q[0] * (1.0 - a - b) + q[1] * a + q[2] * b;
            (at(&p.bottom) * (1.0 - w) + at(&p.top) * w).normalize()
        })
        .collect()
}

#[test]
fn folds_only_where_the_jacobian_changes_sign() {
    let up = DVec3::new(0.0, -0.3, 0.0);
    assert!(!folds(&prism(base(), [up; 3], [0, 1, 2])), "equal heights: an affine map");
    let fan = [DVec3::new(-0.2, -0.3, -0.1), DVec3::new(0.2, -0.3, -0.1), DVec3::new(0.0, -0.3, 0.2)];
    assert!(!folds(&prism(base(), fan, [0, 1, 2])), "heights spreading out, as on a convex surface");
    // Heights crossing over: the top triangle is the base turned over, so the map folds inside.
    let b = base();
    let crossing = [b[1] - b[0] + up, b[0] - b[1] + up, up];
    assert!(folds(&prism(b, crossing, [0, 1, 2])));
    assert!(folds(&prism(base(), [DVec3::ZERO; 3], [0, 1, 2])), "no height: the map is degenerate");
}

/// Two prisms sharing a side (welded ids 1 and 2, listed in opposite orders) see the same
/// crossings of it, bit for bit, and the same map value on it.
#[test]
fn neighbours_cross_their_shared_side_at_identical_points() {
    let b = base();
    let h = [DVec3::new(-0.1, -0.3, 0.0), DVec3::new(0.1, -0.35, 0.05), DVec3::new(0.0, -0.25, 0.1)];
    let other = b[1] + b[2] - b[0];
    let left = prism(b, h, [0, 1, 2]);
    let right = prism([b[2], b[1], other], [h[2], h[1], DVec3::new(0.05, -0.3, 0.1)], [2, 1, 3]);
    let mut rng = Rng(7);
    let mut shared = 0;
    // Rays through points of the shared side, and through either prism.
    let on_side: Vec<DVec3> = (0..400)
        .map(|_| {
            let (u, w) = (rng.next(), rng.next());
            let at = |q: &[DVec3; 3]| q[1] * (1.0 - u) + q[2] * u;
            (at(&left.bottom) * (1.0 - w) + at(&left.top) * w).normalize()
        })
        .collect();
    let through = rays(&left, &mut rng, 200).into_iter().chain(rays(&right, &mut rng, 200));
    for d in on_side.into_iter().chain(through) {
        let (l, r) = (crossings(d, &left, [0.0, 1.0]), crossings(d, &right, [0.0, 1.0]));
        // Crossings of the shared side: corner 0 of left has no weight, corner 2 of right none.
        let on_left: Vec<&Crossing> = l.iter().filter(|c| c.1[0] == 0.0 && c.1[3] > 0.0 && c.1[3] < 1.0).collect();
        let on_right: Vec<&Crossing> = r.iter().filter(|c| c.1[2] == 0.0 && c.1[3] > 0.0 && c.1[3] < 1.0).collect();
        assert_eq!(on_left.len(), on_right.len(), "ray {d}: {l:?} against {r:?}");
        for (a, b) in on_left.iter().zip(&on_right) {
            assert_eq!(a.0.to_bits(), b.0.to_bits(), "the same distance");
            // Vertex 1 is left's corner 1 and right's corner 1; vertex 2 left's 2, right's 0.
            assert_eq!((a.1[1], a.1[2], a.1[3]), (b.1[1], b.1[0], b.1[3]), "the same map value");
            shared += 1;
        }
    }
    assert!(shared > 400, "{shared} crossings of the shared side");
}

/// The largest error (voxels) of the interpolated map over 33 points of each interpolated piece,
/// and the pieces per interval, over rays through `p`.
fn interpolation_error(p: PrismCorners, tolerance: f64) -> (f64, f64) {
    let o = object(p, tolerance);
    let res = o.trace.volume.resolution;
    let uv = o.trace.uvs[0];
    let p = &o.trace.prisms[0];
    let mut rng = Rng(11);
    let (mut worst, mut pieces, mut count): (f64, usize, usize) = (0.0, 0, 0);
    for d in rays(p, &mut rng, 300) {
        for iv in intervals(d, 1.0, &o, 0, 0.1) {
            count += 1;
            pieces += iv.pieces;
            for j in 0..iv.pieces {
                let piece = piece(d, &o, &iv, j);
                let Some((a, b)) = piece.line else { continue };
                for k in 0..=32 {
                    let f = k as f64 / 32.0;
                    let t = piece.ta + (piece.tb - piece.ta) * f;
                    let Some(e) = exact(d * t, p) else { continue };
                    worst = worst.max(max3(voxels(&uv, res, e) - voxels(&uv, res, mix(a, b, f))));
                }
            }
        }
    }
    assert!(count > 250, "{count} intervals");
    (worst, pieces as f64 / count as f64)
}

/// Equal height vectors make the map affine: one piece, exact. Differing ones bend it: the
/// interpolation stays within the tolerance (checked at two points per piece; the error between
/// them is a little larger at most), and a tighter tolerance takes more pieces.
#[test]
fn interpolation_stays_within_the_tolerance() {
    let (err, pieces) = interpolation_error(prism(base(), [DVec3::new(0.0, -0.3, 0.0); 3], [0, 1, 2]), 0.25);
    assert!(err < 1e-6 && pieces == 1.0, "affine: error {err}, {pieces} pieces");
    let bent = [DVec3::new(-0.6, -0.3, -0.5), DVec3::new(0.6, -0.3, -0.5), DVec3::new(0.0, -0.3, 0.7)];
    let mut last = 0.0;
    for tolerance in [1.0, 0.25, 0.05] {
        let (err, pieces) = interpolation_error(prism(base(), bent, [0, 1, 2]), tolerance);
        eprintln!("tolerance {tolerance}: worst error {err:.4} voxels, {pieces:.2} pieces per interval");
        assert!(err <= 1.5 * tolerance, "tolerance {tolerance}: error {err}");
        assert!(pieces > last, "tolerance {tolerance}: {pieces} pieces, {last} with a looser one");
        last = pieces;
    }
}

/// Where the map folds, every sample is mapped exactly (no pieces).
#[test]
fn folded_prisms_are_mapped_exactly() {
    let b = base();
    let up = DVec3::new(0.0, -0.3, 0.0);
    let p = prism(b, [b[1] - b[0] + up, b[0] - b[1] + up, up], [0, 1, 2]);
    let o = object(p, 0.25);
    let mut rng = Rng(3);
    let mut seen = 0;
    for d in rays(&o.trace.prisms[0], &mut rng, 100) {
        for iv in intervals(d, 1.0, &o, 0, 0.1) {
            assert_eq!(iv.pieces, 0);
            assert!(piece(d, &o, &iv, 0).line.is_none());
            seen += 1;
        }
    }
    assert!(seen > 50);
}
