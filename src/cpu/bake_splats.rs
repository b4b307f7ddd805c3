//! CPU twin (f64) of `wgsl/bake_splats.wgsl`: the splat set of a hypertexture object from its
//! lattice (see `hypertexture::splats`), in lattice order (the kernel appends in any order).

use glam::DVec3;

use super::hypertexture::Model;
use crate::hypertexture::splats::Lattice;
use crate::types::Splat;

/// Mirrors the kernel's constants (in cells).
pub const HALF_DIAGONAL: f64 = 0.8660254;
pub const SURFACE_RADIUS: f64 = 1.8;
pub const INTERIOR_RADIUS: f64 = 2.0;

fn splat(c: DVec3, r: f64, n: DVec3) -> Splat {
    Splat {
        center: [c.x as f32, c.y as f32, c.z as f32, r as f32],
        normal: [n.x as f32, n.y as f32, n.z as f32, 0.0],
    }
}

/// Surface and interior splats of `model`'s object over `lattice`.
pub fn bake_splats(model: &Model, lattice: &Lattice) -> (Vec<Splat>, Vec<Splat>) {
    let level = |x: DVec3| model.support_distance(x) - lattice.level;
    let cell = lattice.cell;
    let e = 0.25 * cell;
    let gradient = |x: DVec3| {
        let d = |o: DVec3| level(x + o) - level(x - o);
        DVec3::new(d(DVec3::X * e), d(DVec3::Y * e), d(DVec3::Z * e)) / (2.0 * e)
    };
    let (mut surface, mut interior) = (Vec::new(), Vec::new());
    let [nx, ny, nz] = lattice.counts;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let x = lattice.centre(i, j, k);
                let s = level(x);
                if s.abs() <= HALF_DIAGONAL * cell {
                    let mut p = x;
                    let mut g = gradient(p);
                    for _ in 0..2 {
                        if g.length_squared() > 1e-12 {
                            p -= level(p) * g / g.length_squared();
                            g = gradient(p);
                        }
                    }
                    if g.length() > 1e-6 {
                        surface.push(splat(p, SURFACE_RADIUS * cell, g.normalize()));
                    }
                }
                if s < 0.0 {
                    interior.extend(interior_splat(lattice, &level, [i, j, k], s));
                }
            }
        }
    }
    (surface, interior)
}

/// The interior splat cell `id` makes, if any (`s`: its centre's level, negative): the sphere of
/// the largest block of 8^3, 4^3 or 2^3 cells around it that fits inside the splat surface (made
/// by the block's first cell only), else its own.
fn interior_splat(lattice: &Lattice, level: &impl Fn(DVec3) -> f64, id: [u32; 3], s: f64) -> Option<Splat> {
    let cell = lattice.cell;
    for m in (1..=3).rev() {
        let k = 1u32 << m;
        let corner = id.map(|c| c & !(k - 1));
        let centre = lattice.min
            + (DVec3::new(corner[0] as f64, corner[1] as f64, corner[2] as f64) + 0.5 * k as f64) * cell;
        let r = k as f64 * cell * HALF_DIAGONAL;
        if level(centre) <= -r {
            return (id == corner).then(|| splat(centre, r, DVec3::ZERO));
        }
    }
    Some(splat(
        lattice.centre(id[0], id[1], id[2]),
        (-s).clamp(HALF_DIAGONAL * cell, INTERIOR_RADIUS * cell),
        DVec3::ZERO,
    ))
}
