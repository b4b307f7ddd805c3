//! PNG: 8-bit sRGB previews of HDR images (tonemapped), plain RGBA8 images (heat maps), and
//! 8- or 16-bit RGBA data images (slice stacks) read and written at their full depth.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::atomic::write_atomic;
use super::Image;
use crate::{Error, Result};

/// Writes `image` tonemapped with `super::tonemap` as an 8-bit sRGB PNG, atomically. Alpha is
/// dropped (the PNG is opaque): it is a preview of the colour; alpha stays in the EXR.
pub fn write_tonemapped(path: &Path, image: &Image) -> Result<()> {
    let mut rgba = image.to_srgb8();
    for p in &mut rgba {
        p[3] = 255;
    }
    write_png(path, image.width, image.height, &rgba, false)
}

/// Writes 8-bit RGBA pixels (row-major, top row first; already sRGB-encoded) atomically.
pub fn write_rgba8(path: &Path, width: u32, height: u32, pixels: &[[u8; 4]]) -> Result<()> {
    write_png(path, width, height, pixels, true)
}

fn write_png(path: &Path, width: u32, height: u32, pixels: &[[u8; 4]], alpha: bool) -> Result<()> {
    if pixels.len() != width as usize * height as usize {
        return Err(Error::Invalid(format!(
            "PNG {width}x{height} needs {} pixels, got {}",
            width as usize * height as usize,
            pixels.len()
        )));
    }
    if width == 0 || height == 0 {
        return Err(Error::file(path, "cannot write an empty (0-pixel) PNG"));
    }
    let data: Vec<u8> = if alpha {
        pixels.iter().flatten().copied().collect()
    } else {
        pixels.iter().flat_map(|p| [p[0], p[1], p[2]]).collect()
    };
    let err = |e: &dyn std::fmt::Display| Error::file(path, format!("cannot write PNG: {e}"));
    write_atomic(path, |tmp| {
        let file = File::create(tmp).map_err(|e| err(&e))?;
        let mut out = BufWriter::new(file);
        let mut encoder = ::png::Encoder::new(&mut out, width, height);
        encoder.set_color(if alpha { ::png::ColorType::Rgba } else { ::png::ColorType::Rgb });
        encoder.set_depth(::png::BitDepth::Eight);
        encoder.set_source_srgb(::png::SrgbRenderingIntent::Perceptual);
        let mut writer = encoder.write_header().map_err(|e| err(&e))?;
        writer.write_image_data(&data).map_err(|e| err(&e))?;
        writer.finish().map_err(|e| err(&e))?;
        out.flush().map_err(|e| err(&e))
    })
}

/// Reads any PNG as 8-bit RGBA (grey, palette and 16-bit are converted; missing alpha is 255).
/// Returns `(width, height, pixels)`, row-major, top row first.
pub fn read_rgba8(path: &Path) -> Result<(u32, u32, Vec<[u8; 4]>)> {
    let err = |e: &dyn std::fmt::Display| Error::file(path, format!("cannot read PNG: {e}"));
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "a PNG image")?;
    let mut decoder = ::png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(::png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| err(&e))?;
    let size = reader.output_buffer_size().ok_or_else(|| err(&"image too large"))?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(|e| err(&e))?;
    let buf = &buf[..info.buffer_size()];
    let (w, h) = (info.width, info.height);
    use ::png::ColorType as C;
    let pixels: Vec<[u8; 4]> = match info.color_type {
        C::Rgba => buf.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
        C::Rgb => buf.chunks_exact(3).map(|c| [c[0], c[1], c[2], 255]).collect(),
        C::GrayscaleAlpha => buf.chunks_exact(2).map(|c| [c[0], c[0], c[0], c[1]]).collect(),
        C::Grayscale => buf.iter().map(|&g| [g, g, g, 255]).collect(),
        C::Indexed => return Err(err(&"palette was not expanded")),
    };
    if pixels.len() != w as usize * h as usize {
        return Err(err(&"decoded size does not match the header"));
    }
    Ok((w, h, pixels))
}

/// Writes 16-bit RGBA pixels (row-major, top row first; linear data, no colour space) atomically.
pub fn write_rgba16(path: &Path, width: u32, height: u32, pixels: &[[u16; 4]]) -> Result<()> {
    if pixels.len() != width as usize * height as usize || width == 0 || height == 0 {
        return Err(Error::file(
            path,
            format!("cannot write a {width}x{height} PNG of {} pixels", pixels.len()),
        ));
    }
    let data: Vec<u8> = pixels.iter().flatten().flat_map(|v| v.to_be_bytes()).collect();
    let err = |e: &dyn std::fmt::Display| Error::file(path, format!("cannot write PNG: {e}"));
    write_atomic(path, |tmp| {
        let file = File::create(tmp).map_err(|e| err(&e))?;
        let mut out = BufWriter::new(file);
        let mut encoder = ::png::Encoder::new(&mut out, width, height);
        encoder.set_color(::png::ColorType::Rgba);
        encoder.set_depth(::png::BitDepth::Sixteen);
        let mut writer = encoder.write_header().map_err(|e| err(&e))?;
        writer.write_image_data(&data).map_err(|e| err(&e))?;
        writer.finish().map_err(|e| err(&e))?;
        out.flush().map_err(|e| err(&e))
    })
}

/// Reads any PNG as 16-bit RGBA at its own precision (8-bit samples `v` become `v * 257`, so
/// they convert back exactly; grey and palette expand; missing alpha is opaque), and its bit
/// depth (8 or 16; lower depths count as 8). Returns `(width, height, depth, pixels)`.
pub(crate) fn read_rgba16(path: &Path) -> Result<(u32, u32, u8, Vec<[u16; 4]>)> {
    let err = |e: &dyn std::fmt::Display| Error::file(path, format!("cannot read PNG: {e}"));
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "a PNG image")?;
    let mut decoder = ::png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(::png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| err(&e))?;
    let size = reader.output_buffer_size().ok_or_else(|| err(&"image too large"))?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(|e| err(&e))?;
    let (w, h) = (info.width, info.height);
    let deep = info.bit_depth == ::png::BitDepth::Sixteen;
    let samples: Vec<u16> = match deep {
        true => buf[..info.buffer_size()].chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect(),
        false => buf[..info.buffer_size()].iter().map(|&b| b as u16 * 257).collect(),
    };
    use ::png::ColorType as C;
    let pixels: Vec<[u16; 4]> = match info.color_type {
        C::Rgba => samples.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
        C::Rgb => samples.chunks_exact(3).map(|c| [c[0], c[1], c[2], u16::MAX]).collect(),
        C::GrayscaleAlpha => samples.chunks_exact(2).map(|c| [c[0], c[0], c[0], c[1]]).collect(),
        C::Grayscale => samples.iter().map(|&g| [g, g, g, u16::MAX]).collect(),
        C::Indexed => return Err(err(&"palette was not expanded")),
    };
    if pixels.len() != w as usize * h as usize {
        return Err(err(&"decoded size does not match the header"));
    }
    Ok((w, h, if deep { 16 } else { 8 }, pixels))
}
