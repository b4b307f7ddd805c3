//! OpenEXR: one RGBA f32 layer plus free-text metadata (method, quality knobs, adapter, GPU time)
//! as custom string attributes.

use std::path::Path;

use ::exr::meta::attribute::{AttributeValue, Text};
use ::exr::meta::header::{standard_names, LayerAttributes};
use ::exr::prelude as x;
use ::exr::prelude::{ReadChannels, ReadLayers, WritableImage};

use super::atomic::write_atomic;
use super::Image;
use crate::{Error, Result};

/// Turns a string into EXR text (Latin-1); other characters become `?`.
fn to_text(s: &str) -> Text {
    let bytes = s.chars().map(|c| u8::try_from(c as u32).unwrap_or(b'?')).collect();
    Text::from_bytes_unchecked(bytes)
}

/// Checks a metadata key: EXR attribute names are 1–255 Latin-1 bytes, and must not shadow a
/// standard attribute (`owner`, `comments`, …), which readers would parse as that attribute.
fn check_key(key: &str) -> Result<Text> {
    if key.is_empty() || key.len() > 255 {
        return Err(Error::Invalid(format!("EXR metadata key {key:?} must be 1 to 255 bytes long")));
    }
    let text = Text::new_or_none(key)
        .ok_or_else(|| Error::Invalid(format!("EXR metadata key {key:?} has characters outside Latin-1")))?;
    if text.as_slice().contains(&0) {
        return Err(Error::Invalid(format!("EXR metadata key {key:?} contains NUL")));
    }
    if standard_names::ALL.contains(&text.as_slice()) {
        return Err(Error::Invalid(format!(
            "EXR metadata key {key:?} is a standard EXR attribute name; pick another"
        )));
    }
    Ok(text)
}

/// Writes `image` to `path` atomically as a scan-line EXR with R, G, B, A f32 channels (ZIP
/// compression, lossless) and each `(key, value)` of `metadata` as a string attribute.
/// Keys are free text but must be 1–255 Latin-1 characters and not a standard EXR attribute
/// name; values may be anything (characters outside Latin-1 are stored as `?`).
pub fn write(path: &Path, image: &Image, metadata: &[(&str, String)]) -> Result<()> {
    if image.pixels.len() != image.width as usize * image.height as usize {
        return Err(Error::Invalid(format!(
            "image {}x{} has {} pixels",
            image.width,
            image.height,
            image.pixels.len()
        )));
    }
    if image.is_empty() {
        return Err(Error::file(path, "cannot write an empty (0-pixel) EXR image"));
    }
    let mut attributes =
        LayerAttributes { software_name: Some(to_text("voltex")), ..LayerAttributes::default() };
    for (key, value) in metadata {
        attributes.other.insert(check_key(key)?, AttributeValue::Text(to_text(value)));
    }
    let width = image.width as usize;
    let channels = x::SpecificChannels::rgba(|pos: x::Vec2<usize>| {
        let p = image.pixels[pos.y() * width + pos.x()];
        (p[0], p[1], p[2], p[3])
    });
    let layer = x::Layer::new(
        (image.width as usize, image.height as usize),
        attributes,
        x::Encoding::SMALL_LOSSLESS,
        channels,
    );
    let exr_image = x::Image::from_layer(layer);
    write_atomic(path, |tmp| {
        exr_image.write().to_file(tmp).map_err(|e| Error::file(path, format!("cannot write EXR: {e}")))
    })
}

/// Reads the first layer with R, G, B channels of an EXR file (A is optional and defaults to 1),
/// converting samples to f32, and its string attributes sorted by key. Attributes of other types
/// are skipped. Errors (missing file, not an EXR, no RGB layer) are [`Error::File`].
pub fn read(path: &Path) -> Result<(Image, Vec<(String, String)>)> {
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "an EXR image")?;
    let exr_image = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| Image::new(size.width() as u32, size.height() as u32),
            |img: &mut Image, pos: x::Vec2<usize>, (r, g, b, a): (f32, f32, f32, f32)| {
                let i = pos.y() * img.width as usize + pos.x();
                img.pixels[i] = [r, g, b, a];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::file(path, format!("cannot read as an EXR image with R, G, B channels: {e}")))?;
    let mut metadata: Vec<(String, String)> = exr_image
        .attributes
        .other
        .iter()
        .chain(exr_image.layer_data.attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((latin1(k), latin1(t))),
            _ => None,
        })
        .collect();
    metadata.sort();
    Ok((exr_image.layer_data.channel_data.pixels, metadata))
}

/// Named planes of f32 samples, row-major from the top row.
pub type Channels = Vec<(String, Vec<f32>)>;

/// The first layer's channels of any EXR (any names, f16/f32/u32 samples) as f32 planes in the
/// order R, G, B, A where present, then the others in the file's (alphabetical) order:
/// `(width, height, channels)`.
pub fn read_channels(path: &Path) -> Result<(usize, usize, Channels)> {
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "an EXR image")?;
    let image = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::file(path, format!("cannot read as an EXR image: {e}")))?;
    let size = image.layer_data.size;
    let mut channels: Channels = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| (latin1(&c.name), c.sample_data.values_as_f32().collect()))
        .collect();
    let rank = |n: &str| ["R", "G", "B", "A"].iter().position(|c| *c == n).unwrap_or(4);
    channels.sort_by_key(|(n, _)| rank(n));
    Ok((size.width(), size.height(), channels))
}

/// EXR text bytes are Latin-1; decode them so that `é` survives a round trip.
fn latin1(t: &Text) -> String {
    t.as_slice().iter().map(|&b| b as char).collect()
}
