//! Image error metrics for comparing a render with a reference: relative RMSE on the linear HDR
//! values, LDR FLIP on the tonemapped images, and helpers for hard-case tests.

use crate::io::Image;
use crate::{Error, Result};

/// Added to `reference²` in the relative error denominator so that near-black reference pixels
/// do not blow the error up: an absolute error of 0.1 on black counts like a 100 % error.
pub(crate) const RELATIVE_EPSILON: f64 = 1e-2;

/// Default FLIP viewing condition: a 0.7 m wide 4K (3840 px) display seen from 0.7 m.
pub(crate) const DEFAULT_PIXELS_PER_DEGREE: f32 = 67.0;

fn check_sizes(actual: &Image, reference: &Image) -> Result<()> {
    if !actual.same_size(reference) {
        return Err(Error::Invalid(format!(
            "image size mismatch: actual {}x{}, reference {}x{}",
            actual.width, actual.height, reference.width, reference.height
        )));
    }
    let n = actual.width as usize * actual.height as usize;
    if actual.pixels.len() != n || reference.pixels.len() != n {
        return Err(Error::Invalid("image pixel count does not match its size".into()));
    }
    if n == 0 {
        return Err(Error::Invalid("cannot compare empty images".into()));
    }
    Ok(())
}

/// Per-pixel relative squared error averaged over R, G, B: `mean_c (a-r)² / (r² + ε)`.
fn relative_sq(a: &[f32; 4], r: &[f32; 4]) -> f64 {
    (0..3)
        .map(|c| {
            let (a, r) = (a[c] as f64, r[c] as f64);
            (a - r) * (a - r) / (r * r + RELATIVE_EPSILON)
        })
        .sum::<f64>()
        / 3.0
}

/// Relative RMSE: `sqrt(mean over pixels and R, G, B of (a - r)² / (r² + ε))` with
/// ε = `RELATIVE_EPSILON` = 1e-2. Alpha is ignored. A non-finite value in either image makes the
/// result NaN (so any `<= threshold` check fails). Size mismatch is an error.
pub fn relative_rmse(actual: &Image, reference: &Image) -> Result<f64> {
    check_sizes(actual, reference)?;
    let sum: f64 = actual.pixels.iter().zip(&reference.pixels).map(|(a, r)| relative_sq(a, r)).sum();
    Ok((sum / actual.pixels.len() as f64).sqrt())
}

/// Per-pixel relative RMS error over R, G, B (same terms as [`relative_rmse`]), clamped to [0, 1]
/// (non-finite → 1), for a heat map.
pub fn relative_error_map(actual: &Image, reference: &Image) -> Result<Vec<f32>> {
    check_sizes(actual, reference)?;
    Ok(actual
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            let e = relative_sq(a, r).sqrt() as f32;
            if e.is_finite() {
                e.clamp(0.0, 1.0)
            } else {
                1.0
            }
        })
        .collect())
}

/// Result of [`flip`]: the mean FLIP error and the per-pixel error map (row-major, in [0, 1]).
#[derive(Debug, Clone)]
pub struct FlipResult {
    /// Mean FLIP over the image, in [0, 1].
    pub mean: f64,
    /// Per-pixel FLIP, row-major.
    pub map: Vec<f32>,
}

/// LDR FLIP (Andersson et al. 2020) between the tonemapped images (see `crate::io::tonemap`),
/// at `DEFAULT_PIXELS_PER_DEGREE`. 0 means identical; 1 is the largest perceived difference.
pub fn flip(actual: &Image, reference: &Image) -> Result<FlipResult> {
    flip_with_ppd(actual, reference, DEFAULT_PIXELS_PER_DEGREE)
}

/// [`flip`] with an explicit viewing condition in pixels per degree of visual angle.
///
/// Computed by NVIDIA's reference C++ implementation (crate `nv-flip`) on 8-bit sRGB images,
/// which is how LDR FLIP is defined; quantization differences below 1/255 are not seen.
pub(crate) fn flip_with_ppd(actual: &Image, reference: &Image, pixels_per_degree: f32) -> Result<FlipResult> {
    check_sizes(actual, reference)?;
    if !(pixels_per_degree.is_finite() && pixels_per_degree > 0.0) {
        return Err(Error::Invalid(format!(
            "FLIP pixels per degree must be positive, got {pixels_per_degree}"
        )));
    }
    let to_flip = |img: &Image| {
        let rgb: Vec<u8> = img.to_srgb8().iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
        nv_flip::FlipImageRgb8::with_data(img.width, img.height, &rgb)
    };
    let error = nv_flip::flip(to_flip(reference), to_flip(actual), pixels_per_degree);
    let map = error.to_vec();
    let mean = map.iter().map(|&v| v as f64).sum::<f64>() / map.len() as f64;
    Ok(FlipResult { mean, map })
}

/// Colours an error map (values in [0, 1], row-major `width` × `height`) with the magma colour
/// ramp (black → purple → orange → pale yellow) used by FLIP's own tools. Non-finite values
/// show as the top colour; missing values as 0.
pub fn diff_heatmap(map: &[f32], width: u32, height: u32) -> Vec<[u8; 4]> {
    let lut = nv_flip::magma_lut().to_vec();
    let n = width as usize * height as usize;
    (0..n)
        .map(|i| {
            let v = map.get(i).copied().unwrap_or(0.0);
            let v = if v.is_finite() { v.clamp(0.0, 1.0) } else { 1.0 };
            let k = (v * 255.0 + 0.5) as usize * 3;
            [lut[k], lut[k + 1], lut[k + 2], 255]
        })
        .collect()
}

/// The colours of [`diff_heatmap`] at `n` evenly spaced values from 0 to 1 (n >= 2), as
/// `#rrggbb`: a legend's colour scale.
pub(crate) fn heatmap_scale(n: usize) -> Vec<String> {
    let n = n.max(2);
    let values: Vec<f32> = (0..n).map(|i| i as f32 / (n - 1) as f32).collect();
    diff_heatmap(&values, n as u32, 1)
        .iter()
        .map(|c| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]))
        .collect()
}

/// Largest absolute difference over all pixels and R, G, B, A channels (NaN if any value is
/// non-finite in a way that differs, e.g. NaN vs a number). Size mismatch is an error.
pub fn max_abs_diff(actual: &Image, reference: &Image) -> Result<f64> {
    check_sizes(actual, reference)?;
    let mut max = 0.0f64;
    for (a, r) in actual.pixels.iter().zip(&reference.pixels) {
        for c in 0..4 {
            let d = (a[c] as f64 - r[c] as f64).abs();
            if d.is_nan() {
                return Ok(f64::NAN);
            }
            max = max.max(d);
        }
    }
    Ok(max)
}

/// Number of pixels with at least one non-finite (NaN or ±∞) channel, alpha included.
pub fn count_nonfinite(image: &Image) -> usize {
    image.pixels.iter().filter(|p| p.iter().any(|v| !v.is_finite())).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_rmse_of_a_known_offset() {
        let r = Image::filled(2, 2, [1.0, 1.0, 1.0, 1.0]);
        let a = Image::filled(2, 2, [1.1, 1.1, 1.1, 1.0]);
        let e = relative_rmse(&a, &r).unwrap();
        let want = (0.01f64 / 1.01).sqrt();
        assert!((e - want).abs() < 1e-6, "{e} vs {want}");
    }

    #[test]
    fn heatmap_scale_matches_the_map() {
        let scale = heatmap_scale(5);
        let map = diff_heatmap(&[0.0, 0.25, 0.5, 0.75, 1.0], 5, 1);
        for (c, px) in scale.iter().zip(&map) {
            assert_eq!(*c, format!("#{:02x}{:02x}{:02x}", px[0], px[1], px[2]));
        }
        assert_ne!(scale[0], scale[4]);
    }

    #[test]
    fn heatmap_endpoints() {
        let h = diff_heatmap(&[0.0, 1.0, f32::NAN], 3, 1);
        assert_eq!(h.len(), 3);
        assert!(h[0][0] < 10 && h[0][1] < 10 && h[0][2] < 10, "{:?}", h[0]);
        assert!(h[1][0] > 200 && h[1][1] > 200, "{:?}", h[1]);
        assert_eq!(h[1], h[2]);
    }

    #[test]
    fn nonfinite_counting() {
        let mut img = Image::new(3, 1);
        img.pixels[0][1] = f32::NAN;
        img.pixels[2][3] = f32::INFINITY;
        assert_eq!(count_nonfinite(&img), 2);
        assert!(max_abs_diff(&img, &Image::new(3, 1)).unwrap().is_nan());
    }
}
