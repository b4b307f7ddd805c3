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

/// Per column of level-0 bricks (x fastest): the first and last occupied brick along w, or
/// `None` where the column holds nothing. `pyramid`: a [`pyramid`] of a volume of `res`.
pub(crate) fn columns(pyramid: &[u32], res: [u32; 3]) -> Vec<Option<(u32, u32)>> {
    let [bx, by, bz] = dims(res, BRICKS[0]).map(|n| n as usize);
    let mut out = vec![None; bx * by];
    for z in 0..bz {
        for (c, range) in out.iter_mut().enumerate() {
            if pyramid[z * bx * by + c] != 0 {
                let z = z as u32;
                *range = Some(range.map_or((z, z), |(lo, _): (u32, u32)| (lo, z)));
            }
        }
    }
    out
}

/// The band of w (0 to 1) outside which every sample over the voxel box `lo..=hi` of s and t
/// (voxel coordinates, repeating) is exactly transparent: whole level-0 bricks from the first
/// occupied one to the last (each brick covers samples up to half a voxel beyond it, so the
/// samples below and above read only empty bricks' voxels). `None`: all of them are.
pub(crate) fn band(
    columns: &[Option<(u32, u32)>],
    res: [u32; 3],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Option<[f64; 2]> {
    let size = BRICKS[0] as f64;
    let [bx, by, _] = dims(res, BRICKS[0]).map(|n| n as i64);
    let first = lo.map(|v| (v / size).floor() as i64);
    let last = hi.map(|v| (v / size).floor() as i64);
    let mut range: Option<(u32, u32)> = None;
    for y in first[1]..=last[1].min(first[1] + by - 1) {
        for x in first[0]..=last[0].min(first[0] + bx - 1) {
            if let Some((a, b)) = columns[(y.rem_euclid(by) * bx + x.rem_euclid(bx)) as usize] {
                range = Some(range.map_or((a, b), |(lo, hi)| (lo.min(a), hi.max(b))));
            }
        }
    }
    let depth = res[2] as f64;
    range.map(|(a, b)| [a as f64 * size / depth, ((b + 1) as f64 * size).min(depth) / depth])
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

    /// The band over a box of s and t is the occupied bricks' w extent, found across the repeat.
    #[test]
    fn a_band_spans_the_occupied_bricks_over_a_box_of_s_and_t() {
        let res = [16, 16, 16];
        let mut alpha = vec![0u8; 16 * 16 * 16];
        // Voxel (14, 2, 9): brick (3, 0, 2); its reach adds brick (3, 1, 2) and, across the
        // wrap, none in s (15 is still brick 3).
        alpha[(9 * 16 + 2) * 16 + 14] = 90;
        let cols = columns(&pyramid(&alpha, res), res);
        assert_eq!(cols[3], Some((2, 2)));
        assert_eq!(band(&cols, res, [13.0, 0.0], [15.0, 3.0]), Some([0.5, 0.75]));
        // The same bricks reached from the next repeat of s (x 16 + 13), and a box beside them.
        assert_eq!(band(&cols, res, [29.0, 0.0], [30.0, 1.0]), Some([0.5, 0.75]));
        assert_eq!(band(&cols, res, [0.0, 9.0], [7.0, 15.0]), None);
        // Samples of the band's neighbours read only empty voxels (every sample's 8 voxels).
        let sample_alpha = |z: f64| {
            let z0 = (z * 16.0 - 0.5).floor().clamp(0.0, 15.0) as usize;
            let z1 = (z0 + 1).min(15);
            [z0, z1].iter().map(|&z| alpha[(z * 16 + 2) * 16 + 14]).max().unwrap()
        };
        assert!(sample_alpha(0.5 - 1e-9) == 0 && sample_alpha(0.75 + 1e-9) == 0);
        assert!(sample_alpha(0.59) > 0);
    }
}
