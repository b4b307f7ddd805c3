//! OpenVDB files in: a density grid (a fog volume, or a level set turned into density) and an
//! optional colour grid (`Cd`), read with `vdb-rs` behind a structural walk of the file
//! (`walk`: no length, panic or C decoder reached unchecked), and kept sparse for the GPU
//! (`sparse`: a brick atlas and a two-level table). Errors name the file and the grid.

pub(crate) mod sparse;
mod spliced;
mod tree;
pub(crate) mod walk;

use std::path::Path;
use std::sync::Arc;

use glam::DMat4;

pub(crate) use sparse::SparseVolume;
pub(crate) use tree::level_set_density;

use crate::error::{Error, Result};
use tree::{Blocks, Keep};
use walk::{GridHeader, Topology, Value};

/// One grid of a file, as `voltex import` and the errors list them.
#[derive(Debug, Clone)]
pub struct GridInfo {
    /// The grid's name in the file.
    pub name: String,
    /// OpenVDB's value type name (`float`, `vec3s`, `int32`, ...).
    pub value: String,
    /// `level set`, `fog volume`, ... (empty when the file says nothing).
    pub(crate) class: String,
}

impl GridInfo {
    /// Whether the file says the grid is a level set (signed distances).
    pub fn is_level_set(&self) -> bool {
        self.class == "level set"
    }
}

/// What to read: the density grid, an optional colour grid, and for a level set the width (in
/// voxels of the grid) of the band over which density goes from 1 inside to 0 outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The float grid read as density (a fog volume's, or a level set's distances).
    pub density: String,
    /// The vec3 grid read as colour, if any.
    pub color: Option<String>,
    /// Width in voxels of a level set's band from density 1 to 0.
    pub band: f64,
}

fn read_file(path: &Path) -> Result<Arc<[u8]>> {
    Ok(crate::input::read(path, crate::input::Kind::Asset, "an OpenVDB file")?.into())
}

/// The grids of the file at `path`.
pub fn grids(path: &Path) -> Result<Vec<GridInfo>> {
    let bytes = read_file(path)?;
    let archive = walk::archive(&bytes).map_err(|e| Error::file(path, e))?;
    Ok(archive.grids.iter().map(info).collect())
}

fn info(g: &GridHeader) -> GridInfo {
    GridInfo { name: g.name.clone(), value: g.value_name().to_string(), class: g.class.clone() }
}

/// "`a` (float, level set), `b` (vec3s)": the grids for an error message.
pub(crate) fn list(grids: &[GridInfo]) -> String {
    let items: Vec<String> = grids
        .iter()
        .map(|g| {
            let class = if g.class.is_empty() { String::new() } else { format!(", {}", g.class) };
            format!("`{}` ({}{class})", g.name, g.value)
        })
        .collect();
    if items.is_empty() {
        "it has no grids".into()
    } else {
        format!("its grids are {}", items.join(", "))
    }
}

/// Reads `request` from the file at `path` into a sparse volume.
pub fn load(path: &Path, request: &Request) -> Result<SparseVolume> {
    parse(read_file(path)?, path, request)
}

/// Reads `request` from the bytes of an OpenVDB file; `path` names it in errors.
pub fn parse(bytes: Arc<[u8]>, path: &Path, request: &Request) -> Result<SparseVolume> {
    let read = read_grids(&bytes, path, request)?;
    let fail = |msg: String| Error::file(path, format!("grid `{}`: {msg}", read.name));
    sparse::check_extent(&read.density).map_err(fail)?;
    let built = SparseVolume::build(&read.density, read.color.as_ref(), read.to_world).map_err(fail)?;
    built.ok_or_else(|| {
        let what =
            if read.level_set { "no voxel inside the level set" } else { "no active voxel with density" };
        fail(format!("the grid is empty: {what}"))
    })
}

/// The density grid of `request` in the file at `path` as read, before it is made sparse: its
/// voxels' values (a level set's already turned into density) and its transform. For checks
/// of the GPU's sparse copy that must not share its bricks and tables.
pub fn voxels(path: &Path, request: &Request) -> Result<GridVoxels> {
    let read = read_grids(&read_file(path)?, path, request)?;
    Ok(GridVoxels { index_to_world: read.to_world, blocks: read.density })
}

/// A density grid's voxels by index (see [`voxels`]).
pub struct GridVoxels {
    /// Index space to world space (the file's transform).
    pub index_to_world: DMat4,
    blocks: Blocks<f32>,
}

impl GridVoxels {
    /// The value of voxel `i` (0 where the grid holds none).
    pub fn get(&self, i: glam::IVec3) -> f32 {
        let leaf = i >> glam::IVec3::splat(3);
        sparse::value(self.blocks.get(&leaf), i - (leaf << glam::IVec3::splat(3)), 0.0)
    }

    /// Every value the grid holds (a tile's once per voxel it covers).
    pub fn values(&self) -> impl Iterator<Item = f32> + '_ {
        self.blocks.values().flat_map(|b| match b {
            tree::Block::Tile(v) => vec![*v; 512],
            tree::Block::Voxels(v) => v.to_vec(),
        })
    }

    /// The lowest and highest voxel (inclusive) of the leaves and tiles that hold values.
    pub fn bounds(&self) -> (glam::IVec3, glam::IVec3) {
        let lo = self.blocks.keys().fold(glam::IVec3::MAX, |a, k| a.min(*k << 3));
        let hi = self.blocks.keys().fold(glam::IVec3::MIN, |a, k| a.max((*k << 3) + 7));
        (lo, hi)
    }
}

/// A file's density (and colour) grids as read and checked, before they are made sparse.
struct Read {
    name: String,
    level_set: bool,
    to_world: DMat4,
    density: Blocks<f32>,
    color: Option<Blocks<[f32; 3]>>,
}

fn read_grids(bytes: &Arc<[u8]>, path: &Path, request: &Request) -> Result<Read> {
    let archive = walk::archive(bytes).map_err(|e| Error::file(path, e))?;
    let fail = |grid: &str, msg: String| Error::file(path, format!("grid `{grid}`: {msg}"));
    let find = |name: &str, want: Value| -> Result<&GridHeader> {
        let all: Vec<GridInfo> = archive.grids.iter().map(info).collect();
        let g = archive
            .grids
            .iter()
            .find(|g| g.name == name)
            .ok_or_else(|| Error::file(path, format!("no grid named `{name}`: {}", list(&all))))?;
        let expected = match want {
            Value::Float => "a float grid (a fog volume or a level set; `half` or `float`)",
            Value::Vec3 => "a vec3s grid (a colour such as Houdini's `Cd`)",
        };
        if g.value() != Some(want) {
            return Err(fail(name, format!("expected {expected}, found a {} grid", g.value_name())));
        }
        if !g.instance_parent.is_empty() {
            let msg = format!(
                "shares the tree of grid `{}` (an instance): voltex reads grids with their own tree",
                g.instance_parent
            );
            return Err(fail(name, msg));
        }
        Ok(g)
    };
    let dg = find(&request.density, Value::Float)?;
    let dt = walk::topology(bytes, dg).map_err(|e| fail(&dg.name, e))?;
    let to_world = check_transform(&dt).map_err(|e| fail(&dg.name, e))?;
    let level_set = dg.class == "level set";
    let mut grid = read::<f32>(bytes, &dt, dg).map_err(|e| fail(&dg.name, e))?;
    let root_tiles = |t: &Topology, inside: bool| {
        t.root_tiles.iter().find(|(_, v, active)| *active || (inside && *v < 0.0)).map(|(o, _, _)| {
            format!(
                "a root tile (a constant 4096^3 region) at {}, {}, {}: voltex reads grids whose values lie in leaves \
                 and internal nodes",
                o.x, o.y, o.z
            )
        })
    };
    if let Some(e) = root_tiles(&dt, level_set) {
        return Err(fail(&dg.name, e));
    }
    let density: Blocks<f32> = if level_set {
        tree::signed_flood_fill(&mut grid.tree, dt.background);
        let phi =
            tree::blocks(&grid.tree, Keep::LevelSet, |v: &f32| *v < 0.0).map_err(|e| fail(&dg.name, e))?;
        finite(&phi).map_err(|e| fail(&dg.name, e))?;
        let voxel = voxel_size(&dt.index_to_world);
        let band = (request.band * voxel) as f32;
        tree::map(phi, |v| level_set_density(v, band))
    } else {
        if dt.background != 0.0 {
            let msg = format!("a fog volume's background must be 0 (empty space), found {}", dt.background);
            return Err(fail(&dg.name, msg));
        }
        let d = tree::blocks(&grid.tree, Keep::Active, |_| false).map_err(|e| fail(&dg.name, e))?;
        finite(&d).map_err(|e| fail(&dg.name, e))?;
        if let Some((p, v)) = tree::find(&d, |v| *v >= 0.0) {
            let msg = format!(
                "voxel ({}, {}, {}) holds the negative density {v}: expected densities of 0 or more",
                p.x, p.y, p.z
            );
            return Err(fail(&dg.name, msg));
        }
        d
    };
    drop(grid);
    let color = match &request.color {
        None => None,
        Some(name) => {
            let cg = find(name, Value::Vec3)?;
            let ct = walk::topology(bytes, cg).map_err(|e| fail(name, e))?;
            if let Some(e) = root_tiles(&ct, false) {
                return Err(fail(name, e));
            }
            if (ct.index_to_world - dt.index_to_world).abs().to_cols_array().iter().any(|d| *d > 1e-9) {
                let msg = format!(
                    "its transform differs from grid `{}`'s: a colour grid must share the density's voxels",
                    dg.name
                );
                return Err(fail(name, msg));
            }
            let blocks: Blocks<[f32; 3]> = if cg.half || cg.type_name.ends_with("_HalfFloat") {
                let g = read::<[half::f16; 3]>(bytes, &ct, cg).map_err(|e| fail(name, e))?;
                let b = tree::blocks(&g.tree, Keep::Active, |_| false).map_err(|e| fail(name, e))?;
                tree::map(b, |v| v.map(half::f16::to_f32))
            } else {
                let g = read::<[f32; 3]>(bytes, &ct, cg).map_err(|e| fail(name, e))?;
                tree::blocks(&g.tree, Keep::Active, |_| false).map_err(|e| fail(name, e))?
            };
            if let Some((p, v)) = tree::find(&blocks, |c| c.iter().all(|x| x.is_finite())) {
                let msg = format!("voxel ({}, {}, {}) holds {v:?}: expected finite colours", p.x, p.y, p.z);
                return Err(fail(name, msg));
            }
            Some(blocks)
        }
    };
    Ok(Read { name: dg.name.clone(), level_set, to_world, density, color })
}

/// Reads grid `g` with vdb-rs, over the stream the walk patched, catching its panics.
fn read<T: bytemuck::Pod>(
    bytes: &Arc<[u8]>,
    t: &Topology,
    g: &GridHeader,
) -> std::result::Result<vdb_rs::Grid<T>, String> {
    let (reader, switch) = spliced::Spliced::new(bytes.clone(), t.splices.clone());
    let name = g.name.clone();
    let block_pos = switch.position(g.block_pos);
    let result = crate::error::quietly(std::panic::AssertUnwindSafe(move || {
        let mut r = vdb_rs::VdbReader::new(reader).map_err(|e| e.to_string())?;
        if let Some(d) = r.grid_descriptors.get_mut(&name) {
            d.block_pos = block_pos;
        }
        switch.on();
        r.read_grid::<T>(&name).map_err(|e| e.to_string())
    }));
    match result {
        Ok(r) => r.map_err(|e| format!("the OpenVDB reader failed: {e}")),
        Err(_) => Err("the OpenVDB reader failed on it (a corrupt file?)".into()),
    }
}

fn finite(blocks: &Blocks<f32>) -> std::result::Result<(), String> {
    match tree::find(blocks, |v| v.is_finite()) {
        Some((p, v)) => Err(format!("voxel ({}, {}, {}) holds {v}: expected finite values", p.x, p.y, p.z)),
        None => Ok(()),
    }
}

/// The smallest world length of a voxel edge under `m`.
pub(crate) fn voxel_size(m: &DMat4) -> f64 {
    [m.x_axis, m.y_axis, m.z_axis].iter().map(|c| c.truncate().length()).fold(f64::INFINITY, f64::min)
}

/// The index-to-world matrix, if it is finite, affine and far from singular.
fn check_transform(t: &Topology) -> std::result::Result<DMat4, String> {
    let m = t.index_to_world;
    let cols = m.to_cols_array();
    if cols.iter().any(|x| !x.is_finite()) {
        return Err(format!("its {} transform has non-finite entries", t.map));
    }
    if m.row(3) != glam::DVec4::W {
        return Err(format!("its {} transform is not affine (last column {:?})", t.map, m.row(3).to_array()));
    }
    let longest = [m.x_axis, m.y_axis, m.z_axis].iter().map(|c| c.truncate().length()).fold(0.0, f64::max);
    let det = m.determinant();
    if longest == 0.0 || det.abs() <= 1e-9 * longest.powi(3) {
        return Err(format!(
            "its {} transform is singular (zero scale or collapsed axes: determinant {det:e}): expected voxels with volume",
            t.map
        ));
    }
    Ok(m)
}

#[cfg(test)]
mod tests;
