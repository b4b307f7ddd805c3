//! CPU twin (f64) of `wgsl/shared/simplex.wgsl`: 3D simplex noise (Gustavson 2005) with gradients
//! picked by an integer hash of the lattice corner and a seed.

use glam::DVec3;

use super::bake::pcg_hash;

/// The gradient of corner `c` dotted with `x` (Perlin 2002's 12 cube-edge directions).
pub fn simplex_gradient(c: [i32; 3], seed: u32, x: DVec3) -> f64 {
    let h = pcg_hash((c[0] as u32).wrapping_add(pcg_hash(
        (c[1] as u32).wrapping_add(pcg_hash((c[2] as u32).wrapping_add(pcg_hash(seed)))),
    ))) & 15;
    let u = if h < 8 { x.x } else { x.y };
    let v = if h < 4 {
        x.y
    } else if h == 12 || h == 14 {
        x.x
    } else {
        x.z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

fn simplex_corner(c: [i32; 3], seed: u32, x: DVec3) -> f64 {
    let t = 0.6 - x.dot(x);
    if t <= 0.0 {
        return 0.0;
    }
    t * t * t * t * simplex_gradient(c, seed, x)
}

/// Simplex noise of `p` in [-1, 1].
pub fn simplex3(p: DVec3, seed: u32) -> f64 {
    let skew = (p.x + p.y + p.z) / 3.0;
    let cell = (p + DVec3::splat(skew)).floor();
    let unskew = (cell.x + cell.y + cell.z) / 6.0;
    let x0 = p - cell + DVec3::splat(unskew);
    let ge = |a: f64, b: f64| if a >= b { 1.0 } else { 0.0 };
    let g = DVec3::new(ge(x0.x, x0.y), ge(x0.y, x0.z), ge(x0.z, x0.x));
    let l = DVec3::ONE - g;
    let lzxy = DVec3::new(l.z, l.x, l.y);
    let i1 = g.min(lzxy);
    let i2 = g.max(lzxy);
    let x1 = x0 - i1 + DVec3::splat(1.0 / 6.0);
    let x2 = x0 - i2 + DVec3::splat(1.0 / 3.0);
    let x3 = x0 - DVec3::splat(0.5);
    let c = [cell.x as i32, cell.y as i32, cell.z as i32];
    let add = |o: DVec3| [c[0] + o.x as i32, c[1] + o.y as i32, c[2] + o.z as i32];
    let n = simplex_corner(c, seed, x0)
        + simplex_corner(add(i1), seed, x1)
        + simplex_corner(add(i2), seed, x2)
        + simplex_corner(add(DVec3::ONE), seed, x3);
    (32.0 * n).clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise is continuous (no jump across simplex borders), spans most of [-1, 1] and has a
    /// mean near 0; seeds give independent noises.
    #[test]
    fn simplex_is_continuous_bounded_and_seeded() {
        let mut rng = 0x1234_5678u32;
        let mut next = || {
            rng = pcg_hash(rng);
            rng as f64 / u32::MAX as f64
        };
        let (mut lo, mut hi, mut sum, mut jump, mut same): (f64, f64, f64, f64, usize) =
            (1.0, -1.0, 0.0, 0.0, 0);
        let n = 20000;
        for _ in 0..n {
            let p = DVec3::new(next(), next(), next()) * 40.0 - DVec3::splat(20.0);
            let v = simplex3(p, 0);
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            let e = DVec3::new(next(), next(), next()).normalize() * 1e-6;
            jump = jump.max((simplex3(p + e, 0) - v).abs());
            same += ((simplex3(p, 1) - v).abs() < 1e-9) as usize;
        }
        eprintln!(
            "simplex3: range [{lo:.3}, {hi:.3}], mean {:.4}, largest change over 1e-6: {jump:.2e}",
            sum / n as f64
        );
        assert!(lo < -0.8 && hi > 0.8 && lo >= -1.0 && hi <= 1.0);
        assert!((sum / n as f64).abs() < 0.02);
        assert!(jump < 1e-4, "continuous: {jump}");
        assert!(same < n / 100, "seed 1 differs from seed 0");
    }
}
