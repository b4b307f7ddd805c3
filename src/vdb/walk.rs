//! A structural walk of an OpenVDB file (format 222 and later: OpenVDB 3 to 12) before `vdb-rs`
//! reads it. vdb-rs trusts the file: a length field sizes an allocation before anything checks
//! it, several asserts and `todo!`s panic, unknown transforms panic, and a corrupt Blosc header
//! sends C code past the end of its buffer. The walk visits every field vdb-rs will read, checks
//! each length against the bytes that remain, and so lets through only files vdb-rs can read
//! safely. It also collects what vdb-rs drops: the background value, root tiles, every linear
//! transform, and where the stream must be patched for vdb-rs (`Splice`).

use glam::{DMat4, DVec3, IVec3};

/// OpenVDB's magic number, as the first eight bytes (little-endian).
const MAGIC: u64 = 0x5644_4220;
/// File format versions read: node-mask compression (222) onwards.
pub(crate) const MIN_VERSION: u32 = 222;
/// Per-grid compression flags.
const ZIP: u32 = 1;
const ACTIVE_MASK: u32 = 2;
const BLOSC: u32 = 4;

/// What a failed walk says, positioned by byte offset.
pub(crate) type Fault = String;

/// The archive: its grids in file order (the format version is checked while reading).
#[derive(Debug, Clone)]
pub(crate) struct Archive {
    pub(crate) grids: Vec<GridHeader>,
}

/// A grid's descriptor and metadata.
#[derive(Debug, Clone)]
pub(crate) struct GridHeader {
    pub(crate) name: String,
    /// The tree type as stored (`Tree_float_5_4_3`, maybe with `_HalfFloat`).
    pub(crate) type_name: String,
    pub(crate) instance_parent: String,
    pub(crate) grid_pos: u64,
    pub(crate) block_pos: u64,
    pub(crate) end_pos: u64,
    pub(crate) compression: u32,
    /// Metadata `class`: `level set`, `fog volume`, ... (empty when absent).
    pub(crate) class: String,
    pub(crate) half: bool,
}

/// The value types voltex reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Value {
    Float,
    Vec3,
}

impl GridHeader {
    /// The value type, or `None` for one voltex does not read (its name is `value_name`).
    pub(crate) fn value(&self) -> Option<Value> {
        match self.value_name() {
            "float" => Some(Value::Float),
            "vec3s" => Some(Value::Vec3),
            _ => None,
        }
    }

    /// The value type as OpenVDB names it (`float`, `vec3s`, `int32`, `bool`, `ptdataidx32`, ...).
    pub(crate) fn value_name(&self) -> &str {
        let t = self.type_name.strip_suffix("_HalfFloat").unwrap_or(&self.type_name);
        let t = t.strip_prefix("Tree_").unwrap_or(t);
        t.strip_suffix("_5_4_3").unwrap_or(t)
    }

    fn components(&self) -> usize {
        if self.value() == Some(Value::Vec3) {
            3
        } else {
            1
        }
    }
}

/// A stretch of the file replaced for vdb-rs: bytes `start..end` read as `bytes`.
#[derive(Debug, Clone)]
pub(crate) struct Splice {
    pub(crate) start: u64,
    pub(crate) end: u64,
    pub(crate) bytes: Vec<u8>,
}

/// One grid's tree as walked: its transform, background and active root tiles.
#[derive(Debug, Clone)]
pub(crate) struct Topology {
    /// The map's name, e.g. `ScaleTranslateMap`.
    pub(crate) map: String,
    /// Index space to world space.
    pub(crate) index_to_world: DMat4,
    /// The background (first component of a vector).
    pub(crate) background: f32,
    /// Root tiles (origin, value's first component, active).
    pub(crate) root_tiles: Vec<(IVec3, f32, bool)>,
    /// Where the stream differs for vdb-rs, in file order.
    pub(crate) splices: Vec<Splice>,
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], Fault> {
        let left = (self.bytes.len() - self.at) as u64;
        if n > left {
            return Err(format!(
                "at byte {}: {what} needs {n} bytes, but the file ends {left} bytes later (truncated?)",
                self.at
            ));
        }
        let s = &self.bytes[self.at..self.at + n as usize];
        self.at += n as usize;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, Fault> {
        Ok(self.take(1, what)?[0])
    }
    fn u32(&mut self, what: &str) -> Result<u32, Fault> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }
    fn i32(&mut self, what: &str) -> Result<i32, Fault> {
        Ok(self.u32(what)? as i32)
    }
    fn u64(&mut self, what: &str) -> Result<u64, Fault> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }
    fn f64(&mut self, what: &str) -> Result<f64, Fault> {
        Ok(f64::from_bits(self.u64(what)?))
    }
    fn vec3d(&mut self, what: &str) -> Result<DVec3, Fault> {
        Ok(DVec3::new(self.f64(what)?, self.f64(what)?, self.f64(what)?))
    }
    fn ivec3(&mut self, what: &str) -> Result<IVec3, Fault> {
        Ok(IVec3::new(self.i32(what)?, self.i32(what)?, self.i32(what)?))
    }
    fn string(&mut self, what: &str) -> Result<String, Fault> {
        let n = self.u32(what)?;
        let at = self.at;
        let s = self.take(n as u64, what)?;
        String::from_utf8(s.to_vec()).map_err(|_| format!("at byte {at}: {what} is not UTF-8 text"))
    }
    fn seek(&mut self, to: u64, what: &str) -> Result<(), Fault> {
        if to > self.bytes.len() as u64 {
            return Err(format!(
                "{what} at byte {to} lies beyond the end of the file ({} bytes): truncated?",
                self.bytes.len()
            ));
        }
        self.at = to as usize;
        Ok(())
    }
}

/// Metadata as vdb-rs reads it: each known type must have its size (vdb-rs reads the value
/// without looking at the length). Returns the entries it needs: `class` and the half flag.
fn metadata(c: &mut Cursor) -> Result<(String, bool), Fault> {
    let count = c.u32("the metadata count")?;
    let (mut class, mut half) = (String::new(), false);
    for _ in 0..count {
        let at = c.at;
        let name = c.string("a metadata name")?;
        let kind = c.string("a metadata type")?;
        let len = c.u32("a metadata length")? as u64;
        let size = match kind.as_str() {
            "bool" => Some(1),
            "int32" | "float" => Some(4),
            "int64" => Some(8),
            "vec3i" => Some(12),
            _ => None,
        };
        if size.is_some_and(|s| s != len) {
            return Err(format!(
                "at byte {at}: metadata `{name}` of type {kind} has length {len}, expected {}",
                size.unwrap()
            ));
        }
        let value = c.take(len, "a metadata value")?;
        match name.as_str() {
            "class" if kind == "string" => class = String::from_utf8_lossy(value).into_owned(),
            "is_saved_as_half_float" if kind == "bool" => half = value[0] != 0,
            _ => {}
        }
    }
    Ok((class, half))
}

/// The archive header and every grid descriptor.
pub(crate) fn archive(bytes: &[u8]) -> Result<Archive, Fault> {
    let mut c = Cursor { bytes, at: 0 };
    if bytes.len() < 8 || c.u64("the magic number")? != MAGIC {
        return Err("not an OpenVDB file (its first bytes are not OpenVDB's magic number)".into());
    }
    let version = c.u32("the file version")?;
    if version < MIN_VERSION {
        return Err(format!(
            "OpenVDB file format {version}: voltex reads format {MIN_VERSION} and later (files written by OpenVDB 3 or newer)"
        ));
    }
    c.take(8, "the library version")?;
    if c.u8("the grid-offsets flag")? != 1 {
        return Err(
            "the file has no grid offsets (written as a stream): voltex reads files with offsets".into()
        );
    }
    c.take(36, "the file's UUID")?;
    metadata(&mut c)?;
    let count = c.u32("the grid count")?;
    let mut grids: Vec<GridHeader> = Vec::new();
    for _ in 0..count {
        let at = c.at;
        let name = c.string("a grid name")?;
        let type_name = c.string("a grid type")?;
        let instance_parent = c.string("a grid's instance parent")?;
        let grid_pos = c.u64("a grid position")?;
        let block_pos = c.u64("a grid's block position")?;
        let end_pos = c.u64("a grid's end position")?;
        if !(at as u64 <= grid_pos && grid_pos <= block_pos && block_pos <= end_pos) {
            return Err(format!(
                "at byte {at}: grid `{name}` has positions {grid_pos}, {block_pos}, {end_pos} out of order"
            ));
        }
        if grids.iter().any(|g| g.name == name) {
            return Err(format!("at byte {at}: a second grid named `{name}` (names must be unique)"));
        }
        c.seek(grid_pos, &format!("grid `{name}`"))?;
        let compression = c.u32("a grid's compression flags")?;
        if compression & !(ZIP | ACTIVE_MASK | BLOSC) != 0 {
            return Err(format!("grid `{name}`: unknown compression flags {compression:#x}"));
        }
        let (class, half) = metadata(&mut c)?;
        grids.push(GridHeader {
            name,
            type_name,
            instance_parent,
            grid_pos,
            block_pos,
            end_pos,
            compression,
            class,
            half,
        });
        c.seek(end_pos, "the next grid descriptor")?;
    }
    Ok(Archive { grids })
}

/// The identity `UniformScaleMap` in the stream: what vdb-rs reads in place of maps it does not
/// know (voltex uses the map it read itself).
fn identity_map() -> Vec<u8> {
    let mut out = Vec::new();
    let name = b"UniformScaleMap";
    out.extend_from_slice(&(name.len() as u32).to_le_bytes());
    out.extend_from_slice(name);
    for _ in 0..15 {
        out.extend_from_slice(&1f64.to_le_bytes());
    }
    out
}

/// The grid's transform: the map's name and its index-to-world matrix (OpenVDB maps row vectors:
/// `world = (i, j, k, 1) M`).
fn transform(c: &mut Cursor, splices: &mut Vec<Splice>) -> Result<(String, DMat4), Fault> {
    let start = c.at as u64;
    let map = c.string("the transform's map name")?;
    let scale_translate = |c: &mut Cursor, translated: bool| -> Result<DMat4, Fault> {
        let t = if translated { c.vec3d("a translation")? } else { DVec3::ZERO };
        let s = c.vec3d("a scale")?;
        c.take(4 * 24, "the map's derived values")?;
        Ok(DMat4::from_translation(t) * DMat4::from_scale(s))
    };
    let m = match map.as_str() {
        "UniformScaleMap" | "ScaleMap" => scale_translate(c, false)?,
        "UniformScaleTranslateMap" | "ScaleTranslateMap" => scale_translate(c, true)?,
        "TranslationMap" => DMat4::from_translation(c.vec3d("a translation")?),
        "AffineMap" | "UnitaryMap" => {
            let mut a = [0.0; 16];
            for v in &mut a {
                *v = c.f64("a matrix entry")?;
            }
            // Stored row by row for row vectors: its rows are glam's columns.
            DMat4::from_cols_array(&a)
        }
        other => {
            return Err(format!(
                "the transform is a {other}: voltex reads linear transforms (ScaleMap, ScaleTranslateMap, \
                 TranslationMap, AffineMap, UnitaryMap and their uniform forms)"
            ))
        }
    };
    if !matches!(map.as_str(), "UniformScaleMap" | "UniformScaleTranslateMap" | "ScaleTranslateMap") {
        splices.push(Splice { start, end: c.at as u64, bytes: identity_map() });
    }
    Ok((map, m))
}

fn ones(mask: &[u8]) -> u64 {
    mask.iter().map(|b| b.count_ones() as u64).sum()
}

/// What one grid's values look like in the stream.
struct Values {
    compression: u32,
    /// Bytes of one value in data chunks (halves when saved as half) and in full.
    chunk: u64,
    full: u64,
    /// Saved as half floats.
    half: bool,
    /// A vector saved as half: inactive values are written in full but read by vdb-rs as halves.
    narrow_inactive: bool,
}

/// One compressed value array (`readCompressedValues`) of `count` values, `active` of them on.
fn chunk(
    c: &mut Cursor,
    v: &Values,
    count: u64,
    active: u64,
    splices: &mut Vec<Splice>,
) -> Result<(), Fault> {
    let at = c.at;
    let meta = c.u8("a node's compression metadata")?;
    if meta > 6 {
        return Err(format!("at byte {at}: node compression metadata {meta} (expected 0 to 6)"));
    }
    let inactive = match meta {
        2 | 4 => 1,
        5 => 2,
        _ => 0,
    };
    for _ in 0..inactive {
        let start = c.at as u64;
        let value = c.take(v.full, "an inactive value")?;
        if v.narrow_inactive {
            let halves: Vec<u8> = value
                .chunks_exact(4)
                .flat_map(|f| half::f16::from_f32(f32::from_le_bytes(f.try_into().unwrap())).to_le_bytes())
                .collect();
            splices.push(Splice { start, end: c.at as u64, bytes: halves });
        }
    }
    if (3..=5).contains(&meta) {
        c.take(count.div_ceil(64) * 8, "a selection mask")?;
    }
    let n = if v.compression & ACTIVE_MASK != 0 && meta != 6 { active } else { count };
    let bytes = n * v.chunk;
    let at = c.at;
    if v.half && n == 0 {
        // OpenVDB writes no half values at all for none, where vdb-rs reads a size first.
        if v.compression & (BLOSC | ZIP) != 0 {
            splices.push(Splice { start: at as u64, end: at as u64, bytes: 0i64.to_le_bytes().to_vec() });
        }
        return Ok(());
    }
    if v.compression & (BLOSC | ZIP) != 0 {
        let size = c.u64("a compressed size")? as i64;
        if size <= 0 {
            if size.unsigned_abs() != bytes {
                return Err(format!(
                    "at byte {at}: {} uncompressed bytes where {bytes} were expected",
                    -size
                ));
            }
            c.take(bytes, "uncompressed values")?;
        } else {
            let data = c.take(size as u64, "compressed values")?;
            if v.compression & BLOSC != 0 && n > 0 {
                // Blosc's header: nbytes at 4, cbytes at 12; both must agree with the file.
                let word =
                    |i: usize| data.get(i..i + 4).map(|w| u32::from_le_bytes(w.try_into().unwrap()) as u64);
                let (nbytes, cbytes) = (word(4), word(12));
                if data.len() < 16 || cbytes != Some(size as u64) || nbytes != Some(bytes) {
                    return Err(format!(
                        "at byte {at}: a Blosc block whose header disagrees with the file ({size} bytes holding {bytes})"
                    ));
                }
            }
        }
    } else {
        c.take(bytes, "values")?;
    }
    Ok(())
}

/// Most values (voxels, tiles and node tables) a grid may hold once read: 2^26, 256 MiB of floats.
pub(crate) const MAX_VALUES: u64 = 1 << 26;

/// Walks grid `g`'s transform, tree topology and leaf data.
pub(crate) fn topology(bytes: &[u8], g: &GridHeader) -> Result<Topology, Fault> {
    let mut c = Cursor { bytes, at: 0 };
    let mut splices = Vec::new();
    c.seek(g.grid_pos, "the grid")?;
    c.take(4, "the compression flags")?;
    metadata(&mut c)?;
    let (map, index_to_world) = transform(&mut c, &mut splices)?;
    let half = g.half || g.type_name.ends_with("_HalfFloat");
    let comps = g.components() as u64;
    let v = Values {
        compression: g.compression,
        chunk: comps * if half { 2 } else { 4 },
        full: comps * 4,
        half,
        narrow_inactive: half && comps == 3,
    };
    if c.u32("the buffer count")? != 1 {
        return Err("a multi-buffer tree: voltex reads trees of one buffer".into());
    }
    // vdb-rs reads the background and root tiles' values as one float: a vector's are narrowed.
    let narrowed = |c: &mut Cursor, what: &str, splices: &mut Vec<Splice>| -> Result<f32, Fault> {
        let start = c.at as u64;
        let value = c.take(v.full, what)?;
        if comps > 1 {
            splices.push(Splice { start, end: c.at as u64, bytes: value[..4].to_vec() });
        }
        Ok(f32::from_le_bytes(value[..4].try_into().unwrap()))
    };
    let background = narrowed(&mut c, "the background value", &mut splices)?;
    let tiles = c.u32("the root tile count")?;
    let roots = c.u32("the root child count")?;
    let mut root_tiles = Vec::new();
    for _ in 0..tiles {
        let origin = c.ivec3("a root tile's origin")?;
        let value = narrowed(&mut c, "a root tile's value", &mut splices)?;
        let active = c.u8("a root tile's state")? != 0;
        root_tiles.push((origin, value, active));
    }
    let mut nodes = [0u64; 3];
    let mut values = 0u64;
    let over = |values: u64| {
        (values > MAX_VALUES).then(|| {
            format!(
                "the tree holds more than {MAX_VALUES} values (voxels, tiles and node tables): too large to read \
                 (voltex reads grids of at most {} active leaves)",
                MAX_VALUES / 512
            )
        })
    };
    for _ in 0..roots {
        c.ivec3("a root child's origin")?;
        let child5 = c.take(4096, "a node's child mask")?;
        let value5 = c.take(4096, "a node's value mask")?;
        chunk(&mut c, &v, 32768, ones(value5), &mut splices)?;
        nodes[0] += 1;
        values += 32768;
        for _ in 0..ones(child5) {
            let child4 = c.take(512, "a node's child mask")?;
            let value4 = c.take(512, "a node's value mask")?;
            chunk(&mut c, &v, 4096, ones(value4), &mut splices)?;
            nodes[1] += 1;
            values += 4096;
            let n = ones(child4);
            for _ in 0..n {
                c.take(64, "a leaf's value mask")?;
            }
            nodes[2] += n;
            values += 512 * n;
            if let Some(e) = over(values) {
                return Err(e);
            }
        }
    }
    if c.at as u64 > g.block_pos {
        return Err(format!("the tree's topology runs past the grid's data at byte {}", g.block_pos));
    }
    c.seek(g.block_pos, "the grid's data")?;
    for _ in 0..nodes[2] {
        let mask = c.take(64, "a leaf's value mask")?;
        chunk(&mut c, &v, 512, ones(mask), &mut splices)?;
    }
    if c.at as u64 > g.end_pos {
        return Err(format!("the grid's data runs past its end at byte {}", g.end_pos));
    }
    Ok(Topology { map, index_to_world, background, root_tiles, splices })
}
