//! Twin of `mip_texel_volume.wgsl`: MIP level `l + 1` of a texel volume from level `l`.

/// The voxels of the level below `finer` (a `size` volume, x fastest, then y, then z): each the
/// mean of the 2x2x2 voxels it covers, the last voxel of an odd axis repeated.
pub fn mip_texel_volume(finer: &[[f32; 4]], size: [u32; 3]) -> Vec<[f32; 4]> {
    let [w, h, d] = size;
    let c = size.map(|s| (s / 2).max(1));
    let mut out = Vec::with_capacity((c[0] * c[1] * c[2]) as usize);
    for z in 0..c[2] {
        for y in 0..c[1] {
            for x in 0..c[0] {
                let mut sum = [0.0f32; 4];
                for k in 0..8u32 {
                    let sx = (2 * x + (k & 1)).min(w - 1);
                    let sy = (2 * y + ((k >> 1) & 1)).min(h - 1);
                    let sz = (2 * z + (k >> 2)).min(d - 1);
                    let p = finer[((sz * h + sy) * w + sx) as usize];
                    for i in 0..4 {
                        sum[i] += p[i];
                    }
                }
                out.push(sum.map(|v| v * 0.125));
            }
        }
    }
    out
}
