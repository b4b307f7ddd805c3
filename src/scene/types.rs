//! Scene file types. Every struct and enum denies unknown fields; value checks live in `values`.

use super::values::{self as v, Mark};
use super::Method;
use glam::{DMat4, DQuat, DVec3, EulerRot};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A scene file (`Scene(...)`), parsed and checked by `scene::load`: output size, camera, lights,
/// the named texels, hypertextures and volumes, and the tree of nodes that draw them.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The scene file (not in the file; set by `load`). Relative paths resolve against its folder.
    #[serde(skip)]
    pub path: PathBuf,
    pub(crate) output: Output,
    /// Marked so that `load` can report a degenerate view (eye = target, up along the view).
    pub camera: Mark<Camera>,
    #[serde(default, deserialize_with = "v::color")]
    pub(crate) background: [f32; 3],
    #[serde(default = "default_ambient", deserialize_with = "v::unit_f32")]
    pub(crate) ambient: f32,
    #[serde(default)]
    pub(crate) lights: Vec<Light>,
    /// Texels by name, drawn by nodes with `texel: "name"` (and named as frames by `Sequence` ones).
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub texels: BTreeMap<String, Texel>,
    /// Hypertextures (Gilet & Dischler 2009) that nodes draw with `RayMarch`.
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub hypertextures: BTreeMap<String, super::hypertexture::Hypertexture>,
    /// Volumes read from OpenVDB files, drawn by nodes with `volume: "name"` or baked into
    /// texels (`TexelSource::Volume`).
    #[serde(default, deserialize_with = "crate::input::unique_keys")]
    pub volumes: BTreeMap<String, Volume>,
    /// The roots of the node tree; transforms compose parent times child.
    #[serde(default)]
    pub nodes: Vec<Node>,
    /// Time of the frame in seconds (animated hypertextures; `--time` overrides it).
    #[serde(default, deserialize_with = "v::finite")]
    pub(crate) time: f64,
    /// Extra images (AOVs) written as EXR channels beside the colour, by the names the graph
    /// declares (the default graph: `depth`, `coverage`, `transmittance`); `--aov` replaces it.
    #[serde(default)]
    pub(crate) aovs: Vec<String>,
    /// Settings of `voltex regress` runs: render size and pass thresholds.
    #[serde(default)]
    pub regress: Regress,
    /// OBJ meshes and height images loaded and checked by `load`, by resolved path.
    #[serde(skip)]
    pub(super) assets: super::validate::Assets,
    /// The file's text, to position errors found after parsing (e.g. by the prism checks).
    #[serde(skip)]
    pub(super) source: String,
    /// Where the file writes what planning may refuse (found when parsed).
    #[serde(skip)]
    pub(crate) locations: super::Locations,
    /// What loading found questionable but drew anyway (each names its file), for the user.
    #[serde(skip)]
    pub warnings: Vec<String>,
}

fn default_ambient() -> f32 {
    0.2
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Output {
    #[serde(deserialize_with = "v::output_size")]
    pub(crate) width: u32,
    #[serde(deserialize_with = "v::output_size")]
    pub(crate) height: u32,
}

/// `regress: (size: (128, 128), max_flip: 0.01, max_rel_rmse: 0.02)`, every field optional.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Regress {
    /// Render size of regression runs (width, height; default: `output`).
    #[serde(default, deserialize_with = "v::opt_size2")]
    pub size: Option<[u32; 2]>,
    /// Largest mean FLIP (tonemapped, 0..=1) against the reference that passes.
    #[serde(default = "default_max_flip", deserialize_with = "v::unit")]
    pub max_flip: f64,
    /// Largest relative RMSE (linear HDR) against the reference that passes.
    #[serde(default = "default_max_rel_rmse", deserialize_with = "v::non_negative")]
    pub max_rel_rmse: f64,
    /// The error bound against an independent truth (see [`Truth`]).
    #[serde(default)]
    pub truth: Option<Truth>,
    /// Samples per pixel axis of the regression render and its truth (1..=8): each pixel is the
    /// mean of N x N samples, so a scene whose detail is finer than a pixel at `size` is checked
    /// on pixel averages, not on where single samples happen to land.
    #[serde(default = "default_supersample", deserialize_with = "v::supersample")]
    pub(crate) supersample: u32,
}

/// `truth: (max_flip: 0.05)`: the scene rendered as its truth (textured objects by the exact
/// Reference method; hypertextures ray-marched at `step_scale` times their step, without
/// adaptive stride or segments) at the regress size; the render must be within `max_flip`
/// mean FLIP of it, or `voltex regress` fails the scene and `--update` writes no reference.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    #[serde(deserialize_with = "v::unit")]
    pub(crate) max_flip: f64,
    /// RayMarch objects' step in the truth, as a fraction of theirs.
    #[serde(default = "default_step_scale", deserialize_with = "v::positive")]
    pub(crate) step_scale: f64,
}

fn default_step_scale() -> f64 {
    0.25
}

fn default_supersample() -> u32 {
    1
}

fn default_max_flip() -> f64 {
    0.01
}
fn default_max_rel_rmse() -> f64 {
    0.02
}

impl Default for Regress {
    fn default() -> Self {
        Regress {
            size: None,
            max_flip: default_max_flip(),
            max_rel_rmse: default_max_rel_rmse(),
            truth: None,
            supersample: default_supersample(),
        }
    }
}

/// `camera: (eye, target, up, fov_y)`: a pinhole camera looking from `eye` at `target`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// The camera's position, world space.
    #[serde(deserialize_with = "v::vec3")]
    pub eye: DVec3,
    /// The point looked at, world space; must differ from `eye`.
    #[serde(deserialize_with = "v::vec3")]
    pub target: DVec3,
    #[serde(default = "default_up", deserialize_with = "v::direction")]
    pub(crate) up: DVec3,
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov", deserialize_with = "v::fov")]
    pub fov_y: f64,
}

impl Camera {
    /// The camera turned by `degrees` about its up axis through its target: one step of an
    /// orbit (the preview's left drag; `pareto`'s and `bench`'s orbit times).
    pub(crate) fn orbited(&self, degrees: f64) -> Camera {
        let turn = DQuat::from_axis_angle(self.up.normalize(), degrees.to_radians());
        Camera { eye: self.target + turn * (self.eye - self.target), ..*self }
    }
}

fn default_up() -> DVec3 {
    DVec3::Z
}
fn default_fov() -> f64 {
    45.0
}

/// A light of `lights`; baked lighting uses the scene's first.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Light {
    /// Light travelling along `direction` (world space, not normalised in the file).
    Directional {
        /// Where the light travels, world space (non-zero).
        #[serde(deserialize_with = "v::direction")]
        direction: DVec3,
        /// Linear RGB, each >= 0 (default `(1, 1, 1)`).
        #[serde(default = "white", deserialize_with = "v::light_color")]
        color: [f32; 3],
        /// Factor on `color`, >= 0 (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::non_negative_f32")]
        intensity: f32,
    },
}

fn white() -> [f32; 3] {
    [1.0; 3]
}
fn one_f32() -> f32 {
    1.0
}

/// A pattern volume over texture space `[0, 1]^3` (s, t tile; w is height).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Texel {
    /// Voxels along s, t and w, each 1..=1024 (sources add their own limits).
    #[serde(deserialize_with = "v::resolution")]
    pub resolution: [u32; 3],
    /// World length over which a voxel's stored alpha is reached (see [`Texel::opacity_length`]).
    #[serde(default, rename = "opacity_length", deserialize_with = "v::opt_positive_f32")]
    pub(crate) opacity_length_given: Option<f32>,
    /// What fills the pattern volume.
    pub source: TexelSource,
    /// Self-shadowing baked into the texel's colour (off when absent).
    #[serde(default)]
    pub shadow: Option<TexelShadow>,
}

/// `shadow: (extinction: 40.0)`: every voxel's colour scaled by `ambient + (1 - ambient) T`, `T`
/// the transmittance from its centre towards a light fixed at bake time through the texel's
/// own opacity (extinction `extinction * alpha` per texel unit: the box is 1 high), wrapping
/// across the tile's s and t edges and leaving through its top or bottom (Meyer & Neyret 1998,
/// 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TexelShadow {
    /// Optical depth of one texel unit of alpha-1 matter.
    #[serde(deserialize_with = "v::positive_f32")]
    pub extinction: f32,
    /// The direction the light travels, in texel space (s, t, w); default: the scene's first
    /// light's, taken in texel space as the baked shading takes it.
    #[serde(default, deserialize_with = "v::opt_direction")]
    pub direction: Option<DVec3>,
    /// Light kept in full shadow, in `[0, 1]`.
    #[serde(default, deserialize_with = "v::unit_f32")]
    pub ambient: f32,
    /// Voxels the march skips from each voxel's centre before it counts opacity, so that a
    /// voxelised surface does not shadow itself on its own steps (0 to 8).
    #[serde(default = "default_shadow_bias", deserialize_with = "v::shadow_bias")]
    pub bias: f32,
}

fn default_shadow_bias() -> f32 {
    1.5
}

/// A texel's opacity length when the file gives none (and its source has no length of its own).
pub(crate) const DEFAULT_OPACITY_LENGTH: f32 = 0.05;

impl Texel {
    /// The world length over which a voxel's stored alpha is reached: as given, else for a
    /// hypertexture source the hypertexture's own opacity length (a baked voxel stores the
    /// transfer function's opacity, which RayMarch reaches over that world length), else
    /// `DEFAULT_OPACITY_LENGTH`.
    pub fn opacity_length(&self, hypertextures: &BTreeMap<String, super::Hypertexture>) -> f32 {
        let own = match &self.source {
            TexelSource::Hypertexture { name, .. } => {
                hypertextures.get(&name.value).map(|h| h.opacity_length as f32)
            }
            _ => None,
        };
        self.opacity_length_given.or(own).unwrap_or(DEFAULT_OPACITY_LENGTH)
    }
}

/// What a texel is baked from (`source:` of a [`Texel`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TexelSource {
    /// Union of implicit shapes: each voxel takes colour, opacity and normal from the shape
    /// nearest to it (the deepest where they overlap; the first listed on a tie).
    Implicit {
        /// The shapes of the union, in texel space.
        shapes: Vec<Shape>,
    },
    /// Periodic Perlin height field: voxel filled where `w < base + amplitude * noise(s, t)`,
    /// colour from `color_low` (w = 0) to `color_high` (w = base + amplitude, the highest
    /// possible height).
    PerlinHeight {
        /// Lattice cells of the noise per tile, 1..=1024.
        #[serde(deserialize_with = "v::frequency")]
        frequency: u32,
        /// fBm octaves, 1..=8 (default 1).
        #[serde(default = "one_u32", deserialize_with = "v::octaves")]
        octaves: u32,
        /// Height range of the noise above `base` (texel units, finite).
        #[serde(deserialize_with = "v::finite_f32")]
        amplitude: f32,
        /// Lowest height, where the noise is at its minimum (texel units, finite).
        #[serde(deserialize_with = "v::finite_f32")]
        base: f32,
        /// Seed of the noise's permutation (default 0).
        #[serde(default)]
        seed: u32,
        /// Linear RGB at `w = 0`.
        #[serde(deserialize_with = "v::color")]
        color_low: [f32; 3],
        /// Linear RGB at the highest possible height.
        #[serde(deserialize_with = "v::color")]
        color_high: [f32; 3],
        /// Opacity of filled voxels, in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
        /// Albedo darkened with depth: times `1 - darkening * (top - w) / top`, `top` the highest
        /// possible height (grooves read darker).
        #[serde(default, deserialize_with = "v::unit_f32")]
        darkening: f32,
    },
    /// Height field from a grey-level PNG (Meyer & Neyret 1998, 3.2): voxel filled where
    /// `w < base + amplitude * image(s, t)`, the image sampled bilinearly with wrapping (t = 0 is
    /// its bottom row) and its slopes by central differences one pixel apart.
    ImageHeight {
        /// The PNG or EXR file, relative to the scene file.
        image: Mark<String>,
        /// Channel of the image holding the height (0 for grey images).
        #[serde(default)]
        channel: u32,
        /// Height at image value 1 above `base` (texel units, finite).
        #[serde(deserialize_with = "v::finite_f32")]
        amplitude: f32,
        /// Height at image value 0 (texel units, finite; default 0).
        #[serde(default, deserialize_with = "v::finite_f32")]
        base: f32,
        /// Linear RGB at `w = 0`.
        #[serde(deserialize_with = "v::color")]
        color_low: [f32; 3],
        /// Linear RGB at the highest possible height.
        #[serde(deserialize_with = "v::color")]
        color_high: [f32; 3],
        /// Opacity of filled voxels, in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
        /// Albedo darkened with depth, in [0, 1] (default 0), as for `PerlinHeight`.
        #[serde(default, deserialize_with = "v::unit_f32")]
        darkening: f32,
    },
    /// A slice stack written by `voltex bake` (one RGBA PNG per `w` slice, premultiplied, shading
    /// baked in): the texel's `resolution` must be the stack's. Drawn with baked lighting only.
    Slices {
        /// The folder `voltex bake` wrote (slices and `manifest.json`), relative to the scene file.
        dir: Mark<String>,
    },
    /// Cycling volume sequence (Meyer & Neyret 1998, section 5): at time `t` the texel is
    /// `texels[floor(t * fps) mod n]`, each frame a texel of this map with this resolution.
    Sequence {
        /// Names of the frame texels, of this texel's resolution and not sequences themselves.
        #[serde(deserialize_with = "v::frames")]
        texels: Vec<Mark<String>>,
        /// Frames per second of scene time, > 0.
        #[serde(deserialize_with = "v::positive")]
        fps: f64,
    },
    /// A pattern mesh (Meyer & Neyret 1998, section 3.2): the OBJ at `path` inside the box
    /// `bounds` (object space of the OBJ), which maps onto texel space `[0, 1]^3`. Each voxel samples
    /// the mesh at its centre (`bake_mesh_grid.wgsl`, ray parity voted over three directions):
    /// `fill` covers the inside (a closed mesh is needed: an open one falls back to the shell
    /// with a warning); `fill: false` draws a one-voxel shell around the surface (sparse
    /// patterns, leaves; no inside test). Any resolution of at least 2 voxels per axis and at
    /// most 2^24 in all.
    Mesh {
        /// The OBJ or glTF file, relative to the scene file.
        path: Mark<String>,
        /// The box of the mesh's object space that maps onto texel space.
        bounds: Mark<MeshBounds>,
        /// Linear RGB, tinting the OBJ's vertex colours if it has any (default white).
        #[serde(default = "white", deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity of the covered voxels, in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
        /// Fill the inside (default); `false`: a one-voxel shell around the surface.
        #[serde(default = "yes")]
        fill: bool,
    },
    /// A hypertexture of `hypertextures` (Meyer & Neyret 1998, 3.3) sampled at the voxel centres
    /// of the box `bounds` of its object space (default: its enlarged bounds, every detail
    /// inside), which maps onto texel space `[0, 1]^3`: colour and opacity from its transfer
    /// function, shading from its density gradient (`bake_hypertexture.wgsl`). Animated noises
    /// are baked at the scene's time. The texel's `opacity_length` is the hypertexture's (both
    /// are world lengths, and a voxel stores the transfer function's opacity): drawn at any
    /// scale, the texel is as opaque as RayMarch draws the hypertexture at that scale. Another
    /// length given in the file is used, with a warning.
    Hypertexture {
        /// A key of the scene's `hypertextures`.
        name: Mark<String>,
        /// The box of its object space that maps onto texel space (default: its enlarged bounds).
        #[serde(default)]
        bounds: Option<Mark<MeshBounds>>,
    },
    /// A volume of `volumes` sampled at the voxel centres of the box `bounds` of its world
    /// space (default: the box its density fills), which maps onto texel space `[0, 1]^3`:
    /// colour `albedo * color`, opacity `1 - exp(-density * density_scale * opacity_length)`
    /// (`bake_volume.wgsl`), so that drawn at any place the texel absorbs as the volume would
    /// per world unit there.
    Volume {
        /// A key of the scene's `volumes`.
        name: Mark<String>,
        /// The box of its world space that maps onto texel space (default: the box its density fills).
        #[serde(default)]
        bounds: Option<Mark<MeshBounds>>,
    },
    /// A uniform volume (analytic tests).
    Constant {
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity of every voxel, in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
    },
}

/// A volume from an OpenVDB file: the float grid `grid` (a fog volume's densities, or a level
/// set's signed distances turned into density: 1 inside, 0 outside, linear over `band` voxels
/// across the surface), times `density_scale`, is the extinction coefficient per world unit
/// (Blender's, Houdini's and Mitsuba's convention); the light it scatters is `albedo` times the
/// vec3 grid `color` (Houdini's `Cd`; white without one). `albedo: (0, 0, 0)` is a purely
/// absorbing, black medium.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Volume {
    /// The `.vdb` file, relative to the scene file.
    pub(crate) file: Mark<String>,
    #[serde(default = "default_grid")]
    pub(crate) grid: String,
    #[serde(default)]
    pub(crate) color: Option<String>,
    /// Extinction per unit density per world unit, > 0 (default 1).
    #[serde(default = "one_f64", deserialize_with = "v::positive")]
    pub density_scale: f64,
    /// Linear RGB in [0, 1] scaling the scattered light (default white; black absorbs only).
    #[serde(default = "white", deserialize_with = "v::color")]
    pub albedo: [f32; 3],
    /// Level sets: the width, in voxels, of the band over which density falls from 1 to 0.
    #[serde(default = "one_f64", deserialize_with = "v::positive")]
    pub(crate) band: f64,
}

fn default_grid() -> String {
    "density".into()
}

/// `(lo: (x, y, z), hi: (x, y, z))`: a box of a mesh's object space.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshBounds {
    /// The box's lowest corner.
    #[serde(deserialize_with = "v::vec3")]
    pub lo: DVec3,
    /// The box's highest corner, above `lo` on every axis.
    #[serde(deserialize_with = "v::vec3")]
    pub hi: DVec3,
}

fn one_u32() -> u32 {
    1
}

/// Implicit shapes in texel space `[0, 1]^3`; colours linear RGB in `[0, 1]`; opacity in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Shape {
    /// A solid sphere.
    Sphere {
        /// Centre, texel space.
        #[serde(deserialize_with = "v::point_f32")]
        center: [f32; 3],
        /// Radius, texel units, > 0.
        #[serde(deserialize_with = "v::positive_f32")]
        radius: f32,
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
    },
    /// Axis along w.
    Torus {
        /// Centre, texel space.
        #[serde(deserialize_with = "v::point_f32")]
        center: [f32; 3],
        /// Radius of the ring through the tube's centre, texel units, > 0 and above `minor`.
        #[serde(deserialize_with = "v::positive_f32")]
        major: f32,
        /// Radius of the tube, texel units, > 0.
        #[serde(deserialize_with = "v::positive_f32")]
        minor: f32,
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
    },
    /// An axis-aligned ellipsoid.
    Ellipsoid {
        /// Centre, texel space.
        #[serde(deserialize_with = "v::point_f32")]
        center: [f32; 3],
        /// Semi-axes along s, t and w, texel units, each > 0.
        #[serde(deserialize_with = "v::radii_f32")]
        radii: [f32; 3],
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
    },
    /// Inside where `sum (radius_i / |x - center_i|)^2 >= threshold`.
    Metaballs {
        /// The balls `(center, radius)` whose fields add up.
        balls: Vec<Ball>,
        /// Iso-value of the summed field, > 0.
        #[serde(deserialize_with = "v::positive_f32")]
        threshold: f32,
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity in [0, 1] (default 1).
        #[serde(default = "one_f32", deserialize_with = "v::unit_f32")]
        opacity: f32,
    },
}

/// One ball of `Shape::Metaballs`: `(center, radius)` in texel space.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ball {
    #[serde(deserialize_with = "v::point_f32")]
    pub(crate) center: [f32; 3],
    #[serde(deserialize_with = "v::positive_f32")]
    pub(crate) radius: f32,
}

/// A node of the scene tree: a base surface with a texel and a method, a hypertexture, a volume,
/// an opaque base surface alone, or a group for its children.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Node {
    /// Names the object in errors, metadata and the preview (Latin-1, at most 241 bytes).
    #[serde(deserialize_with = "v::object_name")]
    pub name: String,
    #[serde(default)]
    pub(crate) transform: Transform,
    #[serde(default)]
    pub(crate) surface: Option<Mark<Surface>>,
    #[serde(default)]
    pub(crate) height: Height,
    /// Texture repeats over the surface's uv tile (u, v).
    #[serde(default = "one2", deserialize_with = "v::positive2")]
    pub(crate) uv_tiling: [f64; 2],
    #[serde(default)]
    pub(crate) texel: Option<Mark<String>>,
    /// A hypertexture drawn in this node's frame (instead of a surface with a texel).
    #[serde(default)]
    pub(crate) hypertexture: Option<Mark<String>>,
    /// A volume of `volumes` drawn in this node's frame (its grid's index-to-world transform,
    /// then the node's), with `RayMarch` (the default) or `Reference`.
    #[serde(default)]
    pub(crate) volume: Option<Mark<String>>,
    /// How the node's texel, hypertexture or volume is drawn (none: a textured node draws only
    /// its base surface; hypertexture and volume nodes use `RayMarch`).
    #[serde(default)]
    pub method: Option<Mark<Method>>,
    /// Draw the base surface opaque with this colour.
    #[serde(default, deserialize_with = "v::opt_color")]
    pub(crate) base_color: Option<[f32; 3]>,
    /// Animation of the base surface and height vectors with the scene time.
    #[serde(default)]
    pub(crate) motion: Motion,
    /// Nodes placed in this node's frame.
    #[serde(default)]
    pub children: Vec<Node>,
}

fn one2() -> [f64; 2] {
    [1.0; 2]
}

/// `translate * rotate * scale`; `rotate` is Euler XYZ in degrees.
/// Meyer & Neyret's animation modes: a wave deforming the base surface, wind swaying the height
/// vectors (see `mesh::motion`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Motion {
    #[serde(default)]
    pub(crate) wave: Option<WaveMotion>,
    #[serde(default)]
    pub(crate) wind: Option<WindMotion>,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WaveMotion {
    #[serde(deserialize_with = "v::finite")]
    pub(crate) amplitude: f64,
    #[serde(deserialize_with = "v::positive")]
    pub(crate) wavelength: f64,
    #[serde(default, deserialize_with = "v::finite")]
    pub(crate) speed: f64,
    #[serde(deserialize_with = "v::direction")]
    pub(crate) direction: DVec3,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WindMotion {
    /// Lean as a fraction of the height vector's length, in [0, 1].
    #[serde(deserialize_with = "v::unit")]
    pub(crate) strength: f64,
    #[serde(default, deserialize_with = "v::finite")]
    pub(crate) frequency: f64,
    #[serde(deserialize_with = "v::positive")]
    pub(crate) wavelength: f64,
    #[serde(deserialize_with = "v::direction")]
    pub(crate) direction: DVec3,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Transform {
    #[serde(default, deserialize_with = "v::vec3")]
    pub(crate) translate: DVec3,
    #[serde(default, deserialize_with = "v::vec3")]
    pub(crate) rotate: DVec3,
    #[serde(default = "one3", deserialize_with = "v::scale3")]
    pub(crate) scale: DVec3,
}

fn one3() -> DVec3 {
    DVec3::ONE
}

impl Default for Transform {
    fn default() -> Self {
        Transform { translate: DVec3::ZERO, rotate: DVec3::ZERO, scale: DVec3::ONE }
    }
}

impl Transform {
    pub(crate) fn matrix(&self) -> DMat4 {
        let r = self.rotate * std::f64::consts::PI / 180.0;
        DMat4::from_scale_rotation_translation(
            self.scale,
            DQuat::from_euler(EulerRot::XYZ, r.x, r.y, r.z),
            self.translate,
        )
    }
}

/// A node's base surface (`surface:`), in the node's object space.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Surface {
    /// Grid in the xy plane centred at the origin, normal +z.
    Plane {
        /// Extent along x and y, > 0.
        #[serde(deserialize_with = "v::positive2")]
        size: [f64; 2],
        /// Grid cells along x and y, 1..=4096 each.
        #[serde(deserialize_with = "v::cells")]
        cells: [u32; 2],
        /// Fraction of a cell by which interior vertices move.
        #[serde(default, deserialize_with = "v::jitter")]
        jitter: f64,
        /// Seed of the jitter (default 0).
        #[serde(default)]
        seed: u32,
    },
    /// UV sphere around the origin; segments = (around z, pole to pole).
    Sphere {
        /// Radius, > 0.
        #[serde(deserialize_with = "v::positive")]
        radius: f64,
        /// Segments around z (3..=4096) and from pole to pole (2..=4096).
        #[serde(deserialize_with = "v::sphere_segments")]
        segments: [u32; 2],
    },
    /// Torus around z; segments = (around z, around the tube).
    Torus {
        /// Radius of the ring through the tube's centre, > 0.
        #[serde(deserialize_with = "v::positive")]
        major: f64,
        /// Radius of the tube, > 0 and below `major`.
        #[serde(deserialize_with = "v::positive")]
        minor: f64,
        /// Segments around z and around the tube, 3..=4096 each.
        #[serde(deserialize_with = "v::torus_segments")]
        segments: [u32; 2],
        /// Smooth bumps on the tube radius, a fraction of `minor` in [0, 0.9) (default 0).
        #[serde(default, deserialize_with = "v::distortion")]
        distortion: f64,
        /// Seed of the bumps' phase (default 0).
        #[serde(default)]
        seed: u32,
    },
    /// A mesh file, path relative to the scene file: Wavefront OBJ, or glTF (`.gltf`, `.glb`).
    /// `Obj(path)`, its first name, still reads as this.
    #[serde(alias = "Obj")]
    Mesh {
        /// The OBJ, `.gltf` or `.glb` file.
        path: Mark<String>,
    },
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Height {
    #[serde(default = "default_height", deserialize_with = "v::non_negative")]
    pub(crate) length: f64,
    #[serde(default)]
    pub(crate) scale: Option<Mark<HeightScale>>,
}

fn default_height() -> f64 {
    0.1
}

impl Default for Height {
    fn default() -> Self {
        Height { length: default_height(), scale: None }
    }
}

/// Per-vertex factor in `[0, 1]` on the height length.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum HeightScale {
    /// OBJ only: the first colour channel of `v x y z r g b` lines.
    VertexAttribute,
    /// PNG (grey, grey+alpha, RGB, RGBA), sampled bilinearly with wrapping at the vertex uv
    /// (before tiling); v = 0 is the bottom row.
    Texture {
        /// The PNG or EXR file, relative to the scene file.
        path: Mark<String>,
        /// The image channel holding the factor (default 0).
        #[serde(default)]
        channel: u32,
    },
}

/// Shading of a hypertexture: the transfer function's colour as is, Phong with the density
/// gradient by central differences, Phong with shadow rays towards the light, or volumetric
/// lighting by a Henyey-Greenstein phase function (no normal: the paper's section 3 alternative).
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub enum Shading {
    /// The transfer function's colour, unlit.
    #[default]
    None,
    /// Phong shading with the density gradient (central differences) as the normal.
    Phong,
    /// Phong shading times the transmittance towards the light (`shadows` says how it is found).
    PhongShadows,
    /// Single scattering of the light with the phase function `p_HG(g, cos)`: the colour is the
    /// transfer's times `ambient + (1 - ambient) 4 pi p_HG` (so `g: 0`, isotropic, is the
    /// unshaded colour), times the transmittance towards the light with `shadows`. `g` in
    /// (-1, 1): above 0 forward scattering (bright towards the light), below 0 backward.
    HenyeyGreenstein {
        /// Anisotropy in (-1, 1): above 0 forward scattering, below 0 backward, 0 isotropic.
        #[serde(deserialize_with = "v::anisotropy")]
        g: f64,
        /// Multiply by the transmittance towards the light along a shadow ray (default `false`).
        #[serde(default)]
        shadows: bool,
    },
}

fn yes() -> bool {
    true
}

fn one_f64() -> f64 {
    1.0
}

/// Where a textured object's shading comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub enum Lighting {
    /// Colour as baked in the texel.
    #[default]
    Baked,
    /// Shaded per pixel with the texel's normals and the scene lights.
    PerPixel,
}
