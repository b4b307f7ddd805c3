//! CPU twin (f64) of `wgsl/bake/bake_point_grid.wgsl`: per outside grid sample the vector to the
//! closest point of the union of a point set's kernel balls and the distance to it, then per
//! sample the sum of the kernels `(1 - r^2/R^2)^3` over the saturation, by brute force over
//! every point (ground truth: no BVH to get wrong); [`bake_point_grid`] then floods the inside
//! samples' closest boundary points as `flood_point_grid.wgsl` does.

use glam::DVec3;

use super::flood_point_grid::{flood_point_grid, flood_steps, NO_SEED};
use crate::mesh::points::PointSet;
use crate::mesh::shape::GridSpec;

/// The kernel `(1 - r^2/R^2)^3` inside R (Wyvill's soft-object falloff), 0 outside.
pub fn kernel(r: f64, radius: f64) -> f64 {
    let t = 1.0 - r * r / (radius * radius);
    if t > 0.0 {
        t * t * t
    } else {
        0.0
    }
}

/// One sample before flooding: outside, (vector to the closest ball's closest point, minus the
/// distance); inside, (0, 0, 0, `NO_SEED`); and the kernel sum.
pub(crate) fn sample(set: &PointSet, radius: f64, p: DVec3) -> ([f64; 4], f64) {
    let mut best = f64::INFINITY;
    let mut centre = p;
    let mut sum = 0.0;
    for (i, &c) in set.centres.iter().enumerate() {
        let r = set.radius(i, radius);
        let d = p - c;
        if d.length() - r < best {
            best = d.length() - r;
            centre = c;
        }
        sum += kernel(d.length(), r);
    }
    if best < 0.0 {
        return ([0.0, 0.0, 0.0, NO_SEED], sum);
    }
    let v = (centre - p).normalize_or_zero() * best;
    ([v.x, v.y, v.z, -best], sum)
}

/// Every sample of the grid (x fastest, then y, then z) as (vector xyz, signed distance), then
/// every sample's kernel sum over `saturation` (in x; y, z, w zero), as the kernel writes them.
pub fn bake_point_grid(set: &PointSet, radius: f64, saturation: f64, spec: &GridSpec) -> Vec<[f64; 4]> {
    let [nx, ny, nz] = spec.n;
    let mut cells = Vec::with_capacity(2 * spec.samples() as usize);
    let mut sums = Vec::with_capacity(spec.samples() as usize);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (cell, sum) = sample(set, radius, spec.point(i, j, k));
                cells.push(cell);
                sums.push([sum / saturation, 0.0, 0.0, 0.0]);
            }
        }
    }
    for step in flood_steps(spec.n[0]) {
        cells = flood_point_grid(&cells, spec, step);
    }
    cells.extend(sums);
    cells
}
