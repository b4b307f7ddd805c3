//! CPU twin (f64) of `wgsl/ray_march/bake_splats.wgsl`: the splat set of a hypertexture object from its
//! lattice (see `hypertexture::splats`), in lattice order (the kernel appends in any order).

use glam::DVec3;

use super::hypertexture::Model;
use crate::types::{SegmentParams, Splat};

/// Mirrors the kernel's constants (in cells).
pub(crate) const HALF_DIAGONAL: f64 = 0.8660254;
pub(crate) const SURFACE_RADIUS: f64 = 1.8;
pub(crate) const INTERIOR_RADIUS: f64 = 2.0;

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

/// Where the splats come from: the lattice and the splat surface's level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Cells along the bounds' longest axis (the scene's `splat_grid`).
    pub(crate) grid: u32,
    pub(crate) min: DVec3,
    /// Cell size, object units.
    pub cell: f64,
    /// Cells along x, y and z.
    pub counts: [u32; 3],
    /// Support distance of the splat surface.
    pub level: f64,
}

impl Lattice {
    /// `bounds`: the enlarged bounds; `shift`: the largest shift (as the kernels test it);
    /// `grid`: cells along the longest axis.
    pub(crate) fn new(bounds: (DVec3, DVec3), shift: f64, grid: u32) -> Self {
        let cell = (bounds.1 - bounds.0).max_element() / grid as f64;
        let level = shift + 0.5 * cell;
        // Beyond the bounds by the level and a cell: mesh support distances are lower bounds
        // (the splat surface may lie farther out than the bounds' enlargement).
        let pad = DVec3::splat(level + cell);
        let (lo, hi) = (bounds.0 - pad, bounds.1 + pad);
        let counts = ((hi - lo) / cell).ceil().to_array().map(|c| c as u32);
        Lattice { grid, min: lo, cell, counts, level }
    }

    pub(crate) fn cells(&self) -> u32 {
        self.counts.iter().product()
    }

    /// The centre of cell `(i, j, k)` (object space).
    pub(crate) fn centre(&self, i: u32, j: u32, k: u32) -> DVec3 {
        self.min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.cell
    }

    /// Fills the lattice fields of `params`.
    pub(crate) fn write(&self, params: &mut SegmentParams) {
        let m = self.min;
        params.lattice_min = [m.x as f32, m.y as f32, m.z as f32, self.cell as f32];
        let c = self.counts;
        params.lattice = [c[0], c[1], c[2], self.cells()];
        params.surface[0] = self.level as f32;
    }
}
