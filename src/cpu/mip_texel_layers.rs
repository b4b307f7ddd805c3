//! Twin of `mip_texel_layers.wgsl`: MIP level `l + 1` of a texel's layers from level `l`.

/// The texels of the level below `finer` (`layers` layers of `size`, x fastest, then y, then
/// the layer): each the mean of the 2x2 it covers within its layer, wrapping past an odd size.
pub fn mip_texel_layers(finer: &[[f32; 4]], size: [u32; 2], layers: u32) -> Vec<[f32; 4]> {
    let [w, h] = size;
    let (cw, ch) = ((w / 2).max(1), (h / 2).max(1));
    let mut out = Vec::with_capacity((cw * ch * layers) as usize);
    for layer in 0..layers {
        for y in 0..ch {
            for x in 0..cw {
                let mut sum = [0.0f32; 4];
                for k in 0..4u32 {
                    let sx = (2 * x + (k & 1)) % w;
                    let sy = (2 * y + (k >> 1)) % h;
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
