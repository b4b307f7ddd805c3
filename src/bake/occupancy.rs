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

/// The opacity of a volume of `res` dilated by `radius` voxels in s and t (each voxel the most
/// within `radius` of it along x, then y, repeating): the pyramid of the result covers samples
/// that read that much farther than a level-0 one (ShellMarch's footprint filter).
pub(crate) fn dilate_st(alpha: &[u8], res: [u32; 3], radius: u32) -> Vec<u8> {
    let shape = res.map(|n| n as usize);
    let pass = |values: &[u8], axis: usize| -> Vec<u8> {
        let n = shape[axis];
        let stride = if axis == 0 { 1 } else { shape[0] };
        let r = (radius as usize).min(n / 2);
        let mut out = vec![0u8; values.len()];
        let mut row = Vec::with_capacity(n);
        for base in (0..values.len()).filter(|i| (i / stride) % n == 0) {
            row.clear();
            row.extend((0..n).map(|k| values[base + k * stride]));
            for (k, v) in window_max(&row, r).into_iter().enumerate() {
                out[base + k * stride] = v;
            }
        }
        out
    };
    pass(&pass(alpha, 0), 1)
}

/// Per entry of the repeating `row`, the most within `r` of it (r <= len / 2), in time linear in
/// the row (van Herk / Gil-Werman: maxima of blocks of the window's width, from either end).
fn window_max(row: &[u8], r: usize) -> Vec<u8> {
    let (n, w) = (row.len(), 2 * r + 1);
    let ext: Vec<u8> = (0..n + 2 * r).map(|i| row[(i + n - r) % n]).collect();
    let (mut ahead, mut behind) = (ext.clone(), ext.clone());
    for i in 1..ext.len() {
        if i % w != 0 {
            ahead[i] = ahead[i].max(ahead[i - 1]);
        }
    }
    for i in (0..ext.len() - 1).rev() {
        if (i + 1) % w != 0 {
            behind[i] = behind[i].max(behind[i + 1]);
        }
    }
    (0..n).map(|i| behind[i].max(ahead[i + w - 1])).collect()
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

    /// Dilation in s and t reaches across the repeat and leaves w alone.
    #[test]
    fn dilation_spreads_in_s_and_t_only() {
        let res = [8, 4, 2];
        let mut alpha = vec![0u8; 64];
        alpha[(4 + 1) * 8 + 7] = 9; // (7, 1, 1)
        let d = dilate_st(&alpha, res, 1);
        let at = |x: usize, y: usize, z: usize| d[(z * 4 + y) * 8 + x];
        for (x, y) in [(6, 0), (7, 1), (0, 2), (0, 1)] {
            assert_eq!(at(x, y, 1), 9, "({x}, {y})");
        }
        assert_eq!((at(5, 1, 1), at(1, 1, 1), at(7, 3, 1), at(7, 1, 0)), (0, 0, 0, 0));
        // A radius past half the size takes the whole row and column.
        assert!(dilate_st(&alpha, res, 9)[32..].iter().all(|&v| v == 9));
        // The linear-time window against the plain one, on every radius of a varied row.
        let row: Vec<u8> = (0..13u32).map(|i| (i * 37 % 11) as u8).collect();
        for r in 0..=6 {
            let plain: Vec<u8> =
                (0..13).map(|i| (0..=2 * r).map(|k| row[(i + 13 - r + k) % 13]).max().unwrap()).collect();
            assert_eq!(window_max(&row, r), plain, "radius {r}");
        }
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
