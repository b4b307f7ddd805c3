//! Structs shared with WGSL. Mirrored in `wgsl/shared/types.wgsl`; `tests/checks/types_layout.rs` checks
//! that sizes and field offsets agree (naga reflection against these Rust layouts).

use bytemuck::{Pod, Zeroable};

/// One base-surface vertex of a shell: the bottom `p` and top `p + h`, camera-relative (f32 after
/// subtracting the camera position in f64). `w` components are 1.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ShellVertex {
    /// xyz: camera-relative bottom vertex `p`; w: 1.
    pub bottom: [f32; 4],
    /// xyz: camera-relative top vertex `p + h`; w: 1.
    pub top: [f32; 4],
}

/// One prism: three welded vertex ids (shared edges are recognised by these ids) and the texture
/// coordinates of its corners (per corner, so uv seams need no duplicated positions). Nothing of
/// the view: a camera move reuses the prisms and remakes only the camera-relative vertices and
/// bounding spheres (`mesh::shell::Shell`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct Prism {
    /// xyz: vertex ids into the `ShellVertex` array; w: unused.
    pub vertices: [u32; 4],
    /// uv of corner 0 (xy) and corner 1 (zw).
    pub uv01: [f32; 4],
    /// uv of corner 2 (xy); zw unused.
    pub uv2: [f32; 4],
}

/// Per-object, per-frame parameters of view-aligned slicing.
/// Plane `k` (0 = back-most) is `dot(plane_normal, x) = first_plane - k * spacing`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SliceParams {
    /// xyz: unit plane normal (the camera's forward direction); w: unused.
    pub plane_normal: [f32; 4],
    /// Plane offset along `plane_normal` of the back-most plane (`k = 0`).
    pub first_plane: f32,
    /// Distance between consecutive planes (world units).
    pub spacing: f32,
    /// Planes to slice with.
    pub plane_count: u32,
    /// Prisms of the object's shell.
    pub prism_count: u32,
    /// Capacity of the slice-vertex buffer, in vertices.
    pub vertex_capacity: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad: [u32; 3],
}

/// One vertex of a slice polygon, triangulated as a fan into a triangle list.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SliceVertex {
    /// Camera-relative position (xyz); w holds the prism index (as f32 bits, `bitcast<u32>`).
    pub position: [f32; 4],
    /// Texel coordinates (s, t, w); w component unused.
    pub uvw: [f32; 4],
}

/// Arguments of `draw_indirect`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct DrawIndirect {
    /// Vertices per instance.
    pub vertex_count: u32,
    /// Instances to draw.
    pub instance_count: u32,
    /// First vertex drawn.
    pub first_vertex: u32,
    /// First instance drawn.
    pub first_instance: u32,
}

/// Screen tiles of a `Tiles` compositor (uniform `tile_params`): tiles of 8 x 8 pixels, each
/// with one list segment per block of 32 planes (`src/methods/view_slices/tiles.rs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TileParams {
    /// Tiles across the frame.
    pub tiles_x: u32,
    /// Tiles down the frame.
    pub tiles_y: u32,
    /// Blocks of 32 planes of the chunk: segments per tile.
    pub blocks: u32,
    /// Entries the tile lists hold; a segment past it is composited from its planes' triangles.
    pub entry_capacity: u32,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad: [u32; 2],
}

/// One slice triangle binned into tiles (`wgsl/shared/tiles.wgsl`): its edges in pixels (y
/// down) as `x, y, constant` oriented so its inside is positive, with `w` 1 when the inside owns
/// pixel centres on the edge (top-left rule), else -1; the inclusive tile range its bounding box
/// meets (`x0 > x1`: none); the depth of its plane as the rasteriser tests it, and its plane.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TileTriangle {
    /// First edge `(x, y, constant, owns)`.
    pub e0: [f32; 4],
    /// Second edge, as `e0`.
    pub e1: [f32; 4],
    /// Third edge, as `e0`.
    pub e2: [f32; 4],
    /// Inclusive tile range its bounding box meets: `x0, y0, x1, y1` (`x0 > x1`: none).
    pub tiles: [u32; 4],
    /// Depth of its plane as the rasteriser tests it.
    pub depth: f32,
    /// Index of its slicing plane.
    pub plane: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad: [u32; 2],
}

/// Texel coordinates over a binned triangle as an affine function of the pixel position
/// (`wgsl/shared/tiles.wgsl`): at corner a (xyz) with a's pixel x (w), their steps per pixel in x
/// (xyz) with a's pixel y (w), and in y.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TileAttributes {
    /// Texel coordinates at corner a (xyz); a's pixel x (w).
    pub at_a: [f32; 4],
    /// Texel coordinates' step per pixel in x (xyz); a's pixel y (w).
    pub d_x: [f32; 4],
    /// Texel coordinates' step per pixel in y (xyz); w unused.
    pub d_y: [f32; 4],
}

/// Per-frame parameters (uniform `frame`). Positions are camera-relative, so `view_proj` has no
/// translation.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct FrameParams {
    /// Camera-relative world to clip space (column-major).
    pub view_proj: [[f32; 4]; 4],
    /// xyz: unit camera forward; w: near plane distance.
    pub forward: [f32; 4],
    /// xyz: unit direction towards the light; w: ambient term.
    pub light_dir: [f32; 4],
    /// rgb: light colour times intensity.
    pub light_color: [f32; 4],
    /// rgb: linear background colour.
    pub background: [f32; 4],
    /// width, height, 1/width, 1/height.
    pub viewport: [f32; 4],
}

/// Per-object draw parameters (uniform `object`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ObjectParams {
    /// rgb: base-surface colour.
    pub base_color: [f32; 4],
    /// World length over which a voxel's stored opacity is reached.
    pub opacity_length: f32,
    /// The object's index in the scene (its slot in per-object AOVs such as coverage).
    pub index: u32,
    pub(crate) _pad: [f32; 2],
}

/// Texel-to-world derivatives at a welded vertex, `dP/ds` and `dP/dt` (w unused), averaged over
/// its triangles: per-pixel lighting interpolates them so normals vary smoothly across prisms.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct VertexFrame {
    /// xyz: `dP/ds`; w unused.
    pub ds: [f32; 4],
    /// xyz: `dP/dt`; w unused.
    pub dt: [f32; 4],
}

/// One corner of a base-surface triangle, for the opaque base pass (3 per triangle).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct BaseVertex {
    /// Camera-relative position (xyz), w = 1.
    pub position: [f32; 4],
    /// Unit normal (xyz), w = 0.
    pub normal: [f32; 4],
}

/// Parameters shared by the bake kernels (`bake_implicit.wgsl`, `bake_heightfield.wgsl`).
/// Mirrored as `BakeParams` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct BakeParams {
    /// xyz: volume resolution in voxels; w: number of shapes used (implicit bake only).
    pub resolution: [u32; 4],
    /// xyz: texel-space direction towards the light (normalized by the kernel); w: ambient in `[0, 1]`.
    pub light: [f32; 4],
}

/// One implicit shape of a union, in texel space. Mirrored as `ImplicitShape` in
/// `wgsl/shared/types.wgsl`. `kind` is one of the `cpu::bake::{SPHERE, TORUS, ...}` constants.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ImplicitShape {
    /// Which shape: one of the `cpu::bake::{SPHERE, TORUS, ...}` constants.
    pub kind: u32,
    /// Metaballs only: the range `first_ball..first_ball + ball_count` of the `balls` buffer.
    pub first_ball: u32,
    /// Metaballs only: how many balls from `first_ball`.
    pub ball_count: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad: u32,
    /// xyz: centre (unused by metaballs and constant); w: unused.
    pub center: [f32; 4],
    /// Sphere: x radius. Torus: x major, y minor radius (axis along w). Ellipsoid: xyz radii.
    /// Metaballs: x threshold.
    pub params: [f32; 4],
    /// rgb: albedo; a: opacity per opacity length.
    pub color: [f32; 4],
}

/// A periodic Perlin height field. Mirrored as `HeightfieldParams` in `wgsl/shared/types.wgsl`.
/// Height `h(s,t) = base + amplitude * (0.5 + 0.5 * fbm(s,t))`, fbm in [-1,1].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HeightfieldParams {
    /// Lattice cells per tile along s and t of the first octave (>= 1).
    pub frequency: u32,
    /// Octaves (each doubles the frequency, halves the amplitude); clamped to 1..=16.
    pub octaves: u32,
    /// Seed of the noise's permutation.
    pub seed: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad0: u32,
    /// Height range of the noise above `base` (texel units).
    pub amplitude: f32,
    /// Lowest height, where the noise is at its minimum (texel units).
    pub base: f32,
    /// Opacity per opacity length of the filled region.
    pub opacity: f32,
    /// Darkening with depth (Meyer & Neyret 3.2): albedo times `1 - darkening * (top - w) / top`,
    /// `top` the highest possible height.
    pub darkening: f32,
    /// rgb: albedo at w = 0; a: unused.
    pub color_low: [f32; 4],
    /// rgb: albedo at w = base + amplitude (the highest possible height); a: unused.
    pub color_high: [f32; 4],
}

/// A height field from a grey-level image (`heights`, row-major from the top row, values in
/// `[0, 1]`). Mirrored as `HeightImageParams` in `wgsl/shared/types.wgsl`. Height
/// `h(s,t) = base + amplitude * image(s,t)`, bilinear with wrapping.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HeightImageParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad0: [u32; 2],
    /// Height at image value 1 above `base` (texel units).
    pub amplitude: f32,
    /// Height at image value 0 (texel units).
    pub base: f32,
    /// Opacity per opacity length of the filled region.
    pub opacity: f32,
    /// Darkening with depth, as in [`HeightfieldParams::darkening`].
    pub darkening: f32,
    /// rgb: albedo at w = 0; a: unused.
    pub color_low: [f32; 4],
    /// rgb: albedo at the highest possible height; a: unused.
    pub color_high: [f32; 4],
}

/// Camera of the reference tracer (uniform `reference_params`). A pixel's ray is
/// `forward + sx right + sy up` with `sx, sy` in [-1, 1].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ReferenceParams {
    /// xyz: camera right scaled by the half-width at unit distance; w: near plane distance.
    pub right: [f32; 4],
    /// xyz: camera up scaled by the half-height at unit distance; w: far plane distance.
    pub up: [f32; 4],
    /// x: BVH node count; y: prism count; z: object count; w: ShellMarch: 1 where empty space
    /// is skipped.
    pub counts: [u32; 4],
}

/// A node of the BVH over prism bounds (obvhs's BVH2, flattened). Inner nodes have their children
/// at `first` and `first + 1`; leaves hold the prisms `first..first + count`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ReferenceNode {
    /// xyz: box minimum (camera-relative); w: prism count as u32 bits (0 for inner nodes).
    pub min: [f32; 4],
    /// xyz: box maximum; w: `first` as u32 bits.
    pub max: [f32; 4],
}

/// A prism of a Reference object, in BVH leaf order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ReferencePrism {
    /// xyz: vertex ids into the frame's concatenated shell vertices; w: object index.
    pub vertices: [u32; 4],
    /// uv of corner 0 (xy) and corner 1 (zw).
    pub uv01: [f32; 4],
    /// uv of corner 2 (xy); zw unused.
    pub uv2: [f32; 4],
}

/// A Reference object: where its volume sits in the texel atlas, and its optical parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ReferenceObject {
    /// xyz: volume resolution; w: flags (1: per-pixel lighting, 2: opaque base surface).
    pub resolution: [u32; 4],
    /// x: volume offset in the texel atlas (u32 words); y: row pitch (words); z: normal volume
    /// offset in the normal atlas; w: unused.
    pub atlas: [u32; 4],
    /// x: opacity length; y: ray step (world units); zw: unused.
    pub params: [f32; 4],
}

/// A ShellMarch object's footprint filter (`shell_filters`): where its texel's MIP levels are
/// and how a footprint picks one.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ShellFilter {
    /// Where its levels from 1 on start in `shell_mips` (8-byte words).
    pub mips: u32,
    /// MIP levels, level 0 included: 0 or 1 where the object does not filter.
    pub levels: u32,
    /// Levels added to every footprint's level.
    pub bias: f32,
    /// Words of one occupancy pyramid of its texel: the pyramids of its levels' dilated
    /// opacity follow its own in `shell_occupancy`, one per level from 1 on.
    pub occupancy: u32,
}

/// Per-pixel progress of the reference tracer between its dispatches (`reference_state`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ReferenceState {
    /// rgb: colour gathered so far; a: transmittance.
    pub color: [f32; 4],
    /// x: ray distance to resume from; y: 1 once started; z: 1 once finished.
    pub resume: [f32; 4],
}

/// Per-object parameters of Meyer & Neyret axis-aligned slicing (uniform `axis_params`).
/// Mirrored as `AxisParams` in `wgsl/shared/types.wgsl`. Directions: 0 = s, 1 = t, 2 = w.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct AxisParams {
    /// xyz: texel resolution along s, t, w (the finest slice counts); w: prism count.
    pub resolution: [u32; 4],
    /// x: `d`, how deep inside a contour may be seen (voxels); y: `p`, largest apparent distance
    /// between slices (pixels); z: maximum view angle the criteria are evaluated at (radians);
    /// w: focal length in pixels (half the image height over tan(fov_y / 2)).
    pub criteria: [f32; 4],
    /// xyz: unit camera forward; w: 1 when the eye is inside a prism of the shell, else 0.
    pub forward: [f32; 4],
    /// x: allowed directions (bit i for direction i); y: vertex capacity; z: occlusion culling
    /// (0/1); w: empty-texel culling (0/1).
    pub flags: [u32; 4],
}

/// What `choose_axis_slices` decided for one prism, and where `emit_axis_slices` writes it.
/// Mirrored as `AxisChoice` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq, Eq)]
pub struct AxisChoice {
    /// 0 = s, 1 = t, 2 = w.
    pub direction: u32,
    /// Power-of-two level: slices are `ceil(resolution / 2^level)` per texel.
    pub level: u32,
    /// Global index of the first slice position crossing the prism (s, t: across tiles).
    pub first: i32,
    /// Slice positions crossing the prism, before empty-slice culling.
    pub count: u32,
    /// Triangle-list vertices emitted (0 when culled).
    pub vertex_count: u32,
    /// First vertex in `axis_vertices` (exclusive scan in prism order).
    pub vertex_offset: u32,
    /// 1 when slices are emitted from the last position down (back to front).
    pub reverse: u32,
    /// 1 when the prism was culled as back-facing.
    pub culled: u32,
}

/// One vertex of an extruded slice (a triangle for `w` slices, a ruled quad for `s` and `t`).
/// Mirrored as `AxisVertex` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct AxisVertex {
    /// xyz: camera-relative position; w: world thickness of the slab the slice stands for.
    pub position: [f32; 4],
    /// xy: coordinates in the slice image; z: array layer; w: direction.
    pub texcoord: [f32; 4],
    /// xyz: unit normal of the slice plane; w: unused.
    pub normal: [f32; 4],
}

/// One dispatch of `bake_axis_slices` (uniform `axis_bake`).
/// Mirrored as `AxisBake` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct AxisBake {
    /// xyz: texel resolution (s, t, w); w: direction (0 = s, 1 = t, 2 = w).
    pub resolution: [u32; 4],
    /// x: level; y: first array layer of the level; z: slices in the level; w: first occupancy
    /// word of the level.
    pub level: [u32; 4],
}

/// One dispatch of `shadow_texel` (uniform `shadow`): self-shadowing baked into a texel.
/// Mirrored as `ShadowParams` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct ShadowParams {
    /// xyz: texel resolution (s, t, w); w: most voxels one march crosses.
    pub resolution: [u32; 4],
    /// xyz: unit texel-space direction towards the light; w: extinction, the optical depth of
    /// one texel unit (the box's height) of alpha-1 matter.
    pub light: [f32; 4],
    /// x: ambient, the light a voxel keeps in full shadow (colour scale `ambient + (1 -
    /// ambient) T`); y: optical depth past which the march stops; z: bias, the voxels (along the
    /// axis the light crosses fastest) the march skips from the voxel's centre; w unused.
    pub shading: [f32; 4],
}

/// One hypertexture object of the `RayMarch` method (uniform `hyper`). Object space is the node's
/// local frame; the camera sits at the origin of camera-relative world space.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HyperParams {
    /// Camera-relative world to object space (affine, column-major).
    pub to_local: [[f32; 4]; 4],
    /// xyz: camera right scaled by the half-width at unit distance; w: near plane distance.
    pub right: [f32; 4],
    /// xyz: camera up scaled by the half-height at unit distance; w: far plane distance.
    pub up: [f32; 4],
    /// xyz: object-space bounds enlarged by the largest shift; w: ray step (world units).
    pub bounds_min: [f32; 4],
    /// xyz: upper corner; w: opacity length (world length over which the transfer opacity is reached).
    pub bounds_max: [f32; 4],
    /// Sphere: x radius; ellipsoid: xyz radii; torus: x major, y minor; box: xyz half extents.
    pub object: [f32; 4],
    /// FromCentre: xyz centre; Constant: xyz vector; Swirl: xyz unit axis, w twist.
    pub field: [f32; 4],
    /// Swirl: xyz a point on the axis.
    pub field_center: [f32; 4],
    /// Field perturbation: x direction amount, y frequency (0: off), z magnitude amount.
    pub perturb: [f32; 4],
    /// x: object kind, y: field kind (`hypertexture::OBJECT_*`, `FIELD_*`), z: noise count,
    /// w: seed of the field perturbation.
    pub kinds: [u32; 4],
    /// x: shadow-ray step (world), y: central-difference offset of the gradient (world), z: the
    /// largest shift (object space) with a small margin: farther from the object the density is 0;
    /// w: the frame's time (seconds, animated hypertextures).
    pub march: [f32; 4],
    /// Work of one dispatch, in density evaluations: x the budget, y the most samples of a shadow
    /// ray, z the most one sample may cost (so a sample is begun only when it fits), w the
    /// longest adaptive stride in steps (0 or 1: off).
    pub budget: [u32; 4],
    /// Mesh and point-set objects: xyz the lower corner of the baked grid (object space), w
    /// samples per axis.
    pub grid_min: [f32; 4],
    /// Mesh and point-set objects: xyz the upper corner of the baked grid.
    pub grid_max: [f32; 4],
    /// Density modulation (Perlin's functions): x bias, y gain (0.5: none).
    pub modulation: [f32; 4],
}

/// What `bake_mesh_grid.wgsl` bakes: samples at the vertices of an `n^3` grid from `lo` to `hi`
/// (object space) of a closed mesh whose triangles are ordered as the leaves of its BVH.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct MeshGridParams {
    /// xyz: the grid's lower corner (object space); w unused.
    pub lo: [f32; 4],
    /// xyz: the grid's upper corner (object space); w unused.
    pub hi: [f32; 4],
    /// x: samples along x, y: triangles, z: BVH nodes, w: closed parts.
    pub counts: [u32; 4],
    /// xyz: samples per axis; w: 1 to test inside by ray parity, 0 for a shell (every distance
    /// negative).
    pub(crate) size: [u32; 4],
}

/// What `bake_mesh_texel.wgsl` turns a mesh grid into: a texel's premultiplied colour (Meyer &
/// Neyret 1998, section 3.2: a pattern mesh sliced with its shading baked in).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct MeshTexelParams {
    /// rgb the albedo, w the opacity.
    pub color: [f32; 4],
    /// xyz the size of the bounds box (object space; texel normals are object normals times it),
    /// w one voxel in object units (the coverage ramp's width).
    pub extent: [f32; 4],
    /// y: 1 fills the inside, 0 draws a one-voxel shell around the surface (x, z, w unused).
    pub mode: [u32; 4],
}

/// One noise of a hypertexture: `t = T((1 + simplex(frequency (x + shift V))) / 2)`, whose term
/// `amplitude t` combines into `k` by `combine` (`scene::hypertexture::Operator`). In animated
/// hypertextures the noise is 4D, its fourth coordinate `speed` times the frame's time.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct HyperNoise {
    /// Largest shift, object units.
    pub amplitude: f32,
    /// Noise cycles per object unit.
    pub frequency: f32,
    /// `r` in [0, 1]: where along `V` the noise is evaluated.
    pub shift: f32,
    /// How the term combines into k: `OPERATOR_SUM`, `OPERATOR_BLEND` or `OPERATOR_MIX`.
    pub combine: u32,
    /// Seed of the noise.
    pub seed: u32,
    /// Noise cycles per second along time (0: not animated).
    pub speed: f32,
    /// The noise's first shape table, and its row count: 1 for a 1D shape transfer function, or
    /// the rows of a 2D one (`Grid`), one table per density from 0 to 1.
    pub table: u32,
    /// Rows of the shape table from `table` (1: a 1D shape transfer function).
    pub rows: u32,
    /// xyz: per-axis factors of `frequency` (1 unless periodic) that make each period a whole
    /// number of noise tiles; w: Blend's unit, the largest amplitude of the hypertexture's noises.
    pub scale: [f32; 4],
    /// Periodic noise: `(a, b, c)` with periods of 3a, 3b, 3c noise cells along x, y, z (0: not
    /// periodic). See `simplex3_tiled` in `wgsl/shared/simplex.wgsl`.
    pub tile: [u32; 4],
}

/// A transfer function to sample into a table: `count` control points from `first`; `kind` 0 is
/// a cubic Hermite curve (points carry slopes), 1 piecewise linear.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TransferFunction {
    /// Index of the first control point in the point buffer.
    pub first: u32,
    /// Number of control points.
    pub count: u32,
    /// 0: cubic Hermite curve; 1: piecewise linear.
    pub kind: u32,
    /// Padding to the WGSL layout (zero).
    pub _pad: u32,
}

/// A control point: position `x` in [0, 1], value `y`, slope `dy/dx` (Hermite curves only).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct TransferPoint {
    /// Position in [0, 1].
    pub x: f32,
    /// Value at `x`.
    pub y: f32,
    /// Slope `dy/dx` (Hermite curves only).
    pub slope: f32,
    /// Padding to the WGSL layout (zero).
    pub _pad: f32,
}

/// Per-pixel progress of the ray marcher between its dispatches (`ray_march_state`); all zero is
/// a ray not yet begun.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct MarchState {
    /// rgb: premultiplied colour gathered so far; a: coverage (1 - transmittance).
    pub color: [f32; 4],
    /// x: index of the next sample; y: density evaluations so far; z: 1 once finished, else
    /// 1 - the stride that reached sample x (adaptive stride; 0 when off); w: those
    /// of the evaluations that ran the noises (y and w for benchmarks).
    pub resume: [f32; 4],
}

/// Splat sets and depth-peeled segments of a RayMarch object (`bake_splats.wgsl`,
/// `begin_segments.wgsl`, `peel_segments.wgsl`, `splat_segments.wgsl`, `ray_march.wgsl`); twin: `SegmentParams` in
/// wgsl/shared/types.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SegmentParams {
    /// Object space to camera-relative world (the inverse of `HyperParams::to_local`).
    pub from_local: [[f32; 4]; 4],
    /// xyz: the splat lattice's lowest corner (object space); w: its cell size.
    pub lattice_min: [f32; 4],
    /// xyz: lattice cells per axis; w: splat capacity of each set (the cell count).
    pub lattice: [u32; 4],
    /// x: the support distance of the splat surface (the largest shift plus a margin); y: the
    /// largest factor by which `from_local` scales lengths; zw: unused.
    pub surface: [f32; 4],
    /// x: surface splats; y: interior splats; z: depth-peeling passes; w: footprint pixels one
    /// invocation of `peel_segments.wgsl` tests at most.
    pub counts: [u32; 4],
    /// EWA-style splatting (`splat_segments.wgsl`, `resolve_splats.wgsl`): x: depth slabs per
    /// pixel; y: footprint pixels per block; z: pieces each chord is cut into; w: samples per piece.
    pub splatting: [u32; 4],
}

/// The light volume of a RayMarch object (`bake_light_volume.wgsl`; read by `shade` in
/// wgsl/shared/march.wgsl): transmittance towards a directional light at the vertices of a grid
/// laid in the light's frame over the object's bounds, vertex `(i, j, k)` at `origin + i u + j v
/// + k w`, `k = 0` on the light's side and `w` pointing away from the light. Twin:
/// `LightVolumeParams` in wgsl/shared/types.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct LightVolumeParams {
    /// xyz: vertex (0, 0, 0) (object space); w: world length of one sub-step along the light.
    pub origin: [f32; 4],
    /// xyz: object-space step between vertices along i; w: the opacity length (world).
    pub u: [f32; 4],
    /// xyz: step along j; w: world length of one step along k (a layer).
    pub v: [f32; 4],
    /// xyz: step along k (away from the light); w: unused.
    pub w: [f32; 4],
    /// Object space to grid coordinates in vertex units (affine, column-major).
    pub to_grid: [[f32; 4]; 4],
    /// xyz: vertices along i, j, k; w: sub-steps per layer.
    pub counts: [u32; 4],
}

/// A splat of a hypertexture object's splat set (object space): a surface splat is a disk with
/// an outward normal, an interior splat a sphere (normal zero).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct Splat {
    /// xyz: centre; w: radius.
    pub center: [f32; 4],
    /// xyz: unit outward normal (surface splats); w: unused.
    pub normal: [f32; 4],
}

/// `HyperParams::kinds[0]` (mirrored in wgsl/shared/fields.wgsl).
pub(crate) const OBJECT_SPHERE: u32 = 0;
pub(crate) const OBJECT_ELLIPSOID: u32 = 1;
pub(crate) const OBJECT_TORUS: u32 = 2;
pub(crate) const OBJECT_BOX: u32 = 3;
pub(crate) const OBJECT_MESH: u32 = 4;
pub(crate) const OBJECT_POINTS: u32 = 5;
/// `HyperParams::kinds[1]`.
pub(crate) const FIELD_CLOSEST_SURFACE: u32 = 0;
pub(crate) const FIELD_FROM_CENTRE: u32 = 1;
pub(crate) const FIELD_CONSTANT: u32 = 2;
pub(crate) const FIELD_SWIRL: u32 = 3;
/// `HyperNoise::operator` (mirrored in wgsl/shared/hypertexture.wgsl).
pub(crate) const OPERATOR_SUM: u32 = 0;
pub(crate) const OPERATOR_BLEND: u32 = 1;
pub(crate) const OPERATOR_MIX: u32 = 2;

/// One volume object (an OpenVDB grid) as `march_volume.wgsl` and `bake_volume.wgsl` see it;
/// twin: `VolumeParams` in wgsl/shared/types.wgsl. Index space is the grid's (voxel (i, j, k)
/// at index point (i, j, k)).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct VolumeParams {
    /// Camera-relative world to index space (the bake: texel space to index space).
    pub to_index: [[f32; 4]; 4],
    /// xyz: the camera's right, scaled by the image's half width at unit distance; w: near.
    pub right: [f32; 4],
    /// xyz: up, likewise; w: far.
    pub up: [f32; 4],
    /// xyz: index box outside which the density is 0 (lower corner); w: ray step (world units).
    pub box_lo: [f32; 4],
    /// xyz: upper corner; w: shadow-ray step (world units).
    pub box_hi: [f32; 4],
    /// rgb: albedo; w: density scale (extinction per unit density per world unit).
    pub medium: [f32; 4],
    /// xyz: index coordinate of the brick table's first voxel; w: unused.
    pub origin: [i32; 4],
    /// xyz: top cells of the brick table per axis; w: has a colour grid (1) or not (0).
    pub table: [u32; 4],
    /// xyz: brick slots of the atlases per axis; w: unused.
    pub atlas: [u32; 4],
    /// x: loop iterations per dispatch; y: most shadow samples; z: worst iterations of one
    /// sample; w: unused.
    pub budget: [u32; 4],
}

/// What `export/resample_world.wgsl` resamples: one dispatch's leaves of a textured object's world
/// voxels. Mirrored as `WorldParams` in `wgsl/shared/types.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct WorldParams {
    /// xyz: the index of the voxel whose centre the shell is relative to; w: sub-points per axis.
    pub anchor: [i32; 4],
    /// x: voxel size (world units); y: 1 / the texel's opacity length; z, w unused.
    pub voxel: [f32; 4],
    /// x: leaves in this dispatch; y, z, w unused.
    pub counts: [u32; 4],
    /// xyz: the texel's voxels per axis; w unused.
    pub resolution: [u32; 4],
}
