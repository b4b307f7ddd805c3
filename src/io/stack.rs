//! Slice stacks: a baked texel volume written out as one image per `w` slice (`voltex bake`) and
//! read back as a texel source (`Slices(dir: ..)`), so a bake can be inspected, edited in an
//! image editor, or shipped instead of its recipe.
//!
//! A stack is a folder holding `slice_000.png` (w = 0, the bottom) to `slice_NNN.png` (or `.exr`),
//! all of one size, rows from t = 1 (the top row of the image) down to t = 0, as images are
//! viewed, and a [`Manifest`] (`manifest.json`) saying how to read them: resolution, bounds,
//! opacity length, premultiplied or straight colour, baked or unlit, bit depth (8- or 16-bit
//! PNG, or 32-bit float EXR). A folder without a manifest is a stack of 8-bit premultiplied PNGs
//! with baked lighting, as `voltex bake` wrote them before manifests. Stacks are read at 16 bits.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::io::atomic::check_writable_dir;

/// The manifest's file name in a stack's folder.
pub(crate) const MANIFEST: &str = "manifest.json";
/// The manifest's `format` value.
pub const FORMAT: &str = "voltex slice stack";
/// Most slices, and pixels per side, in a stack: a texel's largest resolution.
const MAX_SLICES: u32 = 1024;

/// How a stack's slices are to be read (`manifest.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Pixels per slice (s, t) and slices (w).
    pub resolution: [u32; 3],
    /// The box of its source's space the texel samples, `[lo, hi]` (texel space `[0, 1]^3`,
    /// or a mesh's or hypertexture's object-space box).
    pub bounds: [[f64; 3]; 2],
    /// World length over which a voxel's alpha is reached; the texel's default when it gives
    /// none.
    pub opacity_length: f32,
    /// Colour multiplied by alpha (`true`), or straight colour.
    pub premultiplied: bool,
    /// Shading baked in with the scene's first light, or the unlit albedo.
    pub lighting: StackLighting,
    /// 8 or 16 (PNG), or 32 (float EXR).
    pub bit_depth: u32,
    /// The slice files in this folder, w = 0 first.
    pub slices: Vec<String>,
}

/// What a slice stack's colours hold (`lighting` in `manifest.json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StackLighting {
    /// Shading baked in with the scene's first light.
    Baked,
    /// The unlit albedo.
    Unlit,
}

/// A volume read from a stack: premultiplied RGBA at 16 bits, x fastest, then y (t = 0
/// first), then z; and the manifest it was read by, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct SliceStack {
    pub(crate) resolution: [u32; 3],
    pub(crate) texels: Vec<u16>,
    /// The stack's `manifest.json` (none: an older folder of 8-bit premultiplied PNGs).
    pub manifest: Option<Manifest>,
}

fn slice_name(z: u32, ext: &str) -> String {
    format!("slice_{z:03}.{ext}")
}

/// Writes `volume` (premultiplied f32 RGBA, x fastest, t = 0 first) as the stack `dir` the
/// way `manifest` says (its `slices` are named here). The slices and the manifest go to a fresh
/// temporary folder beside `dir`, which then replaces `dir` as a whole: an interrupted bake
/// leaves the old stack (or none), never a mix of old and new slices.
pub fn write(dir: &Path, manifest: &Manifest, volume: &[[f32; 4]]) -> Result<()> {
    let [w, h, d] = manifest.resolution;
    let layer = (w * h) as usize;
    if volume.len() != layer * d as usize || ![8, 16, 32].contains(&manifest.bit_depth) {
        return Err(Error::Invalid(format!(
            "a {w}x{h}x{d} volume at {} bits cannot be written from {} voxels",
            manifest.bit_depth,
            volume.len()
        )));
    }
    let ext = if manifest.bit_depth == 32 { "exr" } else { "png" };
    let manifest = Manifest { slices: (0..d).map(|z| slice_name(z, ext)).collect(), ..manifest.clone() };
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    check_writable_dir(&parent)?;
    let name = dir.file_name().ok_or_else(|| Error::file(dir, "expected a folder name"))?.to_string_lossy();
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let fill = || -> Result<()> {
        std::fs::create_dir(&tmp).map_err(|e| Error::file(&tmp, e))?;
        for z in 0..d {
            let slice = &volume[z as usize * layer..][..layer];
            // Image rows run from t = 1 down to t = 0.
            let pixels: Vec<[f32; 4]> = (0..h)
                .rev()
                .flat_map(|y| &slice[(y * w) as usize..][..w as usize])
                .map(|&p| if manifest.premultiplied { p } else { straight(p) })
                .collect();
            let path = tmp.join(&manifest.slices[z as usize]);
            let unit = |v: f32, max: f32| (v.clamp(0.0, 1.0) * max).round();
            match manifest.bit_depth {
                8 => {
                    let px: Vec<[u8; 4]> = pixels.iter().map(|p| p.map(|v| unit(v, 255.0) as u8)).collect();
                    crate::io::png::write_rgba8(&path, w, h, &px)?
                }
                16 => {
                    let px: Vec<[u16; 4]> =
                        pixels.iter().map(|p| p.map(|v| unit(v, 65535.0) as u16)).collect();
                    crate::io::png::write_rgba16(&path, w, h, &px)?
                }
                _ => crate::io::exr::write(&path, &crate::io::Image::from_pixels(w, h, pixels)?, &[])?,
            }
        }
        let text = serde_json::to_string_pretty(&manifest).map_err(|e| Error::Invalid(e.to_string()))?;
        crate::io::atomic::write_bytes(&tmp.join(MANIFEST), text.as_bytes())
    };
    if let Err(e) = fill() {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    if dir.exists() {
        std::fs::rename(dir, &old).map_err(|e| Error::file(dir, e))?;
    }
    std::fs::rename(&tmp, dir).map_err(|e| Error::file(dir, e))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// Premultiplied to straight colour (zero where alpha is).
fn straight(p: [f32; 4]) -> [f32; 4] {
    let a = p[3];
    if a > 0.0 {
        [p[0] / a, p[1] / a, p[2] / a, a]
    } else {
        [0.0; 4]
    }
}

/// Reads the stack `dir`: by its manifest when it has one, else the 8-bit PNG slices
/// `slice_000.png` onwards, consecutive, all of one size.
pub(crate) fn read(dir: &Path) -> Result<SliceStack> {
    if !dir.is_dir() {
        return Err(Error::file(
            dir,
            "expected a folder of slice images (slice_000.png, ...) written by `voltex bake`",
        ));
    }
    let manifest_path = dir.join(MANIFEST);
    if std::fs::symlink_metadata(&manifest_path).is_ok() {
        let text = crate::input::read_text(&manifest_path, "a slice-stack manifest")?;
        let manifest: Manifest = serde_json::from_str(&text).map_err(|e| {
            Error::at(crate::error::FileLoc::new(&manifest_path, e.line(), e.column()), e.to_string())
        })?;
        check_manifest(&manifest).map_err(|e| Error::file(&manifest_path, e))?;
        let paths: Vec<PathBuf> = manifest.slices.iter().map(|s| dir.join(s)).collect();
        let [w, h, _] = manifest.resolution;
        let mut stack = read_slices(&paths, Some((w, h, manifest.bit_depth)))?;
        if !manifest.premultiplied {
            for p in stack.texels.chunks_exact_mut(4) {
                let a = p[3] as u32;
                for c in &mut p[..3] {
                    *c = ((*c as u32 * a + 32767) / 65535) as u16;
                }
            }
        }
        stack.manifest = Some(manifest);
        return Ok(stack);
    }
    // Any entry named like a slice is read, so a FIFO or folder there is an error, not the end.
    let mut paths = Vec::new();
    while std::fs::symlink_metadata(dir.join(slice_name(paths.len() as u32, "png"))).is_ok() {
        if paths.len() as u32 >= MAX_SLICES {
            return Err(Error::file(
                dir.join(slice_name(MAX_SLICES, "png")),
                format!("expected at most {MAX_SLICES} slices (a texel's resolution)"),
            ));
        }
        paths.push(dir.join(slice_name(paths.len() as u32, "png")));
    }
    if paths.is_empty() {
        return Err(Error::file(
            dir,
            format!(
                "expected slice images slice_000.png, slice_001.png, ... (or a {MANIFEST}) in this folder"
            ),
        ));
    }
    read_slices(&paths, None)
}

/// What is wrong with a manifest, said in a sentence.
fn check_manifest(m: &Manifest) -> std::result::Result<(), String> {
    if m.format != FORMAT {
        return Err(format!("format {:?}: expected {FORMAT:?}", m.format));
    }
    if m.resolution.iter().any(|&r| r == 0 || r > MAX_SLICES) {
        return Err(format!("resolution {:?}: expected 1 to {MAX_SLICES} per axis", m.resolution));
    }
    let ext = match m.bit_depth {
        8 | 16 => "png",
        32 => "exr",
        d => return Err(format!("bit_depth {d}: expected 8 or 16 (PNG) or 32 (EXR)")),
    };
    if !(m.opacity_length.is_finite() && m.opacity_length > 0.0) {
        return Err(format!("opacity_length {}: expected a positive world length", m.opacity_length));
    }
    if !m.bounds.iter().flatten().all(|v| v.is_finite()) || (0..3).any(|a| m.bounds[0][a] >= m.bounds[1][a]) {
        return Err(format!("bounds {:?}: expected [lo, hi] with lo < hi on every axis", m.bounds));
    }
    if m.slices.len() != m.resolution[2] as usize {
        return Err(format!(
            "{} slices listed: expected one per w voxel, {}",
            m.slices.len(),
            m.resolution[2]
        ));
    }
    for s in &m.slices {
        let plain = Path::new(s).file_name().is_some_and(|n| n == s.as_str()) && !s.starts_with('.');
        if !plain || !s.to_ascii_lowercase().ends_with(&format!(".{ext}")) {
            return Err(format!("slice {s:?}: expected a .{ext} file name in the stack's folder"));
        }
    }
    Ok(())
}

/// Reads the slice images `paths` (w = 0 first), all of one size: `expect` gives the size and
/// bit depth a manifest promised.
fn read_slices(paths: &[PathBuf], expect: Option<(u32, u32, u32)>) -> Result<SliceStack> {
    let mut texels = Vec::new();
    let mut size = expect.map(|(w, h, _)| (w, h));
    for path in paths {
        let exr = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let (w, h, depth, pixels) = if exr {
            let (img, _) = crate::io::exr::read(path)?;
            if let Some(i) = img.pixels.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
                let (x, y) = (i as u32 % img.width, i as u32 / img.width);
                return Err(Error::file(path, format!("pixel ({x}, {y}) is not finite")));
            }
            let px =
                img.pixels.iter().map(|p| p.map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16)).collect();
            (img.width, img.height, 32, px)
        } else {
            let (w, h, depth, px) = crate::io::png::read_rgba16(path)?;
            (w, h, depth as u32, px)
        };
        if w > MAX_SLICES || h > MAX_SLICES {
            return Err(Error::file(
                path,
                format!(
                    "expected at most {MAX_SLICES}x{MAX_SLICES} pixels (a texel's resolution), got {w}x{h}"
                ),
            ));
        }
        if let Some((_, _, d)) = expect.filter(|&(_, _, d)| d != depth) {
            return Err(Error::file(
                path,
                format!("expected a {d}-bit slice as the manifest says, got {depth} bits"),
            ));
        }
        match size {
            None => size = Some((w, h)),
            Some(s) if s != (w, h) => {
                let like = if expect.is_some() { "as the manifest says" } else { "like slice_000.png" };
                return Err(Error::file(path, format!("expected {}x{} {like}, got {w}x{h}", s.0, s.1)));
            }
            _ => {}
        }
        for y in (0..h).rev() {
            texels.extend(pixels[(y * w) as usize..][..w as usize].iter().flatten());
        }
    }
    let (w, h) = size.unwrap_or((0, 0));
    Ok(SliceStack { resolution: [w, h, paths.len() as u32], texels, manifest: None })
}

#[cfg(test)]
mod tests;
