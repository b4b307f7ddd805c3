// Structs shared with Rust; mirrored in src/types.rs (tests/types_layout.rs checks both agree).

struct ShellVertex {
    bottom: vec4<f32>,
    top: vec4<f32>,
}

struct Prism {
    vertices: vec4<u32>,
    uv01: vec4<f32>,
    uv2: vec4<f32>,
    sphere: vec4<f32>,
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
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

struct BaseVertex {
    position: vec4<f32>,
    normal: vec4<f32>,
}
