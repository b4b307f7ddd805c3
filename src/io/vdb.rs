//! OpenVDB writer: float and vec3 grids in the standard 5-4-3 tree (file format 224, what
//! OpenVDB 12 writes and reads), sparse (only leaves holding an active voxel are stored),
//! uncompressed or zip, each grid with its index-to-world transform. No Rust crate writes VDB;
//! the layout follows OpenVDB's `io/Archive.cc`, `tree/RootNode.h`, `tree/InternalNode.h`,
//! `tree/LeafNode.h` and `io/Compression.h`.
//!
//! Voxel `(i, j, k)` sits at index-space point `(i, j, k)` (cell-centred data on `[0, 1]^3`
//! needs a half-voxel translation in the transform). Inactive voxels hold the background, 0.

use std::collections::BTreeMap;
use std::io::{Seek, SeekFrom, Write};
use std::path::Path;

use glam::{DMat4, DVec3};

use crate::error::{Error, Result};
use crate::io::atomic::Staged;

/// `OPENVDB_MAGIC` (" BDV" as a little-endian int64).
const MAGIC: i64 = 0x5644_4220;
/// `OPENVDB_FILE_VERSION` of OpenVDB 10 to 12.
const FILE_VERSION: u32 = 224;
/// The library version the file claims (OpenVDB 12.0: the format above is its own).
const LIBRARY_VERSION: (u32, u32) = (12, 0);
/// `io::COMPRESS_*` flags.
const COMPRESS_ZIP: u32 = 0x1;
const COMPRESS_ACTIVE_MASK: u32 = 0x2;
/// Per-node metadata bytes of `io::writeCompressedValues`: all values follow, or only the
/// active ones (every inactive value is the background).
const NO_MASK_OR_INACTIVE_VALS: u8 = 0;
const NO_MASK_AND_ALL_VALS: u8 = 6;

/// Log2 of the node sides: leaves 8^3, internal nodes 16^3 and 32^3 children.
const LEAF_LOG2: u32 = 3;
const NODE4_LOG2: u32 = 4;
const NODE5_LOG2: u32 = 5;
/// Voxels per side of a leaf and of a root child.
const LEAF_DIM: i32 = 1 << LEAF_LOG2;
const NODE5_DIM: i32 = 1 << (LEAF_LOG2 + NODE4_LOG2 + NODE5_LOG2);
/// Voxels of a leaf.
pub(crate) const LEAF_VOXELS: usize = 1 << (3 * LEAF_LOG2);

/// A voxel value type OpenVDB knows: its name in grid types and metadata.
pub trait Value: Copy + PartialEq + bytemuck::Pod + Default {
    /// The type's name in OpenVDB grid types (`float`, `vec3s`).
    const TYPE: &'static str;
    /// Whether every component is finite.
    fn is_finite(&self) -> bool;
}

impl Value for f32 {
    const TYPE: &'static str = "float";
    fn is_finite(&self) -> bool {
        f32::is_finite(*self)
    }
}

impl Value for [f32; 3] {
    const TYPE: &'static str = "vec3s";
    fn is_finite(&self) -> bool {
        self.iter().all(|v| v.is_finite())
    }
}

/// An 8^3 block of voxels: which are active, and their values (x slowest, z fastest, as in
/// OpenVDB's `LeafNode::coordToOffset`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Leaf<T> {
    pub(crate) mask: [u64; LEAF_VOXELS / 64],
    pub(crate) values: Vec<T>,
}

/// Index of voxel `(x, y, z)` (any coordinates) in its leaf.
fn leaf_offset(ijk: [i32; 3]) -> usize {
    let m = LEAF_DIM - 1;
    (((ijk[0] & m) << (2 * LEAF_LOG2)) | ((ijk[1] & m) << LEAF_LOG2) | (ijk[2] & m)) as usize
}

/// `ijk` rounded down to a multiple of `dim` (a power of two), negative coordinates included.
fn origin(ijk: [i32; 3], dim: i32) -> [i32; 3] {
    ijk.map(|c| c & !(dim - 1))
}

/// A sparse grid: its leaves by origin. Only leaves holding an active voxel are kept.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Voxels<T> {
    pub(crate) leaves: BTreeMap<[i32; 3], Leaf<T>>,
}

impl<T: Value> Voxels<T> {
    pub(crate) fn new() -> Self {
        Voxels { leaves: BTreeMap::new() }
    }

    /// Sets voxel `ijk` to `value` and makes it active.
    pub(crate) fn set(&mut self, ijk: [i32; 3], value: T) {
        let leaf = self
            .leaves
            .entry(origin(ijk, LEAF_DIM))
            .or_insert_with(|| Leaf { mask: [0; LEAF_VOXELS / 64], values: vec![T::default(); LEAF_VOXELS] });
        let n = leaf_offset(ijk);
        leaf.mask[n / 64] |= 1 << (n % 64);
        leaf.values[n] = value;
    }

    /// Adds the leaf whose first voxel is `origin` (a multiple of 8): voxel `n` (OpenVDB's
    /// order: x slowest, z fastest) is active with value `f(n)` where that is `Some`. A leaf
    /// with no active voxel is not added.
    pub(crate) fn insert_leaf(&mut self, origin: [i32; 3], mut f: impl FnMut(usize) -> Option<T>) {
        let mut leaf = Leaf { mask: [0; LEAF_VOXELS / 64], values: vec![T::default(); LEAF_VOXELS] };
        let mut any = false;
        for n in 0..LEAF_VOXELS {
            if let Some(v) = f(n) {
                leaf.mask[n / 64] |= 1 << (n % 64);
                leaf.values[n] = v;
                any = true;
            }
        }
        if any {
            self.leaves.insert(origin, leaf);
        }
    }

    /// The value of voxel `ijk` when it is active.
    pub fn get(&self, ijk: [i32; 3]) -> Option<T> {
        let leaf = self.leaves.get(&origin(ijk, LEAF_DIM))?;
        let n = leaf_offset(ijk);
        (leaf.mask[n / 64] >> (n % 64) & 1 == 1).then(|| leaf.values[n])
    }

    /// A box of `dims` voxels whose first voxel is `first`: voxel `first + (i, j, k)` is active
    /// with value `f([i, j, k])` where that is `Some`. Walks leaf by leaf, keeping only leaves
    /// with an active voxel, so memory follows the active voxels, not the box.
    pub(crate) fn from_dense(
        first: [i32; 3],
        dims: [u32; 3],
        mut f: impl FnMut([u32; 3]) -> Option<T>,
    ) -> Self {
        let mut leaves = BTreeMap::new();
        let last = [0, 1, 2].map(|a| first[a] + dims[a] as i32 - 1);
        if dims.contains(&0) {
            return Voxels { leaves };
        }
        let lo = origin(first, LEAF_DIM);
        let leaf_range = |a: usize| (lo[a]..=last[a]).step_by(LEAF_DIM as usize);
        for ox in leaf_range(0) {
            for oy in leaf_range(1) {
                for oz in leaf_range(2) {
                    let mut leaf =
                        Leaf { mask: [0; LEAF_VOXELS / 64], values: vec![T::default(); LEAF_VOXELS] };
                    let mut any = false;
                    for x in ox.max(first[0])..=(ox + LEAF_DIM - 1).min(last[0]) {
                        for y in oy.max(first[1])..=(oy + LEAF_DIM - 1).min(last[1]) {
                            for z in oz.max(first[2])..=(oz + LEAF_DIM - 1).min(last[2]) {
                                let local = [x - first[0], y - first[1], z - first[2]].map(|c| c as u32);
                                if let Some(v) = f(local) {
                                    let n = leaf_offset([x, y, z]);
                                    leaf.mask[n / 64] |= 1 << (n % 64);
                                    leaf.values[n] = v;
                                    any = true;
                                }
                            }
                        }
                    }
                    if any {
                        leaves.insert([ox, oy, oz], leaf);
                    }
                }
            }
        }
        Voxels { leaves }
    }

    /// Active voxels.
    pub fn active_count(&self) -> u64 {
        self.leaves.values().map(|l| l.mask.iter().map(|w| w.count_ones() as u64).sum::<u64>()).sum()
    }

    /// The active voxels' bounding box (inclusive), or `None` for an empty grid.
    pub(crate) fn bbox(&self) -> Option<([i32; 3], [i32; 3])> {
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        for (o, leaf) in &self.leaves {
            for n in (0..LEAF_VOXELS).filter(|n| leaf.mask[n / 64] >> (n % 64) & 1 == 1) {
                let ijk = [o[0] + (n >> 6) as i32, o[1] + ((n >> 3) & 7) as i32, o[2] + (n & 7) as i32];
                for a in 0..3 {
                    lo[a] = lo[a].min(ijk[a]);
                    hi[a] = hi[a].max(ijk[a]);
                }
            }
        }
        (lo[0] <= hi[0]).then_some((lo, hi))
    }
}

/// What a grid holds.
#[derive(Clone, Debug, PartialEq)]
pub enum GridData {
    /// Scalar voxels (`float`).
    Float(Voxels<f32>),
    /// Vector voxels (`vec3s`).
    Vec3(Voxels<[f32; 3]>),
}

/// OpenVDB's grid classes (the `class` metadata) that voltex writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum GridClass {
    /// Density, 0 outside: Blender, Houdini and Mitsuba read it as a fog volume.
    FogVolume,
    /// Anything else (a colour grid).
    Unknown,
}

/// One OpenVDB grid: its name, class, index-to-world transform and voxels.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub(crate) name: String,
    pub(crate) class: GridClass,
    /// Index space (voxel `(i, j, k)` at point `(i, j, k)`) to world.
    pub(crate) index_to_world: DMat4,
    /// The grid's voxels.
    pub data: GridData,
}

/// How voxel values are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compression {
    /// Every value of every node as it is (OpenVDB's `COMPRESS_NONE`).
    None,
    /// zlib, and only the active values of each node (`COMPRESS_ZIP | COMPRESS_ACTIVE_MASK`).
    #[default]
    Zip,
}

impl Compression {
    fn flags(self) -> u32 {
        match self {
            Compression::None => 0,
            Compression::Zip => COMPRESS_ZIP | COMPRESS_ACTIVE_MASK,
        }
    }
}

/// Checks `grids` (names non-empty and unique, values finite, transforms invertible and
/// finite), then writes them to `path` atomically.
pub fn write(path: &Path, grids: &[Grid], compression: Compression) -> Result<()> {
    stage(path, grids, compression)?.commit()
}

/// Like [`write()`], but leaves the file at its temporary name until [`Staged::commit`], so that
/// several files can be written all or none.
pub fn stage(path: &Path, grids: &[Grid], compression: Compression) -> Result<Staged> {
    check(grids).map_err(|e| Error::file(path, e))?;
    crate::io::atomic::stage(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::file(path, format!("cannot write: {e}")))?;
        let mut out = std::io::BufWriter::new(file);
        encode(&mut out, grids, compression)
            .and_then(|()| out.flush())
            .map_err(|e| Error::file(path, format!("cannot write VDB: {e}")))
    })
}

/// What makes `grids` unwritable, said in a sentence.
pub(crate) fn check(grids: &[Grid]) -> std::result::Result<(), String> {
    let mut names = std::collections::BTreeSet::new();
    for g in grids {
        if g.name.is_empty() || g.name.len() > 255 || g.name.contains('\0') {
            return Err(format!("grid name {:?}: expected 1 to 255 bytes without NUL", g.name));
        }
        if !names.insert(&g.name) {
            return Err(format!("grid name {:?} appears twice", g.name));
        }
        let m = g.index_to_world;
        let det = m.determinant();
        if !m.to_cols_array().iter().all(|v| v.is_finite()) || !det.is_finite() || det.abs() < 1e-300 {
            return Err(format!("grid {:?}: the index-to-world transform is not invertible", g.name));
        }
        if m.row(3) != glam::DVec4::W {
            return Err(format!("grid {:?}: the index-to-world transform is not affine", g.name));
        }
        let finite = match &g.data {
            GridData::Float(v) => v.leaves.values().all(|l| l.values.iter().all(Value::is_finite)),
            GridData::Vec3(v) => v.leaves.values().all(|l| l.values.iter().all(Value::is_finite)),
        };
        if !finite {
            return Err(format!("grid {:?} holds non-finite values", g.name));
        }
    }
    Ok(())
}

/// Writes a whole VDB file to `out` (seekable: grid offsets are patched in, as OpenVDB does
/// for files, so readers can load one grid without the others).
pub(crate) fn encode<W: Write + Seek>(
    out: &mut W,
    grids: &[Grid],
    compression: Compression,
) -> std::io::Result<()> {
    out.write_all(&MAGIC.to_le_bytes())?;
    out.write_all(&FILE_VERSION.to_le_bytes())?;
    out.write_all(&LIBRARY_VERSION.0.to_le_bytes())?;
    out.write_all(&LIBRARY_VERSION.1.to_le_bytes())?;
    out.write_all(&[1])?; // has grid offsets
    out.write_all(uuid().as_bytes())?;
    write_metadata(out, &[])?; // file metadata
    out.write_all(&(grids.len() as i32).to_le_bytes())?;
    for g in grids {
        write_grid(out, g, compression)?;
    }
    Ok(())
}

/// 36 hexadecimal digits and hyphens, unique enough to tell files apart (OpenVDB's own is
/// random and used only for that).
fn uuid() -> String {
    use std::hash::{BuildHasher, Hasher};
    let mut hex = String::new();
    for i in 0..2u64 {
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(i);
        h.write_u128(
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default().as_nanos(),
        );
        hex += &format!("{:016X}", h.finish());
    }
    format!("{}-{}-{}-{}-{}", &hex[0..8], &hex[8..12], &hex[12..16], &hex[16..20], &hex[20..32])
}

fn write_string<W: Write>(out: &mut W, s: &str) -> std::io::Result<()> {
    out.write_all(&(s.len() as u32).to_le_bytes())?;
    out.write_all(s.as_bytes())
}

/// A metadata value: its OpenVDB type name and bytes.
enum Meta {
    Str(String),
    Bool(bool),
    I64(i64),
    Vec3i([i32; 3]),
}

fn write_metadata<W: Write>(out: &mut W, items: &[(&str, Meta)]) -> std::io::Result<()> {
    out.write_all(&(items.len() as u32).to_le_bytes())?;
    for (name, value) in items {
        write_string(out, name)?;
        let (ty, bytes): (&str, Vec<u8>) = match value {
            Meta::Str(s) => ("string", s.as_bytes().to_vec()),
            Meta::Bool(b) => ("bool", vec![*b as u8]),
            Meta::I64(v) => ("int64", v.to_le_bytes().to_vec()),
            Meta::Vec3i(v) => ("vec3i", bytemuck::cast_slice(v).to_vec()),
        };
        write_string(out, ty)?;
        out.write_all(&(bytes.len() as u32).to_le_bytes())?;
        out.write_all(&bytes)?;
    }
    Ok(())
}

/// The transform: `ScaleTranslateMap` when the matrix only scales and translates (what every
/// reader, vdb-rs included, knows), else a general `AffineMap`.
fn write_transform<W: Write>(out: &mut W, m: &DMat4) -> std::io::Result<()> {
    let linear = glam::DMat3::from_mat4(*m);
    let diagonal =
        [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)].iter().all(|&(c, r)| linear.col(c)[r] == 0.0);
    let vec3 = |out: &mut W, v: DVec3| out.write_all(bytemuck::cast_slice(&v.to_array()));
    if diagonal {
        let scale = DVec3::new(linear.x_axis.x, linear.y_axis.y, linear.z_axis.z);
        write_string(out, "ScaleTranslateMap")?;
        vec3(out, m.w_axis.truncate())?;
        vec3(out, scale)?;
        vec3(out, scale.abs())?; // voxel size
        let inverse = scale.recip();
        vec3(out, inverse)?;
        vec3(out, inverse * inverse)?;
        vec3(out, inverse / 2.0)
    } else {
        // OpenVDB's Mat4d maps row vectors (p' = p M, translation in the last row): M's
        // row-major elements are glam's column-major ones.
        write_string(out, "AffineMap")?;
        out.write_all(bytemuck::cast_slice(&m.to_cols_array()))
    }
}

fn write_grid<W: Write + Seek>(out: &mut W, g: &Grid, compression: Compression) -> std::io::Result<()> {
    match &g.data {
        GridData::Float(v) => write_typed(out, g, v, compression),
        GridData::Vec3(v) => write_typed(out, g, v, compression),
    }
}

/// Leaves grouped into the internal nodes of the 5-4-3 tree: root children by origin (in
/// OpenVDB's `Coord` order, x then y then z), their children and leaves by offset in the node
/// (the order of the child mask's bits).
type Tree<'a, T> = BTreeMap<[i32; 3], BTreeMap<usize, BTreeMap<usize, &'a Leaf<T>>>>;

fn node_offset(ijk: [i32; 3], node_log2: u32, child_total: u32) -> usize {
    let m = (1 << (node_log2 + child_total)) - 1;
    let c = ijk.map(|v| ((v & m) >> child_total) as usize);
    (c[0] << (2 * node_log2)) | (c[1] << node_log2) | c[2]
}

fn write_typed<W: Write + Seek, T: Value>(
    out: &mut W,
    g: &Grid,
    voxels: &Voxels<T>,
    compression: Compression,
) -> std::io::Result<()> {
    let mut tree: Tree<T> = BTreeMap::new();
    for (o, leaf) in &voxels.leaves {
        tree.entry(origin(*o, NODE5_DIM))
            .or_default()
            .entry(node_offset(*o, NODE5_LOG2, NODE4_LOG2 + LEAF_LOG2))
            .or_default()
            .insert(node_offset(*o, NODE4_LOG2, LEAF_LOG2), leaf);
    }
    let flags = compression.flags();
    // Descriptor: name, type, instance parent, then the three offsets (patched below).
    write_string(out, &g.name)?;
    write_string(out, &format!("Tree_{}_5_4_3", T::TYPE))?;
    write_string(out, "")?;
    let offsets_at = out.stream_position()?;
    out.write_all(&[0u8; 24])?;
    let grid_pos = out.stream_position()?;
    out.write_all(&flags.to_le_bytes())?;
    let (lo, hi) = voxels.bbox().unwrap_or(([0; 3], [0; 3]));
    let leaf_bytes = voxels.leaves.len() as i64 * (LEAF_VOXELS * std::mem::size_of::<T>() + 64) as i64;
    let mut meta = vec![
        (
            "class",
            Meta::Str(
                match g.class {
                    GridClass::FogVolume => "fog volume",
                    GridClass::Unknown => "unknown",
                }
                .into(),
            ),
        ),
        ("creator", Meta::Str("voltex".into())),
        ("file_bbox_max", Meta::Vec3i(hi)),
        ("file_bbox_min", Meta::Vec3i(lo)),
        (
            "file_compression",
            Meta::Str(
                match compression {
                    Compression::None => "none",
                    Compression::Zip => "zip + active values",
                }
                .into(),
            ),
        ),
        ("file_mem_bytes", Meta::I64(leaf_bytes)),
        ("file_voxel_count", Meta::I64(voxels.active_count() as i64)),
        ("is_local_space", Meta::Bool(false)),
        ("is_saved_as_half_float", Meta::Bool(false)),
        ("name", Meta::Str(g.name.clone())),
    ];
    if T::TYPE == "vec3s" {
        meta.push(("vector_type", Meta::Str("invariant".into())));
    }
    write_metadata(out, &meta)?;
    write_transform(out, &g.index_to_world)?;
    // Topology: buffer count, the root (background, no tiles, its children), then each
    // internal node's masks and values, and each leaf's value mask, depth first.
    out.write_all(&1i32.to_le_bytes())?;
    out.write_all(bytemuck::bytes_of(&T::default()))?;
    out.write_all(&0u32.to_le_bytes())?;
    out.write_all(&(tree.len() as u32).to_le_bytes())?;
    for (o5, node5) in &tree {
        out.write_all(bytemuck::cast_slice(o5))?;
        write_internal::<W, T>(out, NODE5_LOG2, node5.keys(), flags)?;
        for node4 in node5.values() {
            write_internal::<W, T>(out, NODE4_LOG2, node4.keys(), flags)?;
            for leaf in node4.values() {
                out.write_all(bytemuck::cast_slice(&leaf.mask))?;
            }
        }
    }
    let block_pos = out.stream_position()?;
    // Buffers: each leaf's value mask and values, in the same order.
    for leaf in tree.values().flat_map(|n| n.values()).flat_map(|n| n.values()) {
        out.write_all(bytemuck::cast_slice(&leaf.mask))?;
        write_values(out, &leaf.values, &leaf.mask, flags)?;
    }
    let end_pos = out.stream_position()?;
    out.seek(SeekFrom::Start(offsets_at))?;
    for p in [grid_pos, block_pos, end_pos] {
        out.write_all(&(p as i64).to_le_bytes())?;
    }
    out.seek(SeekFrom::Start(end_pos))?;
    Ok(())
}

/// An internal node of side `2^log2` children whose children sit at `children` (offsets in
/// the node): child mask, value mask (no active tiles), and its tile values (all background).
fn write_internal<'a, W: Write, T: Value>(
    out: &mut W,
    log2: u32,
    children: impl Iterator<Item = &'a usize>,
    flags: u32,
) -> std::io::Result<()> {
    let n = 1usize << (3 * log2);
    let mut child_mask = vec![0u64; n / 64];
    for &c in children {
        child_mask[c / 64] |= 1 << (c % 64);
    }
    let value_mask = vec![0u64; n / 64];
    out.write_all(bytemuck::cast_slice(&child_mask))?;
    out.write_all(bytemuck::cast_slice(&value_mask))?;
    write_values(out, &vec![T::default(); n], &value_mask, flags)
}

/// `io::writeCompressedValues`: the metadata byte, then every value, or with active-mask
/// compression only the active ones (inactive values are all the background here), raw or
/// zipped (`zipToStream`: the byte count, negative when stored raw because zlib did not help).
fn write_values<W: Write, T: Value>(
    out: &mut W,
    values: &[T],
    mask: &[u64],
    flags: u32,
) -> std::io::Result<()> {
    let kept: Vec<T> = if flags & COMPRESS_ACTIVE_MASK != 0 {
        out.write_all(&[NO_MASK_OR_INACTIVE_VALS])?;
        values
            .iter()
            .enumerate()
            .filter(|(i, _)| mask[i / 64] >> (i % 64) & 1 == 1)
            .map(|(_, v)| *v)
            .collect()
    } else {
        out.write_all(&[NO_MASK_AND_ALL_VALS])?;
        values.to_vec()
    };
    let bytes: &[u8] = bytemuck::cast_slice(&kept);
    if flags & COMPRESS_ZIP == 0 {
        return out.write_all(bytes);
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(bytes)?;
    let zipped = z.finish()?;
    if zipped.len() < bytes.len() {
        out.write_all(&(zipped.len() as i64).to_le_bytes())?;
        out.write_all(&zipped)
    } else {
        out.write_all(&(-(bytes.len() as i64)).to_le_bytes())?;
        out.write_all(bytes)
    }
}

#[cfg(test)]
mod tests;
