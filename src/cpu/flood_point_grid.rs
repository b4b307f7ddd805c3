//! CPU twin (f64) of `wgsl/bake/flood_point_grid.wgsl`: jump flooding of the closest boundary
//! points of a point grid's inside samples from its outside samples' exact ones, pass by pass as
//! the kernel runs them.

use crate::mesh::shape::GridSpec;

/// Inside samples without a boundary point yet (mirrors `NO_SEED`).
pub(crate) const NO_SEED: f64 = 3.0e38;

/// The steps of the passes (in samples) for `n` samples per axis: halving from the largest power
/// of two below `n` to 1, then passes of 1 until their count is even (so the last pass writes
/// the grid, not the scratch buffer; extra passes of 1 also mend jump flooding's rare misses).
pub(crate) fn flood_steps(n: u32) -> Vec<u32> {
    let mut steps = Vec::new();
    let mut k = (n.max(2) - 1).next_power_of_two() / 2;
    while k >= 1 {
        steps.push(k);
        k /= 2;
    }
    steps.push(1);
    if steps.len() % 2 == 1 {
        steps.push(1);
    }
    steps
}

/// One pass of step `step` from `from` (the first block of a point grid) into a new block.
pub(crate) fn flood_point_grid(from: &[[f64; 4]], spec: &GridSpec, step: u32) -> Vec<[f64; 4]> {
    let [nx, ny, nz] = spec.n.map(|n| n as i64);
    let index = |i: i64, j: i64, k: i64| (i + nx * (j + ny * k)) as usize;
    let mut to = from.to_vec();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let mut best = from[index(i, j, k)];
                if best[3] <= 0.0 {
                    continue;
                }
                let p = spec.point(i as u32, j as u32, k as u32);
                for d in 0..27i64 {
                    let s = step as i64;
                    let m = [i + (d % 3 - 1) * s, j + ((d / 3) % 3 - 1) * s, k + (d / 9 - 1) * s];
                    if d == 13 || m.iter().zip([nx, ny, nz]).any(|(&c, n)| c < 0 || c >= n) {
                        continue;
                    }
                    let c = from[index(m[0], m[1], m[2])];
                    if c[3] >= NO_SEED {
                        continue;
                    }
                    let q = spec.point(m[0] as u32, m[1] as u32, m[2] as u32)
                        + glam::DVec3::new(c[0], c[1], c[2]);
                    let v = q - p;
                    if v.length() < best[3] {
                        best = [v.x, v.y, v.z, v.length()];
                    }
                }
                to[index(i, j, k)] = best;
            }
        }
    }
    to
}
