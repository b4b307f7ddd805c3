// Per prism: writes its extruded slices (w: triangles, s and t: ruled quads) back to front at the scanned offset.
#include "shared/types.wgsl"

@group(0) @binding(0) var<uniform> axis_params: AxisParams;
@group(0) @binding(1) var<storage, read> shell_vertices: array<ShellVertex>;
@group(0) @binding(2) var<storage, read> prisms: array<Prism>;
@group(0) @binding(3) var<storage, read> axis_occupancy: array<u32>;
@group(0) @binding(4) var<storage, read> axis_choices: array<AxisChoice>;
@group(0) @binding(5) var<storage, read_write> axis_vertices: array<AxisVertex>;
// `draw_order: Slices`: triangles per (direction, layer), one stride of layers per direction,
// for group_axis_slices.wgsl (a stand-in otherwise).
@group(0) @binding(6) var<storage, read_write> axis_layer_counts: array<atomic<u32>>;

override grouped_slices: bool = false;

fn count_layer(direction: u32, layer: u32, triangles: u32) {
    if (grouped_slices) {
        atomicAdd(&axis_layer_counts[direction * (arrayLength(&axis_layer_counts) / 3u) + layer], triangles);
    }
}

#include "shared/axis_slices.wgsl"

// Writes the slice at texture coordinate x standing for a slab `thickness` (world) thick at
// `at`; returns its vertex count (0 when an s or t line misses the uv triangle).
fn emit_slice(f: ptr<function, AxisFrame>, c: AxisChoice, x: f32, thickness: f32, layer_index: u32, at: u32) -> u32 {
    let axis = (*f).axes[c.direction];
    let layer = f32(layer_index);
    if (c.direction == 2u) {
        for (var i = 0u; i < 3u; i++) {
            let p = mix((*f).bottom[i], (*f).top[i], x);
            axis_vertices[at + i] = AxisVertex(vec4<f32>(p, thickness), vec4<f32>((*f).uv[i], layer, 2.0), vec4<f32>(axis.xyz, 0.0));
        }
        count_layer(2u, layer_index, 1u);
        return 3u;
    }
    // The line (s or t) = x across the uv triangle: two edge crossings (half-open edges).
    let other = 1u - c.direction;
    var ends: array<vec4<f32>, 4>; // per crossing: bottom xyz + image u, top xyz
    var found = 0u;
    for (var e = 0u; e < 3u; e++) {
        let e2 = (e + 1u) % 3u;
        let a = (*f).uv[e][c.direction];
        let b = (*f).uv[e2][c.direction];
        if (((a <= x && x < b) || (b <= x && x < a)) && found < 2u) {
            let l = (x - a) / (b - a);
            let u = mix((*f).uv[e][other], (*f).uv[e2][other], l);
            ends[2u * found] = vec4<f32>(mix((*f).bottom[e], (*f).bottom[e2], l), u);
            ends[2u * found + 1u] = vec4<f32>(mix((*f).top[e], (*f).top[e2], l), u);
            found++;
        }
    }
    if (found < 2u) {
        return 0u;
    }
    // Ruled quad A0 B0 B1, A0 B1 A1 (image v = w: 0 at the bottom, 1 at the top).
    let order = array<u32, 6>(0u, 2u, 3u, 0u, 3u, 1u);
    for (var i = 0u; i < 6u; i++) {
        let k = order[i];
        let v = ends[k];
        let tex = vec4<f32>(v.w, f32(k & 1u), layer, f32(c.direction));
        axis_vertices[at + i] = AxisVertex(vec4<f32>(v.xyz, thickness), tex, vec4<f32>(axis.xyz, 0.0));
    }
    count_layer(c.direction, layer_index, 2u);
    return 6u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let index = gid.x;
    if (index >= axis_params.resolution.w) {
        return;
    }
    let c = axis_choices[index];
    if (c.vertex_count == 0u || c.vertex_offset + c.vertex_count > min(axis_params.flags.y, arrayLength(&axis_vertices))) {
        return;
    }
    var f = load_axis_frame(index);
    let n = level_slices(axis_params.resolution[c.direction], c.level);
    let fn_ = f32(n);
    let layer0 = level_layer(axis_params.resolution[c.direction], c.level);
    let slab = f.axes[c.direction].w / fn_;
    // Eye in the layer: the two ends of the remaining range, farthest from the eye first, so each
    // side of the eye is drawn back to front.
    let xe = eye_slice(&f, c);
    var lo = c.first;
    var hi = c.first + i32(c.count) - 1;
    var at = c.vertex_offset;
    for (var j = 0u; j < c.count; j++) {
        var g = slice_position(c, j);
        if (xe > -1.0e30) {
            if (abs(f32(lo) + 0.5 - xe) > abs(f32(hi) + 0.5 - xe)) {
                g = lo;
                lo++;
            } else {
                g = hi;
                hi--;
            }
        }
        if (!slice_occupied(c, g)) {
            continue;
        }
        let layer_index = layer0 + slice_layer(g, n);
        if (splits_at_eye(g, xe)) {
            let parts = split_slab(g, xe, fn_);
            at += emit_slice(&f, c, parts.x, parts.z * slab, layer_index, at);
            at += emit_slice(&f, c, parts.y, parts.w * slab, layer_index, at);
        } else {
            at += emit_slice(&f, c, (f32(g) + 0.5) / fn_, slab, layer_index, at);
        }
    }
}
