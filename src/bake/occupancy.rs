//! The occupancy pyramid of a texel, for empty-space skipping (read by ShellMarch's kernel, and
//! by the world export to leave out leaves only empty texel space reaches): levels of bricks of 4, 16 and 64 voxels, x fastest, each brick holding the most
//! opacity (0 to 255) of the voxels within one voxel of it: a trilinear sample taken up to half a
//! voxel outside the brick reads only those, so where a brick holds 0 such samples are exactly
//! transparent and skipping them changes no pixel. Made on the CPU from the texel the kernel
//! reads.

/// Brick edge in voxels, per level.
pub(crate) const BRICKS: [u32; 3] = [4, 16, 64];

/// Bricks per axis at brick size `size`.
fn dims(res: [u32; 3], size: u32) -> [u32; 3] {
    res.map(|n| n.div_ceil(size))
}

/// Words of an object's pyramid (one per brick, all levels).
pub(crate) fn words(res: [u32; 3]) -> u64 {
    BRICKS.iter().map(|&b| dims(res, b).iter().map(|&d| d as u64).product::<u64>()).sum()
}

/// Along one axis of a grid of `shape` cells (x fastest): per brick of `size` cells, the most of
/// its cells and of one beyond either side (repeating when `wrap`, else clamped).
fn reduce_axis(
    values: &[u8],
    shape: [usize; 3],
    axis: usize,
    size: usize,
    wrap: bool,
) -> (Vec<u8>, [usize; 3]) {
    let n = shape[axis];
    let bricks = n.div_ceil(size);
    let mut out_shape = shape;
    out_shape[axis] = bricks;
    let mut out = vec![0u8; out_shape.iter().product()];
    let index = |s: [usize; 3], c: [usize; 3]| (c[2] * s[1] + c[1]) * s[0] + c[0];
    for z in 0..out_shape[2] {
        for y in 0..out_shape[1] {
            for x in 0..out_shape[0] {
                let at = [x, y, z];
                let b = at[axis] as i64;
                let (lo, hi) = (b * size as i64 - 1, ((b + 1) * size as i64).min(n as i64));
                let mut most = 0u8;
                for i in lo..=hi {
                    let i = if wrap { i.rem_euclid(n as i64) } else { i.clamp(0, n as i64 - 1) } as usize;
                    let mut c = at;
                    c[axis] = i;
                    most = most.max(values[index(shape, c)]);
                }
                out[index(out_shape, at)] = most;
            }
        }
    }
    (out, out_shape)
}

/// The pyramid of a volume whose opacity at voxel (x, y, z) is `alpha[(z * h + y) * w + x]`.
pub(crate) fn pyramid(alpha: &[u8], res: [u32; 3]) -> Vec<u32> {
    let shape = res.map(|n| n as usize);
    let mut out = Vec::with_capacity(words(res) as usize);
    for size in BRICKS {
        let size = size as usize;
        let (a, s) = reduce_axis(alpha, shape, 0, size, true);
        let (a, s) = reduce_axis(&a, s, 1, size, true);
        let (a, _) = reduce_axis(&a, s, 2, size, false);
        out.extend(a.into_iter().map(u32::from));
    }
    out
}

/// Level 0 opacity of a volume read back as f32 RGBA (x fastest): any opacity above 0 counts at
/// least 1, so that no occupied voxel reads as empty.
pub(crate) fn float_alpha(rgba: &[[f32; 4]]) -> Vec<u8> {
    rgba.iter().map(|v| if v[3] > 0.0 { (v[3].min(1.0) * 255.0).round().max(1.0) as u8 } else { 0 }).collect()
}

/// Level 0 opacity of one object's volume from the atlas bytes (rgba8, rows `pitch` words apart,
/// starting at word `offset`).
pub(crate) fn atlas_alpha(bytes: &[u8], res: [u32; 3], offset: u32, pitch: u32) -> Vec<u8> {
    let [w, h, d] = res.map(|n| n as usize);
    let mut out = Vec::with_capacity(w * h * d);
    for z in 0..d {
        for y in 0..h {
            let row = (offset as usize + (z * h + y) * pitch as usize) * 4;
            out.extend((0..w).map(|x| bytes[row + 4 * x + 3]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One opaque voxel marks the bricks within one voxel of it, across the repeat in s and t,
    /// and nothing else.
    #[test]
    fn a_voxel_marks_the_bricks_that_can_sample_it() {
        let res = [8, 8, 8];
        let mut alpha = vec![0u8; 512];
        // Voxel (0, 4, 7): next to the s wrap, inside in t, at the top in w.
        alpha[(7 * 8 + 4) * 8] = 200;
        let p = pyramid(&alpha, res);
        assert_eq!(p.len() as u64, words(res));
        // Level 0: 2 x 2 x 2 bricks of 4.
        let at = |x: usize, y: usize, z: usize| p[(z * 2 + y) * 2 + x];
        // s: brick 0 holds it, brick 1 reaches it across the wrap (its cells 4..8 and 8 = 0).
        // t: voxel 4 is brick 1's first, within one voxel of brick 0's last (3). w: brick 1 only.
        for (x, y, z, want) in
            [(0, 0, 1, 200), (1, 0, 1, 200), (0, 1, 1, 200), (1, 1, 1, 200), (0, 0, 0, 0), (1, 1, 0, 0)]
        {
            assert_eq!(at(x, y, z), want, "brick ({x}, {y}, {z})");
        }
        // Levels 1 and 2: one brick each, holding it.
        assert_eq!(&p[8..], &[200, 200]);
        assert!(pyramid(&vec![0; 512], res).iter().all(|&v| v == 0));
    }
}
