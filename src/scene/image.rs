//! Height textures: PNG images (grey, grey+alpha, RGB, RGBA; 8 or 16 bit) as values in `[0, 1]`,
//! and EXR images (any channels, half or float) as their values, at full precision.

use crate::error::{Error, Result};
use glam::DVec2;
use std::path::Path;

/// A height image: PNG or EXR values per pixel and channel.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Channels per pixel.
    pub channels: usize,
    /// Row-major from the top row, `channels` values per pixel: in `[0, 1]` from a PNG, as
    /// stored (finite) from an EXR.
    pub data: Vec<f32>,
}

impl HeightImage {
    /// Reads a PNG, or an EXR by its extension.
    pub fn load(path: &Path) -> Result<HeightImage> {
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            return Self::load_exr(path);
        }
        let bytes = crate::input::read(path, crate::input::Kind::Asset, "a PNG image")?;
        let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        // Palettes and low bit depths expand to 8 bit; 16 bit stays 16 (precision for heights).
        decoder.set_transformations(png::Transformations::EXPAND);
        let bad = |e: png::DecodingError| Error::file(path, format!("expected a PNG image: {e}"));
        let mut reader = decoder.read_info().map_err(bad)?;
        let size = reader.output_buffer_size().ok_or_else(|| Error::file(path, "PNG image too large"))?;
        let mut buf = vec![0; size];
        let info = reader.next_frame(&mut buf).map_err(bad)?;
        let channels = info.color_type.samples();
        let (w, h) = (info.width as usize, info.height as usize);
        let n = w * h * channels;
        let data = match info.bit_depth {
            png::BitDepth::Sixteen => buf
                .chunks_exact(2)
                .take(n)
                .map(|b| u16::from_be_bytes([b[0], b[1]]) as f32 / 65535.0)
                .collect(),
            _ => buf[..n].iter().map(|&b| b as f32 / 255.0).collect(),
        };
        Ok(HeightImage { width: w, height: h, channels, data })
    }

    /// An EXR's channels interleaved (R, G, B, A first; see `io::exr::read_channels`).
    fn load_exr(path: &Path) -> Result<HeightImage> {
        let (width, height, planes) = crate::io::exr::read_channels(path)?;
        if planes.is_empty() || width == 0 || height == 0 {
            return Err(Error::file(path, "expected an EXR image with at least one channel and pixel"));
        }
        for (name, values) in &planes {
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                let (x, y) = (i % width, i / width);
                return Err(Error::file(path, format!("channel {name}: pixel ({x}, {y}) is not finite")));
            }
        }
        let channels = planes.len();
        let data = (0..width * height).flat_map(|i| planes.iter().map(move |(_, p)| p[i])).collect();
        Ok(HeightImage { width, height, channels, data })
    }

    fn texel(&self, x: i64, y: i64, channel: usize) -> f64 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.data[(y * self.width + x) * self.channels + channel] as f64
    }

    /// Bilinear with wrapping; pixel centres at (i + 0.5) / size; v = 0 is the bottom row.
    pub(crate) fn sample(&self, uv: DVec2, channel: usize) -> f64 {
        let x = uv.x * self.width as f64 - 0.5;
        let y = (1.0 - uv.y) * self.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0, channel) * (1.0 - fx) + self.texel(x0 + 1, y0, channel) * fx;
        let bottom = self.texel(x0, y0 + 1, channel) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1, channel) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_wraps() {
        let img = HeightImage { width: 2, height: 1, channels: 1, data: vec![0.0, 1.0] };
        assert_eq!(img.sample(DVec2::new(0.25, 0.5), 0), 0.0);
        assert_eq!(img.sample(DVec2::new(0.75, 0.5), 0), 1.0);
        assert_eq!(img.sample(DVec2::new(0.5, 0.5), 0), 0.5);
        // Across the wrap: u = 0 is halfway between the last and first pixel.
        assert_eq!(img.sample(DVec2::new(0.0, 0.5), 0), 0.5);
        assert_eq!(img.sample(DVec2::new(1.0, 0.5), 0), 0.5);
    }
}
