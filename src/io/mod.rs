//! Images in and out: a linear HDR RGBA [`Image`], EXR ([`exr`]) for results and references, PNG
//! ([`png`]) for tonemapped previews and heat maps. Every write is atomic ([`atomic`]): a reader
//! never sees a half-written file, and a failed write leaves the old file as it was.

pub mod atomic;
pub mod exr;
pub mod png;
pub mod stack;
pub mod vdb;

use crate::{Error, Result};

/// A linear (scene-referred) HDR RGBA image, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels; `pixels[y * width + x]`.
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    /// A `width` × `height` image of transparent black.
    pub fn new(width: u32, height: u32) -> Self {
        Self::filled(width, height, [0.0; 4])
    }

    /// A `width` × `height` image with every pixel `value`.
    pub fn filled(width: u32, height: u32, value: [f32; 4]) -> Self {
        Self { width, height, pixels: vec![value; width as usize * height as usize] }
    }

    /// An image whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> [f32; 4]) -> Self {
        let mut pixels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Self { width, height, pixels }
    }

    /// Wraps existing pixels; their count must be `width * height`.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> Result<Self> {
        let expected = width as usize * height as usize;
        if pixels.len() != expected {
            return Err(Error::Invalid(format!(
                "image {width}x{height} needs {expected} pixels, got {}",
                pixels.len()
            )));
        }
        Ok(Self { width, height, pixels })
    }

    /// Index of pixel (x, y) in `pixels`. Panics when out of bounds (a programming error).
    pub(crate) fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}x{}", self.width, self.height);
        y as usize * self.width as usize + x as usize
    }

    /// Pixel (x, y). Panics when out of bounds.
    pub fn get(&self, x: u32, y: u32) -> [f32; 4] {
        self.pixels[self.index(x, y)]
    }

    /// Sets pixel (x, y). Panics when out of bounds.
    pub fn set(&mut self, x: u32, y: u32, value: [f32; 4]) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    /// Whether the image has no pixel.
    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }

    /// Same width and height as `other`.
    /// The mean of each `n x n` block (`n` = 1 returns the image itself); sizes must divide.
    pub fn box_downsample(self, n: u32) -> Image {
        if n <= 1 {
            return self;
        }
        let (w, h) = (self.width / n, self.height / n);
        Image::from_fn(w, h, |x, y| {
            let mut sum = [0.0f64; 4];
            for dy in 0..n {
                for dx in 0..n {
                    let p = self.get(x * n + dx, y * n + dy);
                    for c in 0..4 {
                        sum[c] += p[c] as f64;
                    }
                }
            }
            sum.map(|v| (v / (n * n) as f64) as f32)
        })
    }

    /// Like [`Image::box_downsample`], keeping each block's smallest value per channel (a depth:
    /// the nearest hit, not a mean of near and far).
    pub(crate) fn min_downsample(self, n: u32) -> Image {
        if n <= 1 {
            return self;
        }
        Image::from_fn(self.width / n, self.height / n, |x, y| {
            let mut out = [f32::INFINITY; 4];
            for dy in 0..n {
                for dx in 0..n {
                    let p = self.get(x * n + dx, y * n + dy);
                    for c in 0..4 {
                        out[c] = out[c].min(p[c]);
                    }
                }
            }
            out
        })
    }

    /// Whether `other` has the same width and height.
    pub fn same_size(&self, other: &Image) -> bool {
        self.width == other.width && self.height == other.height
    }

    /// The image tonemapped with `tonemap` into 8-bit sRGB; alpha is clamped to [0, 1] and
    /// quantized linearly.
    pub fn to_srgb8(&self) -> Vec<[u8; 4]> {
        self.pixels
            .iter()
            .map(|p| {
                let [r, g, b] = tonemap([p[0], p[1], p[2]]);
                let a = if p[3].is_finite() { p[3].clamp(0.0, 1.0) } else { 0.0 };
                [quantize(r), quantize(g), quantize(b), quantize(a)]
            })
            .collect()
    }
}

/// Maps a [0, 1] value to 0..=255, rounding to nearest.
pub(crate) fn quantize(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Linear HDR RGB → display sRGB in [0, 1]: exposure 1, the ACES filmic curve as fitted by
/// K. Narkowicz (2015), then the sRGB OETF. Negative values clamp to 0, non-finite values map to 0.
pub(crate) fn tonemap(rgb: [f32; 3]) -> [f32; 3] {
    rgb.map(|v| {
        if !v.is_finite() {
            return 0.0;
        }
        let x = v.max(0.0);
        // Narkowicz's fit: x (a x + b) / (x (c x + d) + e).
        let filmic = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
        srgb_oetf(filmic.clamp(0.0, 1.0)).clamp(0.0, 1.0)
    })
}

/// The sRGB opto-electronic transfer function (linear [0, 1] → encoded [0, 1]).
pub(crate) fn srgb_oetf(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tonemap_is_monotonic_clamped_and_safe() {
        assert_eq!(tonemap([0.0, -1.0, f32::NAN]), [0.0, 0.0, 0.0]);
        assert_eq!(tonemap([f32::INFINITY; 3]), [0.0; 3]);
        let mut last = 0.0;
        for i in 1..200 {
            let v = tonemap([i as f32 * 0.1; 3])[0];
            assert!(v >= last && v <= 1.0, "{v} after {last}");
            last = v;
        }
        assert!(tonemap([1e6; 3])[0] > 0.99);
    }

    #[test]
    fn image_indexing() {
        let img = Image::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.0, 1.0]);
        assert_eq!(img.get(2, 1), [2.0, 1.0, 0.0, 1.0]);
        assert_eq!(img.pixels[img.index(1, 1)], [1.0, 1.0, 0.0, 1.0]);
        assert!(Image::from_pixels(2, 2, vec![[0.0; 4]; 3]).is_err());
    }
}
