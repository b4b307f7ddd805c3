// Structs shared with Rust; mirrored in src/types.rs (tests/types_layout.rs checks both agree).

struct ShellVertex {
    bottom: vec4<f32>,
    top: vec4<f32>,
}

struct Prism {
    vertices: vec4<u32>,
    uv01: vec4<f32>,
    uv2: vec4<f32>,
}

struct SliceParams {
    plane_normal: vec4<f32>,
    first_plane: f32,
    spacing: f32,
    plane_count: u32,
    prism_count: u32,
    vertex_capacity: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct SliceVertex {
    position: vec4<f32>,
    uvw: vec4<f32>,
}

struct DrawIndirect {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

// Screen tiles of a Tiles compositor (TileParams in src/types.rs).
struct TileParams {
    tiles_x: u32,
    tiles_y: u32,
    blocks: u32,
    entry_capacity: u32,
    width: u32,
    height: u32,
    _pad0: u32,
    _pad1: u32,
}

// One slice triangle binned into tiles (TileTriangle in src/types.rs): its edges oriented so
// its inside is positive (x, y, constant; w = 1 when the inside owns centres on the edge), its
// inclusive tile range, its plane's depth and its plane.
struct TileTriangle {
    e0: vec4<f32>,
    e1: vec4<f32>,
    e2: vec4<f32>,
    tiles: vec4<u32>,
    depth: f32,
    plane: u32,
    _pad0: u32,
    _pad1: u32,
}

// Texel coordinates over a binned triangle (TileAttributes in src/types.rs): at corner a (xyz)
// with a's pixel x (w), their steps per pixel in x (xyz) with a's pixel y (w), and in y.
struct TileAttributes {
    at_a: vec4<f32>,
    d_x: vec4<f32>,
    d_y: vec4<f32>,
}

struct FrameParams {
    view_proj: mat4x4<f32>,
    forward: vec4<f32>,
    light_dir: vec4<f32>,
    light_color: vec4<f32>,
    background: vec4<f32>,
    viewport: vec4<f32>,
}

struct ObjectParams {
    base_color: vec4<f32>,
    opacity_length: f32,
    // The object's index in the scene: its slot in per-object AOVs (coverage).
    index: u32,
    _pad1: f32,
    _pad2: f32,
}

struct VertexFrame {
    ds: vec4<f32>,
    dt: vec4<f32>,
}

struct BaseVertex {
    position: vec4<f32>,
    normal: vec4<f32>,
}

// Bake kernels' parameters (twin: BakeParams in src/types.rs).
// resolution: xyz voxels, w shape count; light: xyz texel-space direction towards the light, w ambient.
struct BakeParams {
    resolution: vec4<u32>,
    light: vec4<f32>,
}

// One implicit shape (twin: ImplicitShape in src/types.rs); kind constants in bake_implicit.wgsl.
struct ImplicitShape {
    kind: u32,
    first_ball: u32,
    ball_count: u32,
    _pad: u32,
    center: vec4<f32>,
    params: vec4<f32>,
    color: vec4<f32>,
}

// Periodic Perlin height field (twin: HeightfieldParams in src/types.rs).
struct HeightfieldParams {
    frequency: u32,
    octaves: u32,
    seed: u32,
    _pad0: u32,
    amplitude: f32,
    base: f32,
    opacity: f32,
    darkening: f32,
    color_low: vec4<f32>,
    color_high: vec4<f32>,
}

// Height field from a grey-level image (twin: HeightImageParams in src/types.rs).
struct HeightImageParams {
    width: u32,
    height: u32,
    _pad0: vec2<u32>,
    amplitude: f32,
    base: f32,
    opacity: f32,
    darkening: f32,
    color_low: vec4<f32>,
    color_high: vec4<f32>,
}

// Reference tracer (twins: ReferenceParams, ReferenceNode, ReferencePrism, ReferenceObject in src/types.rs).
struct ReferenceParams {
    right: vec4<f32>,
    up: vec4<f32>,
    counts: vec4<u32>,
}

struct ReferenceNode {
    min: vec4<f32>,
    max: vec4<f32>,
}

struct ReferencePrism {
    vertices: vec4<u32>,
    uv01: vec4<f32>,
    uv2: vec4<f32>,
}

struct ReferenceObject {
    resolution: vec4<u32>,
    atlas: vec4<u32>,
    params: vec4<f32>,
}

// ShellMarch's footprint filter of an object (twin: ShellFilter in src/types.rs).
struct ShellFilter {
    mips: u32,
    levels: u32,
    bias: f32,
    occupancy: u32,
}

struct ReferenceState {
    color: vec4<f32>,
    resume: vec4<f32>,
}

// Axis-aligned slicing, Meyer & Neyret (twins: AxisParams, AxisChoice, AxisVertex, AxisBake in src/types.rs).
struct AxisParams {
    resolution: vec4<u32>,
    criteria: vec4<f32>,
    forward: vec4<f32>, // w: 1 when the eye is inside a prism of the shell
    flags: vec4<u32>,
}

struct AxisChoice {
    direction: u32,
    level: u32,
    first: i32,
    count: u32,
    vertex_count: u32,
    vertex_offset: u32,
    reverse: u32,
    culled: u32,
}

struct AxisVertex {
    position: vec4<f32>,
    texcoord: vec4<f32>,
    normal: vec4<f32>,
}

struct AxisBake {
    resolution: vec4<u32>,
    level: vec4<u32>,
}

// Baked self-shadowing of a texel (twin: ShadowParams in src/types.rs).
struct ShadowParams {
    resolution: vec4<u32>,
    light: vec4<f32>,
    shading: vec4<f32>,
}

// Hypertextures (twins: HyperParams, HyperNoise, TransferFunction, TransferPoint, MarchState in src/types.rs).
struct HyperParams {
    to_local: mat4x4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    bounds_min: vec4<f32>,
    bounds_max: vec4<f32>,
    object: vec4<f32>,
    field: vec4<f32>,
    field_center: vec4<f32>,
    perturb: vec4<f32>,
    kinds: vec4<u32>,
    march: vec4<f32>,
    budget: vec4<u32>,
    grid_min: vec4<f32>,
    grid_max: vec4<f32>,
    modulation: vec4<f32>,
}

// A mesh object's grid bake (twin: MeshGridParams in src/types.rs).
struct MeshGridParams {
    lo: vec4<f32>,
    hi: vec4<f32>,
    counts: vec4<u32>,
    size: vec4<u32>,
}

// A mesh texel's colouring of a mesh grid (twin: MeshTexelParams in src/types.rs).
struct MeshTexelParams {
    color: vec4<f32>,
    extent: vec4<f32>,
    mode: vec4<u32>,
}

struct HyperNoise {
    amplitude: f32,
    frequency: f32,
    shift: f32,
    combine: u32,
    seed: u32,
    speed: f32,
    table: u32,
    rows: u32,
    scale: vec4<f32>,
    tile: vec4<u32>,
}

struct TransferFunction {
    first: u32,
    count: u32,
    kind: u32,
    _pad: u32,
}

struct TransferPoint {
    x: f32,
    y: f32,
    slope: f32,
    _pad: f32,
}

struct MarchState {
    color: vec4<f32>,
    resume: vec4<f32>,
}

// Splat sets and depth-peeled segments (twins: SegmentParams, Splat in src/types.rs).
struct SegmentParams {
    from_local: mat4x4<f32>,
    lattice_min: vec4<f32>,
    lattice: vec4<u32>,
    surface: vec4<f32>,
    counts: vec4<u32>,
    splatting: vec4<u32>,
}

// The light volume of a RayMarch object (twin: LightVolumeParams in src/types.rs).
struct LightVolumeParams {
    origin: vec4<f32>,
    u: vec4<f32>,
    v: vec4<f32>,
    w: vec4<f32>,
    to_grid: mat4x4<f32>,
    counts: vec4<u32>,
}

struct Splat {
    center: vec4<f32>,
    normal: vec4<f32>,
}

// Volume objects (twin: VolumeParams in src/types.rs).
struct VolumeParams {
    to_index: mat4x4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    box_lo: vec4<f32>,
    box_hi: vec4<f32>,
    medium: vec4<f32>,
    origin: vec4<i32>,
    table: vec4<u32>,
    atlas: vec4<u32>,
    budget: vec4<u32>,
}

// What resample_world.wgsl resamples (twin: WorldParams in src/types.rs).
struct WorldParams {
    anchor: vec4<i32>,
    voxel: vec4<f32>,
    counts: vec4<u32>,
    resolution: vec4<u32>,
}
