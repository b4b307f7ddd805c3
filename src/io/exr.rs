//! OpenEXR: one RGBA f32 layer plus free-text metadata (method, quality knobs, adapter, GPU time)
//! as custom string attributes; optionally more channels (AOVs: `Z`, `coverage.OBJECT.Y`, ...)
//! and the standard camera attributes.

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
    write_with(path, image, metadata, &Extras::default())
}

/// What an EXR may carry beside the colour and the string metadata.
#[derive(Debug, Default)]
pub struct Extras<'a> {
    /// More f32 channels, one sample per pixel, row-major from the top row (AOVs).
    pub channels: &'a [(String, Vec<f32>)],
    /// The standard `worldToCamera`, `worldToNDC`, `nearClipPlane` and `farClipPlane`.
    pub camera: Option<CameraAttributes>,
    /// The standard `framesPerSecond` (a sequence's frames).
    pub fps: Option<f64>,
}

/// OpenEXR's camera attributes, matrices as Imath stores them (row vectors: `p * M`, the
/// translation in the last row). Camera space is left-handed: x right, y up, z the viewing
/// direction; NDC has (0, 0) at the top-left corner of the image and (1, 1) at the bottom-right.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraAttributes {
    pub(crate) world_to_camera: [f32; 16],
    pub(crate) world_to_ndc: [f32; 16],
    pub(crate) near: f32,
    pub(crate) far: f32,
}

/// Like [`write()`], with AOV channels and camera attributes. A channel name must be 1–255 Latin-1
/// bytes, not R, G, B or A, and appear once; each channel has one sample per pixel.
pub fn write_with(path: &Path, image: &Image, metadata: &[(&str, String)], extras: &Extras) -> Result<()> {
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
    if let Some(c) = extras.camera {
        attributes.world_to_camera = Some(c.world_to_camera);
        attributes.world_to_normalized_device = Some(c.world_to_ndc);
        attributes.near_clip_plane = Some(c.near);
        attributes.far_clip_plane = Some(c.far);
    }
    attributes.frames_per_second = extras.fps.filter(|f| f.is_finite() && *f > 0.0).map(rational);
    let size = (image.width as usize, image.height as usize);
    let encoding = x::Encoding::SMALL_LOSSLESS;
    if extras.channels.is_empty() {
        let width = image.width as usize;
        let channels = x::SpecificChannels::rgba(|pos: x::Vec2<usize>| {
            let p = image.pixels[pos.y() * width + pos.x()];
            (p[0], p[1], p[2], p[3])
        });
        let image = x::Image::from_layer(x::Layer::new(size, attributes, encoding, channels));
        write_atomic(path, |tmp| image.write().to_file(tmp).map_err(|e| cannot(path, e)))
    } else {
        let mut list = x::SmallVec::new();
        for (c, name) in ["R", "G", "B", "A"].iter().enumerate() {
            let plane = image.pixels.iter().map(|p| p[c]).collect();
            list.push(x::AnyChannel::new(*name, x::FlatSamples::F32(plane)));
        }
        let mut names: Vec<&str> = vec!["R", "G", "B", "A"];
        for (name, plane) in extras.channels {
            check_channel(name, &names)?;
            if plane.len() != image.pixels.len() {
                return Err(Error::Invalid(format!(
                    "EXR channel `{name}` has {} samples for {} pixels",
                    plane.len(),
                    image.pixels.len()
                )));
            }
            names.push(name);
            list.push(x::AnyChannel::new(to_text(name), x::FlatSamples::F32(plane.clone())));
        }
        let channels = x::AnyChannels::sort(list);
        let image = x::Image::from_layer(x::Layer::new(size, attributes, encoding, channels));
        write_atomic(path, |tmp| image.write().to_file(tmp).map_err(|e| cannot(path, e)))
    }
}

fn cannot(path: &Path, e: ::exr::error::Error) -> Error {
    Error::file(path, format!("cannot write EXR: {e}"))
}

/// A frame rate as the rational EXR stores (exact for whole rates, else to a thousandth).
fn rational(fps: f64) -> (i32, u32) {
    if fps.fract() == 0.0 && fps <= i32::MAX as f64 {
        (fps as i32, 1)
    } else {
        ((fps * 1000.0).round().min(i32::MAX as f64) as i32, 1000)
    }
}

/// An EXR channel name: 1–255 Latin-1 bytes without NUL, not one already written.
fn check_channel(name: &str, written: &[&str]) -> Result<()> {
    if name.is_empty() || name.len() > 255 || name.chars().any(|c| c as u32 > 0xff || c == '\0') {
        return Err(Error::Invalid(format!(
            "EXR channel name {name:?} must be 1 to 255 Latin-1 bytes without NUL"
        )));
    }
    if written.contains(&name) {
        return Err(Error::Invalid(format!("EXR channel `{name}` is written twice")));
    }
    Ok(())
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
pub(crate) type Channels = Vec<(String, Vec<f32>)>;

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
