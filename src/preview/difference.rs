//! The preview's difference view (key `3`): FLIP between the frame and the reference's frame,
//! its mean and its heat map in the colours of `voltex compare --diff` and of the regress report
//! (magma, 0 to 1), so the three agree on what a difference looks like and how large it is.

use crate::gpu::GpuContext;
use crate::io::Image;

/// The difference of one pair of finished frames.
pub(crate) struct Difference {
    /// Which frames it was made from (the window's counts of finished frames and references).
    pub(crate) key: (u64, u64),
    /// The heat map (sRGB), shown as it is; `None` where FLIP could not be computed.
    pub(crate) texture: Option<wgpu::Texture>,
    /// The mean FLIP, or why there is none (a draft frame against a full-size reference).
    pub(crate) flip: Result<f64, String>,
}

impl Difference {
    /// FLIP of `image` against `reference` (as `voltex compare` computes it), uploaded as a heat
    /// map.
    pub(crate) fn new(ctx: &GpuContext, image: &Image, reference: &Image, key: (u64, u64)) -> Self {
        let flip = match crate::metrics::flip(image, reference) {
            Ok(f) => f,
            Err(e) => return Difference { key, texture: None, flip: Err(e.to_string()) },
        };
        let heat = crate::metrics::diff_heatmap(&flip.map, image.width, image.height);
        let size = wgpu::Extent3d { width: image.width, height: image.height, depth_or_array_layers: 1 };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("difference heat map"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        ctx.queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(&heat),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * image.width),
                rows_per_image: None,
            },
            size,
        );
        Difference { key, texture: Some(texture), flip: Ok(flip.mean) }
    }

    /// The info line: the mean FLIP and the scale's ends.
    pub(crate) fn line(&self) -> String {
        match &self.flip {
            Ok(mean) => format!("mean FLIP {mean:.5} (heat map: black 0 .. yellow 1)"),
            Err(e) => format!("no FLIP: {e}"),
        }
    }
}

/// The heat map's colour at `v` in [0, 1] (the colour scale drawn beside the view).
pub(crate) fn colour(v: f32) -> [u8; 4] {
    crate::metrics::diff_heatmap(&[v], 1, 1)[0]
}
