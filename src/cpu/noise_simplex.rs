//! CPU twin (f64) of `wgsl/shared/simplex.wgsl`: 3D and 4D simplex noise (Gustavson 2005) with
//! gradients picked by an integer hash of the lattice corner and a seed.

use glam::{DVec3, DVec4};

use super::bake::pcg_hash;

/// The gradient of corner `c` dotted with `x` (Perlin 2002's 12 cube-edge directions).
pub(crate) fn simplex_gradient(c: [i32; 3], seed: u32, x: DVec3) -> f64 {
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

/// `simplex_wrap`: the class of corner `c` modulo the periods (3a, 3b, 3c) of `tile` (0: none).
pub(crate) fn simplex_wrap(c: [i32; 3], tile: [i32; 3]) -> [i32; 3] {
    if tile[0] <= 0 {
        return c;
    }
    let w = [5 * c[0] - c[1] - c[2], 5 * c[1] - c[2] - c[0], 5 * c[2] - c[0] - c[1]];
    [0, 1, 2].map(|i| w[i].rem_euclid(18 * tile[i]))
}

fn simplex_corner(c: [i32; 3], seed: u32, x: DVec3, tile: [i32; 3]) -> f64 {
    let t = 0.6 - x.dot(x);
    if t <= 0.0 {
        return 0.0;
    }
    t * t * t * t * simplex_gradient(simplex_wrap(c, tile), seed, x)
}

/// Simplex noise of `p` in [-1, 1].
pub fn simplex3(p: DVec3, seed: u32) -> f64 {
    simplex3_tiled(p, seed, [0; 3])
}

/// Simplex noise repeating every (3a, 3b, 3c) cells for `tile` = (a, b, c) > 0.
pub fn simplex3_tiled(p: DVec3, seed: u32, tile: [i32; 3]) -> f64 {
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
    let n = simplex_corner(c, seed, x0, tile)
        + simplex_corner(add(i1), seed, x1, tile)
        + simplex_corner(add(i2), seed, x2, tile)
        + simplex_corner(add(DVec3::ONE), seed, x3, tile);
    (32.0 * n).clamp(-1.0, 1.0)
}

/// The gradient of 4D corner `c` dotted with `x` (the 32 tesseract-edge directions).
pub(crate) fn simplex_gradient4(c: [i32; 4], seed: u32, x: DVec4) -> f64 {
    let h = pcg_hash((c[0] as u32).wrapping_add(pcg_hash((c[1] as u32).wrapping_add(pcg_hash(
        (c[2] as u32).wrapping_add(pcg_hash((c[3] as u32).wrapping_add(pcg_hash(seed)))),
    )))))
        & 31;
    let o = match h >> 3 {
        1 => [x.x, x.z, x.w],
        2 => [x.x, x.y, x.w],
        3 => [x.x, x.y, x.z],
        _ => [x.y, x.z, x.w],
    };
    let sign = |v: f64, bit: u32| if h & bit == 0 { v } else { -v };
    sign(o[0], 1) + sign(o[1], 2) + sign(o[2], 4)
}

fn simplex_corner4(c: [i32; 4], seed: u32, x: DVec4) -> f64 {
    let t = 0.6 - x.dot(x);
    if t <= 0.0 {
        return 0.0;
    }
    t * t * t * t * simplex_gradient4(c, seed, x)
}

/// 4D simplex noise of `p` in [-1, 1] (the fourth coordinate is time).
pub fn simplex4(p: DVec4, seed: u32) -> f64 {
    let f4 = (5f64.sqrt() - 1.0) / 4.0;
    let g4 = (5.0 - 5f64.sqrt()) / 20.0;
    let skew = (p.x + p.y + p.z + p.w) * f4;
    let cell = (p + DVec4::splat(skew)).floor();
    let unskew = (cell.x + cell.y + cell.z + cell.w) * g4;
    let x0 = p - cell + DVec4::splat(unskew);
    let ge = |a: f64, b: f64| if a >= b { 1.0 } else { 0.0 };
    let is_x = [ge(x0.x, x0.y), ge(x0.x, x0.z), ge(x0.x, x0.w)];
    let is_yz = [ge(x0.y, x0.z), ge(x0.y, x0.w), ge(x0.z, x0.w)];
    let rank = DVec4::new(
        is_x[0] + is_x[1] + is_x[2],
        1.0 - is_x[0] + is_yz[0] + is_yz[1],
        1.0 - is_x[1] + 1.0 - is_yz[0] + is_yz[2],
        1.0 - is_x[2] + 2.0 - is_yz[1] - is_yz[2],
    );
    let i1 = (rank - DVec4::splat(2.0)).clamp(DVec4::ZERO, DVec4::ONE);
    let i2 = (rank - DVec4::ONE).clamp(DVec4::ZERO, DVec4::ONE);
    let i3 = rank.clamp(DVec4::ZERO, DVec4::ONE);
    let x1 = x0 - i1 + DVec4::splat(g4);
    let x2 = x0 - i2 + DVec4::splat(2.0 * g4);
    let x3 = x0 - i3 + DVec4::splat(3.0 * g4);
    let x4 = x0 - DVec4::splat(1.0 - 4.0 * g4);
    let c = [cell.x as i32, cell.y as i32, cell.z as i32, cell.w as i32];
    let add = |o: DVec4| [c[0] + o.x as i32, c[1] + o.y as i32, c[2] + o.z as i32, c[3] + o.w as i32];
    let n = simplex_corner4(c, seed, x0)
        + simplex_corner4(add(i1), seed, x1)
        + simplex_corner4(add(i2), seed, x2)
        + simplex_corner4(add(i3), seed, x3)
        + simplex_corner4(add(DVec4::ONE), seed, x4);
    (27.0 * n).clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Range, mean and largest change over a 1e-6 step of a noise at 20000 random points:
    /// `sample(next)` draws its point with `next` (uniform in [0, 1]) and returns (value, change).
    struct Survey {
        lo: f64,
        hi: f64,
        mean: f64,
        jump: f64,
    }

    const SAMPLES: usize = 20000;

    fn survey(
        name: &str,
        seed: u32,
        mut sample: impl FnMut(&mut dyn FnMut() -> f64) -> (f64, f64),
    ) -> Survey {
        let mut rng = seed;
        let mut next = || {
            rng = pcg_hash(rng);
            rng as f64 / u32::MAX as f64
        };
        let (mut lo, mut hi, mut sum, mut jump): (f64, f64, f64, f64) = (1.0, -1.0, 0.0, 0.0);
        for _ in 0..SAMPLES {
            let (v, change) = sample(&mut next);
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            jump = jump.max(change);
        }
        let mean = sum / SAMPLES as f64;
        eprintln!("{name}: range [{lo:.3}, {hi:.3}], mean {mean:.4}, largest change over 1e-6: {jump:.2e}");
        Survey { lo, hi, mean, jump }
    }

    /// The noise is continuous (no jump across simplex borders), spans most of [-1, 1] and has a
    /// mean near 0; seeds give independent noises.
    #[test]
    fn simplex_is_continuous_bounded_and_seeded() {
        let mut same = 0;
        let s = survey("simplex3", 0x1234_5678, |next| {
            let p = DVec3::new(next(), next(), next()) * 40.0 - DVec3::splat(20.0);
            let v = simplex3(p, 0);
            let e = DVec3::new(next(), next(), next()).normalize() * 1e-6;
            same += ((simplex3(p, 1) - v).abs() < 1e-9) as usize;
            (v, (simplex3(p + e, 0) - v).abs())
        });
        assert!(s.lo < -0.8 && s.hi > 0.8 && s.lo >= -1.0 && s.hi <= 1.0);
        assert!(s.mean.abs() < 0.02);
        assert!(s.jump < 1e-4, "continuous: {}", s.jump);
        assert!(same < SAMPLES / 100, "seed 1 differs from seed 0");
    }

    /// 4D noise: continuous in space and time, spans most of [-1, 1], mean near 0.
    #[test]
    fn simplex4_is_continuous_and_bounded() {
        let s = survey("simplex4", 0x9e37_79b9, |next| {
            let p = DVec4::new(next(), next(), next(), next()) * 40.0 - DVec4::splat(20.0);
            let v = simplex4(p, 3);
            let e = DVec4::new(next(), next(), next(), next()).normalize() * 1e-6;
            (v, (simplex4(p + e, 3) - v).abs())
        });
        assert!(s.lo < -0.7 && s.hi > 0.7 && s.lo >= -1.0 && s.hi <= 1.0);
        assert!(s.mean.abs() < 0.02);
        assert!(s.jump < 1e-4, "continuous: {}", s.jump);
    }
}
