//! `voltex export`: every texel, and the hypertexture of every node that draws one, baked on the
//! GPU by the render's own kernels at full precision (f32, [`Baker::full_precision`]) and turned
//! into OpenVDB grids that Blender, Houdini and Mitsuba render: a float `density` (fog volume)
//! and a vec3 `Cd` colour, with the index-to-world transform. Volume objects (nodes drawing an
//! OpenVDB grid) are written from the grid as read, voxel for voxel (`volume_grids`).
//!
//! Density is the extinction coefficient per world unit: a voxel of opacity `a` over the opacity
//! length `L` (a world length; every method composites `1 - (1 - a)^(step / L)`) has
//! `sigma_t = -ln(1 - a) / L`, so `exp(-sigma_t * step)` is voltex's own transmittance.
//! Voxels of opacity 0 are inactive. Opacity 1 (an opaque voxel: infinitely dense for voltex)
//! becomes `OPAQUE_TRANSMITTANCE` through one voxel. `Cd` is the colour without the opacity
//! (the premultiplied colour over alpha): unlit albedo, except for slice stacks, which hold
//! their baked shading.

use std::path::Path;
use std::sync::Arc;

use glam::{DMat4, DVec3, DVec4};

use crate::bake::hypertexture::HyperTexel;
use crate::bake::{BakeRequest, BakeSource, Baker};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::io::vdb::{self, Grid, GridClass, GridData, Voxels};
use crate::mesh::BaseSurface;
use crate::methods::view::FrameLight;
use crate::scene::{Scene, TexelSource};
use crate::vdb::SparseVolume;

pub mod resample_world;
pub mod world;

pub use world::{WorldOptions, WorldShell};

/// The transmittance of one voxel (its smallest world side) of opacity 1.
pub(crate) const OPAQUE_TRANSMITTANCE: f64 = 1e-4;
/// Most voxels one exported volume may have: its f32 RGBA read-back takes 16 bytes a voxel
/// (1 GiB at this limit), and the grids as much again.
pub(crate) const MAX_EXPORT_VOXELS: u64 = 1 << 26;
/// Default voxels along the longest side of an exported hypertexture node.
pub const DEFAULT_HYPER_RESOLUTION: u32 = 128;

/// `voltex export`'s options.
#[derive(Debug, Clone)]
pub struct ExportOptions {
    /// Texels and nodes to export (default: all).
    pub only: Vec<String>,
    /// Time of the bake (animated hypertextures, sequences' frames, moving surfaces).
    pub time: Option<f64>,
    /// Voxels along the longest side of a hypertexture node's box.
    pub resolution: u32,
    /// How the voxel values are stored.
    pub compression: vdb::Compression,
    /// Every textured object resampled into world voxels (`--world`), in place of one tile per
    /// texel.
    pub world: Option<WorldOptions>,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            only: Vec::new(),
            time: None,
            resolution: DEFAULT_HYPER_RESOLUTION,
            compression: vdb::Compression::Zip,
            world: None,
        }
    }
}

/// Where an export's voxels come from.
#[derive(Debug)]
pub enum Source {
    /// A texel or a hypertexture, baked on the GPU; `opacity_length` is the world length over
    /// which a voxel's alpha is reached.
    Bake {
        /// What to bake.
        request: BakeRequest,
        /// World length over which a voxel's alpha is reached.
        opacity_length: f64,
    },
    /// A volume object's grid as read from its file, with its volume's `density_scale` and
    /// `albedo`.
    Volume {
        /// The grid's voxels.
        grid: Arc<SparseVolume>,
        /// Extinction per unit density per world unit.
        density_scale: f64,
        /// Linear RGB scaling the scattered light.
        albedo: [f32; 3],
    },
    /// A textured object's look resampled into world voxels on the GPU (`--world`).
    Shell(Box<WorldShell>),
}

/// One volume to write: its file stem, what it is, its voxels and where they lie.
#[derive(Debug)]
pub struct Export {
    /// The file stem.
    pub name: String,
    /// What the volume is, for the listing (e.g. `texel "grass"`).
    pub what: String,
    /// Where its voxels come from.
    pub source: Source,
    /// Voxel `(i, j, k)` (the bake's voxel centre) to world.
    pub index_to_world: DMat4,
    /// How the transform was found, when that is not exact.
    pub note: Option<String>,
}

/// Every volume the scene exports (or those `only` names), in a fixed order: texels by name,
/// then hypertexture nodes in document order. CPU only: unknown names, file-name clashes and
/// volumes over `MAX_EXPORT_VOXELS` fail here, before any GPU work.
pub fn plan(scene: &Scene, opts: &ExportOptions) -> Result<Vec<Export>> {
    let time = opts.time.unwrap_or(scene.time);
    let objects = scene.objects_at(time)?;
    let light = FrameLight::of(scene);
    let mut out = Vec::new();
    if let Some(world) = opts.world {
        out.extend(world_shells(scene, &objects, &light, time, world, &opts.only)?);
    }
    for (name, texel) in scene.texels.iter().filter(|_| opts.world.is_none()) {
        if matches!(texel.source, TexelSource::Sequence { .. }) {
            continue; // its frames are texels of their own
        }
        // Slice stacks hold what they were baked with; every other source bakes the unlit albedo.
        let stack = match &texel.source {
            TexelSource::Slices { dir } => Some(scene.stack(&dir.value).and_then(|s| s.manifest.as_ref())),
            _ => None,
        };
        let per_pixel = stack.is_none();
        let lit =
            stack.is_some_and(|m| m.is_none_or(|m| m.lighting == crate::io::stack::StackLighting::Baked));
        let mut bakes = Vec::new();
        crate::methods::texels::bake_index(scene, name, per_pixel, &light, time, &mut bakes)?;
        let request = bakes.remove(0).request;
        let drawn_by = objects.iter().find(|o| o.texel.as_deref() == Some(name.as_str()));
        let (texel_to_world, note) = match drawn_by {
            Some(o) => texel_frame(&o.surface, &o.name),
            None => (DMat4::IDENTITY, Some("drawn by no object: one tile is one world unit".into())),
        };
        out.push(Export {
            name: name.clone(),
            what: format!("texel \"{name}\""),
            index_to_world: texel_to_world * index_to_box(DVec3::ZERO, DVec3::ONE, request.resolution),
            source: Source::Bake {
                request,
                opacity_length: texel.opacity_length(&scene.hypertextures) as f64,
            },
            note: if lit { Some(join(note, "a slice stack: Cd holds its baked shading")) } else { note },
        });
    }
    for o in &objects {
        let Some(node) = &o.hypertexture else { continue };
        let h = scene.hypertextures.get(&node.name).ok_or_else(|| {
            Error::Invalid(format!("{}: unknown hypertexture `{}`", scene.path.display(), node.name))
        })?;
        let (lo, hi) = crate::hypertexture::pack(h).bounds;
        let extent = hi - lo;
        // `--world --voxel`: about that voxel along each axis of the node's box in world units.
        let resolution = match opts.world.and_then(|w| w.voxel) {
            Some(voxel) => std::array::from_fn(|a| {
                let world = extent[a] * node.to_world.col(a).truncate().length();
                ((world / voxel).round().clamp(1.0, u32::MAX as f64) as u32).max(1)
            }),
            None => extent
                .to_array()
                .map(|e| ((opts.resolution as f64 * e / extent.max_element()).round() as u32).max(1)),
        };
        let texel = HyperTexel::new(h, Some((lo, hi)), resolution, time);
        out.push(Export {
            name: o.name.clone(),
            what: format!("hypertexture \"{}\" of node \"{}\"", node.name, o.name),
            source: Source::Bake {
                request: BakeRequest {
                    resolution,
                    source: BakeSource::Hypertexture(Box::new(texel)),
                    per_pixel: true,
                    light: light.direction,
                    ambient: light.ambient,
                    derived: Default::default(),
                    layers: false,
                    shadow: None,
                },
                opacity_length: h.opacity_length,
            },
            index_to_world: node.to_world * index_to_box(lo, hi, resolution),
            note: None,
        });
    }
    for o in &objects {
        let Some(node) = &o.volume else { continue };
        let v = scene.volumes.get(&node.name).ok_or_else(|| {
            Error::Invalid(format!("{}: unknown volume `{}`", scene.path.display(), node.name))
        })?;
        out.push(Export {
            name: o.name.clone(),
            what: format!("volume \"{}\" of node \"{}\"", node.name, o.name),
            source: Source::Volume {
                grid: node.grid.clone(),
                density_scale: v.density_scale,
                albedo: v.albedo,
            },
            index_to_world: node.to_world * node.grid.index_to_world,
            note: None,
        });
    }
    select(scene, out, &opts.only, opts.world.is_some())
}

/// Every object drawing a texel (those `only` names, when it names any), resampled in world
/// space: one export per object, named after it.
fn world_shells(
    scene: &Scene,
    objects: &[crate::scene::SceneObject],
    light: &FrameLight,
    time: f64,
    world: WorldOptions,
    only: &[String],
) -> Result<Vec<Export>> {
    let mut out = Vec::new();
    for o in objects {
        if o.hypertexture.is_some() || o.volume.is_some() {
            continue;
        }
        let what = format!("object \"{}\"", o.name);
        let Some(texel_name) = &o.texel else {
            if only.contains(&o.name) {
                return Err(Error::Invalid(format!(
                    "{}: --only {:?}: {what} draws no texel, so it has no look to export (its base surface only)",
                    scene.path.display(),
                    o.name
                )));
            }
            continue;
        };
        if !only.is_empty() && !only.contains(&o.name) {
            continue;
        }
        let texel = &scene.texels[texel_name];
        // Slice stacks hold what they were baked with; every other source bakes the unlit albedo.
        let stack = matches!(texel.source, TexelSource::Slices { .. });
        let mut bakes = Vec::new();
        crate::methods::texels::bake_index(scene, texel_name, !stack, light, time, &mut bakes)?;
        let request = bakes.remove(0).request;
        let opacity_length = texel.opacity_length(&scene.hypertextures) as f64;
        let at = |e: Error| Error::Invalid(format!("{}: {e}", scene.path.display()));
        let shell =
            WorldShell::new(&what, o.surface.clone(), request, opacity_length, world, MAX_EXPORT_VOXELS)
                .map_err(at)?;
        let note = stack.then(|| "a slice stack: Cd holds the colour it was baked with".to_string());
        out.push(Export {
            name: o.name.clone(),
            what: format!(
                "{what} (texel \"{texel_name}\", voxel {:.6}, {}^3 sub-points)",
                shell.voxel, shell.samples
            ),
            index_to_world: shell.index_to_world(),
            source: Source::Shell(Box::new(shell)),
            note,
        });
    }
    Ok(out)
}

/// Keeps the volumes `only` names (all when empty), and checks names and sizes.
fn select(scene: &Scene, all: Vec<Export>, only: &[String], world: bool) -> Result<Vec<Export>> {
    let at = |msg: String| Error::Invalid(format!("{}: {msg}", scene.path.display()));
    if let Some(unknown) = only.iter().find(|n| !all.iter().any(|e| &e.name == *n)) {
        let names: Vec<&str> = all.iter().map(|e| e.name.as_str()).collect();
        return Err(at(format!(
            "--only {unknown:?}: expected {} of the scene: {}",
            if world {
                "a textured object, a hypertexture node or a volume node"
            } else {
                "a texel, a hypertexture node or a volume node"
            },
            if names.is_empty() { "it has none".to_string() } else { names.join(", ") }
        )));
    }
    let chosen: Vec<Export> = all.into_iter().filter(|e| only.is_empty() || only.contains(&e.name)).collect();
    if chosen.is_empty() {
        return Err(at(format!(
            "the scene has no {} to export",
            if world {
                "textured object, hypertexture node or volume node"
            } else {
                "texel, hypertexture node or volume node"
            }
        )));
    }
    for (i, e) in chosen.iter().enumerate() {
        if let Some(other) = chosen[..i].iter().find(|o| o.name == e.name) {
            return Err(at(format!(
                "{} and {} would both be written to {}.vdb: export one at a time with --only",
                other.what, e.what, e.name
            )));
        }
        file_name(&e.name).map_err(|m| at(format!("{}: {m}", e.what)))?;
        // A volume object's grid is already in memory, as sparse as its file; a world shell's
        // leaves were counted as it was planned.
        let Source::Bake { request, .. } = &e.source else { continue };
        let [x, y, z] = request.resolution;
        let voxels = x as u64 * y as u64 * z as u64;
        if voxels > MAX_EXPORT_VOXELS {
            return Err(at(format!(
                "{}: {x}x{y}x{z} = {voxels} voxels, more than the {MAX_EXPORT_VOXELS} one export may have \
                 (16 bytes a voxel are read back): lower its resolution{}",
                e.what,
                if matches!(request.source, BakeSource::Hypertexture(_)) {
                    " (--resolution, or --voxel with --world)"
                } else {
                    ""
                }
            )));
        }
    }
    Ok(chosen)
}

/// `NAME.vdb`, or why NAME cannot be a file name on every system a scene travels to.
pub(crate) fn file_name(name: &str) -> std::result::Result<String, String> {
    let bad = |c: char| c.is_control() || "/\\:*?\"<>|".contains(c);
    if name.is_empty() || name == "." || name == ".." || name.starts_with('.') {
        return Err(format!("{name:?} is not a file name (empty, or starting with a dot)"));
    }
    if let Some(c) = name.chars().find(|&c| bad(c)) {
        return Err(format!("{name:?} is not a file name: it holds {c:?}"));
    }
    if name.len() > 200 {
        return Err(format!("{name:?} is too long for a file name ({} bytes, at most 200)", name.len()));
    }
    Ok(format!("{name}.vdb"))
}

impl Export {
    /// Voxels per axis: the bake's, or the box of a volume's voxels with density.
    pub fn resolution(&self) -> [u32; 3] {
        match &self.source {
            Source::Bake { request, .. } => request.resolution,
            Source::Volume { grid, .. } => (grid.hi - grid.lo + 1).as_uvec3().to_array(),
            Source::Shell(shell) => shell.extent(),
        }
    }

    /// A volume written from its grid needs no GPU.
    pub fn needs_gpu(&self) -> bool {
        !matches!(self.source, Source::Volume { .. })
    }
}

/// Bakes `e` with `baker` (a [`Baker::full_precision`]) and reads the volume back: premultiplied
/// RGBA, x fastest, then y, then z. A world shell is resampled too: per leaf, 512 voxels of
/// (extinction, colour) ([`world::resample`]).
pub fn bake(ctx: &GpuContext, baker: &mut Baker, e: &Export) -> Result<Vec<[f32; 4]>> {
    if baker.format() != wgpu::TextureFormat::Rgba32Float {
        return Err(Error::Invalid("export needs a full-precision baker".into()));
    }
    let request = match &e.source {
        Source::Bake { request, .. } => request,
        Source::Shell(shell) => return world::resample(ctx, baker, shell),
        Source::Volume { .. } => return Err(Error::Invalid(format!("{} is not baked", e.what))),
    };
    let baked = baker.bake(ctx, request)?;
    let bytes = crate::gpu::readback::read_texture(ctx, &baked.volume, 16)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}

/// The `density` and `Cd` grids of `e`: from its baked volume `rgba` ([`bake`]; empty for a
/// volume object, which is written from its grid).
pub fn grids(e: &Export, rgba: &[[f32; 4]]) -> Vec<Grid> {
    let (density, colour) = match &e.source {
        Source::Bake { request, opacity_length } => baked_grids(request.resolution, *opacity_length, e, rgba),
        Source::Volume { grid, density_scale, albedo } => volume_grids(grid, *density_scale, *albedo),
        Source::Shell(shell) => world::world_grids(shell, rgba),
    };
    vec![
        Grid {
            name: "density".into(),
            class: GridClass::FogVolume,
            index_to_world: e.index_to_world,
            data: GridData::Float(density),
        },
        Grid {
            name: "Cd".into(),
            class: GridClass::Unknown,
            index_to_world: e.index_to_world,
            data: GridData::Vec3(colour),
        },
    ]
}

fn baked_grids(
    resolution: [u32; 3],
    opacity_length: f64,
    e: &Export,
    rgba: &[[f32; 4]],
) -> (Voxels<f32>, Voxels<[f32; 3]>) {
    let [nx, ny, _] = resolution;
    let at = |[i, j, k]: [u32; 3]| rgba[(k as usize * ny as usize + j as usize) * nx as usize + i as usize];
    let voxel = (0..3).map(|a| e.index_to_world.col(a).truncate().length()).fold(f64::INFINITY, f64::min);
    let opaque = density(1.0 - 2f64.powi(-20), opacity_length).max(-OPAQUE_TRANSMITTANCE.ln() / voxel);
    let first = [0; 3];
    let density = Voxels::from_dense(first, resolution, |ijk| {
        let a = at(ijk)[3] as f64;
        (a > 0.0).then(|| if a >= 1.0 { opaque } else { density(a, opacity_length).min(opaque) } as f32)
    });
    let colour = Voxels::from_dense(first, resolution, |ijk| {
        let [r, g, b, a] = at(ijk);
        (a > 0.0).then(|| [r / a, g / a, b / a])
    });
    (density, colour)
}

/// A volume object's grids, at the file's own voxels: `density` is the voxel's density times
/// `density_scale` in f32 (the product the kernel forms, so a re-import with scale 1 draws the
/// same extinction), active where it is not 0; `Cd` is `albedo` times the colour grid (white
/// without one), written at every voxel the brick of a leaf with density reaches, so that its
/// interpolant over the cells with density is the one the object was drawn with.
pub(crate) fn volume_grids(
    grid: &SparseVolume,
    density_scale: f64,
    albedo: [f32; 3],
) -> (Voxels<f32>, Voxels<[f32; 3]>) {
    use crate::vdb::sparse::{BRICK, BRICK_VALUES, LEAF};
    let scale = density_scale as f32;
    let (mut density, mut colour) = (Voxels::new(), Voxels::new());
    for (first, brick) in grid.leaf_bricks() {
        for n in 0..BRICK_VALUES {
            let local = glam::IVec3::new(
                (n % BRICK) as i32,
                (n / BRICK % BRICK) as i32,
                (n / (BRICK * BRICK)) as i32,
            );
            let ijk = (first + local).to_array();
            let at = brick * BRICK_VALUES + n;
            let d = grid.density[at];
            if local.max_element() < LEAF && d != 0.0 {
                density.set(ijk, d * scale);
            }
            let c = grid.color.as_ref().map_or([1.0; 3], |c| c[at]);
            colour.set(ijk, [0, 1, 2].map(|i| albedo[i] * c[i]));
        }
    }
    (density, colour)
}

/// Extinction per world unit of opacity `a` reached over `length`.
pub fn density(a: f64, length: f64) -> f64 {
    -(1.0 - a).ln() / length
}

/// Voxel `(i, j, k)` of `n` voxels filling the box `lo..hi` (cell-centred) to the box's space.
pub(crate) fn index_to_box(lo: DVec3, hi: DVec3, n: [u32; 3]) -> DMat4 {
    let voxel = (hi - lo) / DVec3::from_array(n.map(f64::from));
    DMat4::from_translation(lo + voxel / 2.0) * DMat4::from_scale(voxel)
}

/// Texel space `(s, t, w)` onto the object: the affine map that best fits every prism corner
/// (`(uv, 0)` to the base vertex, `(uv, 1)` to its tip), exact for a flat base surface with
/// constant height vectors and affine uvs (a plane). A curved shell has no such map: then one
/// tile at the world origin, scaled like the shell on average, and a note says so.
pub(crate) fn texel_frame(surface: &BaseSurface, object: &str) -> (DMat4, Option<String>) {
    let mut samples = Vec::new();
    for (tri, uvs) in surface.triangles.iter().zip(&surface.corner_uvs) {
        for k in 0..3 {
            let i = tri[k] as usize;
            let (p, h, uv) = (surface.positions[i], surface.heights[i], uvs[k]);
            samples.push((DVec4::new(uv.x, uv.y, 0.0, 1.0), p));
            samples.push((DVec4::new(uv.x, uv.y, 1.0, 1.0), p + h));
        }
    }
    let normal = samples.iter().fold(DMat4::ZERO, |m, (x, _)| m + outer(*x, *x));
    let rhs = samples.iter().fold(DMat4::ZERO, |m, (x, p)| m + outer(p.extend(0.0), *x));
    let size = samples.iter().map(|(_, p)| p.length()).fold(0.0, f64::max).max(1e-12);
    if normal.determinant().abs() > 1e-12 {
        // Round-off of the solve is cleared, so an axis-aligned tile stays a scale-translate map.
        let mut cols = (rhs * normal.inverse()).to_cols_array();
        cols.iter_mut().filter(|v| v.abs() < 1e-12 * size).for_each(|v| *v = 0.0);
        cols[15] = 1.0;
        let fit = DMat4::from_cols_array(&cols);
        let error = samples.iter().map(|(x, p)| ((fit * *x).truncate() - *p).length()).fold(0.0, f64::max);
        if error <= 1e-6 * size && fit.determinant().abs() > 1e-300 {
            return (fit, None);
        }
    }
    // Mean scales: world area over uv area for s and t, the mean height for w.
    let (st, height) = surface.mean_scale();
    let st = if st.is_finite() { st } else { 1.0 };
    let scale = DVec3::new(st, st, if height > 0.0 { height } else { st });
    let note = format!(
        "object \"{object}\"'s shell is curved: one tile at the world origin, {st:.4} x {st:.4} x {:.4} world units \
         (its mean scale)",
        scale.z
    );
    (DMat4::from_scale(scale), Some(note))
}

fn outer(a: DVec4, b: DVec4) -> DMat4 {
    DMat4::from_cols(a * b.x, a * b.y, a * b.z, a * b.w)
}

fn join(a: Option<String>, b: &str) -> String {
    match a {
        Some(a) => format!("{a}; {b}"),
        None => b.to_string(),
    }
}

/// The scene's view for other renderers (`voltex export --view`, read by `tools/peers/`): the
/// output size, the camera (a pinhole through pixel centres, `fov_y` the vertical field of view
/// in degrees), background, ambient term and lights (each travelling along `direction`), and the
/// files written.
pub fn view_json(scene: &Scene, exports: &[Export]) -> String {
    let cam = &scene.camera.value;
    let v = |d: DVec3| [d.x, d.y, d.z];
    let lights: Vec<_> = scene
        .lights
        .iter()
        .map(|l| match l {
            crate::scene::Light::Directional { direction, color, intensity } => serde_json::json!({
                "type": "directional", "direction": v(*direction), "color": color, "intensity": intensity,
            }),
        })
        .collect();
    let files: Vec<_> = exports
        .iter()
        .map(|e| serde_json::json!({ "file": format!("{}.vdb", e.name), "what": e.what }))
        .collect();
    let json = serde_json::json!({
        "scene": scene.path.display().to_string(),
        "width": scene.output.width,
        "height": scene.output.height,
        "camera": { "eye": v(cam.eye), "target": v(cam.target), "up": v(cam.up), "fov_y": cam.fov_y },
        "background": scene.background,
        "ambient": scene.ambient,
        "lights": lights,
        "files": files,
    });
    serde_json::to_string_pretty(&json).unwrap_or_default() + "\n"
}

/// The output file of `e` in `dir`.
pub fn path_in(dir: &Path, e: &Export) -> std::path::PathBuf {
    dir.join(format!("{}.vdb", e.name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn density_is_the_extinction_that_gives_back_the_opacity() {
        for (a, l) in [(0.5, 0.05), (0.01, 2.0), (0.999, 0.1)] {
            let sigma = density(a, l);
            // Transmittance over the opacity length is 1 - a; over half of it, sqrt(1 - a).
            assert!(((-sigma * l).exp() - (1.0 - a)).abs() < 1e-12);
            assert!(((-sigma * l / 2.0).exp() - (1.0 - a).sqrt()).abs() < 1e-12);
        }
    }

    #[test]
    fn a_plane_gives_its_exact_tile() {
        let mesh = crate::mesh::generate::plane([4.0, 2.0], [3, 2], 0.0, 0);
        let surface = mesh.to_base(0.5, None, glam::DVec2::new(2.0, 1.0));
        let (m, note) = texel_frame(&surface, "floor");
        assert!(note.is_none());
        // Tile (0, 0) starts at the plane's corner; s spans 4 / 2 world units, t 2, w 0.5.
        let p = |s: f64, t: f64, w: f64| m.transform_point3(DVec3::new(s, t, w));
        assert!((p(0.0, 0.0, 0.0) - DVec3::new(-2.0, -1.0, 0.0)).length() < 1e-9);
        assert!((p(1.0, 1.0, 1.0) - DVec3::new(0.0, 1.0, 0.5)).length() < 1e-9);
    }

    #[test]
    fn a_sphere_gets_its_mean_scale_and_a_note() {
        let mesh = crate::mesh::generate::sphere(1.0, [24, 12]);
        let surface = mesh.to_base(0.1, None, glam::DVec2::ONE);
        let (m, note) = texel_frame(&surface, "ball");
        assert!(note.unwrap().contains("curved"));
        // uv [0,1]^2 covers the sphere's area 4 pi (less at the poles' triangles): s and t
        // scale by about sqrt(4 pi).
        assert!((m.x_axis.x / (4.0 * std::f64::consts::PI).sqrt() - 1.0).abs() < 0.05, "{m}");
        assert!((m.z_axis.z - 0.1).abs() < 1e-9);
    }

    #[test]
    fn file_names_refuse_separators_and_dots() {
        assert_eq!(file_name("moss").unwrap(), "moss.vdb");
        for bad in ["", "..", ".hidden", "a/b", "a\\b", "c:d", "new\nline"] {
            assert!(file_name(bad).is_err(), "{bad:?}");
        }
    }
}
