//! Slice stacks: a baked texel volume written out as one RGBA PNG per `w` slice (`voltex bake`)
//! and read back as a texel source (`Slices(dir: ..)`), so a bake can be inspected, edited in an
//! image editor, or shipped instead of its recipe.
//!
//! A stack is a folder holding `slice_000.png` (w = 0, the bottom) to `slice_NNN.png`, all of one
//! size, with the volume's stored bytes: 8-bit RGBA, colour premultiplied by alpha, rows from
//! t = 1 (the top row of the image) down to t = 0, as images are viewed.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::atomic::check_writable_dir;

/// A volume read from a stack: rgba8 texels, x fastest, then y (t = 0 first), then z.
#[derive(Debug, Clone, PartialEq)]
pub struct SliceStack {
    pub resolution: [u32; 3],
    pub texels: Vec<u8>,
}

fn slice_name(z: u32) -> String {
    format!("slice_{z:03}.png")
}

/// Writes `volume` (rgba8, x fastest, t = 0 first) of `resolution` as the stack `dir`. The
/// slices go to a fresh temporary folder beside `dir`, which then replaces `dir` as a whole:
/// an interrupted bake leaves the old stack (or none), never a mix of old and new slices.
pub fn write(dir: &Path, resolution: [u32; 3], volume: &[u8]) -> Result<()> {
    let [w, h, d] = resolution;
    let layer = (w * h * 4) as usize;
    if volume.len() != layer * d as usize {
        return Err(Error::Invalid(format!(
            "a {w}x{h}x{d} volume needs {} bytes, got {}",
            layer * d as usize,
            volume.len()
        )));
    }
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
            let pixels: Vec<[u8; 4]> = (0..h)
                .rev()
                .flat_map(|y| slice[(y * w * 4) as usize..][..(w * 4) as usize].chunks_exact(4))
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect();
            crate::io::png::write_rgba8(&tmp.join(slice_name(z)), w, h, &pixels)?;
        }
        Ok(())
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

/// Most slices, and pixels per side, in a stack: a texel's largest resolution.
const MAX_SLICES: u32 = 1024;

/// Reads the stack `dir`: slices `slice_000.png` onwards, consecutive, all of one size.
pub fn read(dir: &Path) -> Result<SliceStack> {
    if !dir.is_dir() {
        return Err(Error::file(
            dir,
            "expected a folder of slice images (slice_000.png, ...) written by `voltex bake`",
        ));
    }
    let mut texels = Vec::new();
    let mut size = None;
    let mut d = 0;
    // Any entry named like a slice is read, so a FIFO or folder there is an error, not the end.
    while std::fs::symlink_metadata(dir.join(slice_name(d))).is_ok() {
        let path = dir.join(slice_name(d));
        if d >= MAX_SLICES {
            return Err(Error::file(
                &path,
                format!("expected at most {MAX_SLICES} slices (a texel's resolution)"),
            ));
        }
        let (w, h, pixels) = crate::io::png::read_rgba8(&path)?;
        if w > MAX_SLICES || h > MAX_SLICES {
            return Err(Error::file(
                &path,
                format!(
                    "expected at most {MAX_SLICES}x{MAX_SLICES} pixels (a texel's resolution), got {w}x{h}"
                ),
            ));
        }
        match size {
            None => size = Some((w, h)),
            Some(s) if s != (w, h) => {
                return Err(Error::file(
                    &path,
                    format!("expected {}x{} like slice_000.png, got {w}x{h}", s.0, s.1),
                ))
            }
            _ => {}
        }
        for y in (0..h).rev() {
            texels.extend(pixels[(y * w) as usize..][..w as usize].iter().flatten());
        }
        d += 1;
    }
    let Some((w, h)) = size else {
        return Err(Error::file(
            dir,
            "expected slice images slice_000.png, slice_001.png, ... in this folder",
        ));
    };
    Ok(SliceStack { resolution: [w, h, d], texels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stack_reads_back_what_was_written() {
        let dir = std::env::temp_dir().join(format!("voltex-stack-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let res = [5, 3, 4];
        let volume: Vec<u8> = (0..5 * 3 * 4 * 4).map(|i| (i * 7 % 256) as u8).collect();
        write(&dir, res, &volume).unwrap();
        assert_eq!(read(&dir).unwrap(), SliceStack { resolution: res, texels: volume.clone() });
        // Rewriting a smaller stack replaces the folder as a whole: no stale slice remains.
        write(&dir, [5, 3, 2], &volume[..5 * 3 * 2 * 4]).unwrap();
        assert_eq!(read(&dir).unwrap().resolution, [5, 3, 2]);
        // A slice of another size is an error naming it.
        let other = vec![[0u8; 4]; 4];
        crate::io::png::write_rgba8(&dir.join("slice_002.png"), 2, 2, &other).unwrap();
        let e = read(&dir).unwrap_err().to_string();
        assert!(e.contains("slice_002.png") && e.contains("expected 5x3"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(read(&dir).unwrap_err().to_string().contains("expected a folder"));
    }
}
