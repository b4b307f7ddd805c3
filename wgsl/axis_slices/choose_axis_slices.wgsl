// Per prism: slice direction (smallest (1/c^2 - 1) h^2), power-of-two level from the criteria, occlusion culling, vertex count.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> axis_params: AxisParams;
@group(0) @binding(1) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(2) var<storage, read> prisms: array<Prism>;
@group(0) @binding(3) var<storage, read> axis_occupancy: array<u32>;
@group(0) @binding(4) var<storage, read_write> axis_choices: array<AxisChoice>;
@group(0) @binding(5) var<uniform> frame: FrameParams;
@group(0) @binding(6) var base_depth: texture_2d<f32>;

#include "shared/axis_slices.wgsl"
#include "shared/occlusion.wgsl"

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let index = gid.x;
    if (index >= axis_params.resolution.w) {
        return;
    }
    var f = load_axis_frame(index);
    var c = choose_axis(&f);
    c.vertex_count = 0u;
    c.vertex_offset = 0u;
    if (axis_params.flags.z != 0u && hidden_behind_base(array<vec3<f32>, 6>(f.bottom[0], f.bottom[1], f.bottom[2], f.top[0], f.top[1], f.top[2]))) {
        c.culled = 1u;
    } else {
        let n = f32(level_slices(axis_params.resolution[c.direction], c.level));
        let xe = eye_slice(&f, c);
        for (var j = 0u; j < c.count; j++) {
            let g = slice_position(c, j);
            if (!slice_occupied(c, g)) {
                continue;
            }
            if (splits_at_eye(g, xe)) {
                let parts = split_slab(g, xe, n);
                c.vertex_count += slice_vertex_count(&f, c, parts.x) + slice_vertex_count(&f, c, parts.y);
            } else {
                c.vertex_count += slice_vertex_count(&f, c, (f32(g) + 0.5) / n);
            }
        }
    }
    axis_choices[index] = c;
}
