//! Twin of `mip_layers.wgsl`: MIP level `l + 1` of a 2D texture array from level `l`.

/// The texels of the level below `finer` (`layers` layers of `size`, x fastest, then y, then
/// the layer): each the mean of the 2x2 it covers within its layer; past an odd size, the first
/// column, and the first row with `wrap_rows`, else the last.
pub fn mip_layers(finer: &[[f32; 4]], size: [u32; 2], layers: u32, wrap_rows: bool) -> Vec<[f32; 4]> {
    let [w, h] = size;
    let (cw, ch) = ((w / 2).max(1), (h / 2).max(1));
    let mut out = Vec::with_capacity((cw * ch * layers) as usize);
    for layer in 0..layers {
        for y in 0..ch {
            for x in 0..cw {
                let mut sum = [0.0f32; 4];
                for k in 0..4u32 {
                    let sx = (2 * x + (k & 1)) % w;
                    let qy = 2 * y + (k >> 1);
                    let sy = if wrap_rows { qy % h } else { qy.min(h - 1) };
                    let p = finer[((layer * h + sy) * w + sx) as usize];
                    for i in 0..4 {
                        sum[i] += p[i];
                    }
                }
                out.push(sum.map(|v| v * 0.25));
            }
        }
    }
    out
}
