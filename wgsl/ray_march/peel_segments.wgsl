// Depth peeling (Gilet & Dischler 2009, section 5.2): one thread per surface splat and footprint block intersects the rays of its screen footprint with the splat's disk and keeps per pixel the nearest entry (front-facing) or exit (back-facing) beyond the previous boundary. CPU twin: src/methods/ray_march/peel_segments.rs.
#include "shared/types.wgsl"
#include "shared/fields.wgsl"
#include "shared/segments.wgsl"

// The pass is dispatched twice per peel (`peel_phases`): entries, then exits. Phase p reads
// boundary slot p of each pixel (final since the previous dispatch) and lowers slot p + 1 with
// atomicMin on the f32 bits (t > 0, so the bits order as the numbers do). Which phase a dispatch
// is comes from a ticket: every workgroup takes one, and each dispatch takes exactly as many as
// it has workgroups, so ticket / workgroups is the dispatch's index.
// A footprint is cut into blocks of `segments.counts.w` pixels (one per invocation along y) so
// that no invocation loops more than lavapipe's 65535 iterations (the loop body has no loops).
// Disks are tangent to the splat surface: outside it where it is convex, cutting into it where it
// is concave. A ray grazing a concave part can leave such a disk's inner side while still deep
// inside (a false exit that would clip detail), so an exit counts only where the disk lies on or
// outside the surface; a true exit missed there makes the segment longer, never shorter. Entries
// need no such test: any disk point lies outside the support (the surface is half a cell beyond
// it, more than a disk cuts in).
const EXIT_SLACK: f32 = 1e-3;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<uniform> segments: SegmentParams;
@group(0) @binding(3) var<storage, read> surface_splats: array<Splat>;
@group(0) @binding(4) var<storage, read_write> segment_bounds: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read_write> peel_tickets: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> mesh_depth: array<u32>;

var<workgroup> ticket: u32;

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    if (local == 0u) {
        ticket = atomicAdd(&peel_tickets[0], 1u);
    }
    let phase = workgroupUniformLoad(&ticket) / (groups.x * groups.y * groups.z);
    if (id.x >= segments.counts.x || phase >= 2u * segments.counts.z) {
        return;
    }
    let splat = surface_splats[id.x];
    let centre = splat.center.xyz;
    let normal = splat.normal.xyz;
    let radius = splat.center.w;
    // A ray from the eye o through a point q of the disk faces it as (q - o) . n = (centre - o) . n
    // does: the whole splat is front- or back-facing, and only one phase of two wants it.
    let origin = hyper.to_local[3].xyz;
    let offset = dot(centre - origin, normal);
    let entering = (phase & 1u) == 0u;
    if ((offset < 0.0) != entering || offset == 0.0) {
        return;
    }
    let size = vec2<u32>(frame.viewport.xy);
    let rect = footprint(centre, radius);
    let lo = rect.xy;
    let hi = rect.zw;
    if (any(hi < lo)) {
        return;
    }
    let columns = u32(hi.x - lo.x + 1);
    let pixels = columns * u32(hi.y - lo.y + 1);
    let first = id.y * segments.counts.w;
    let last = min(first + segments.counts.w, pixels);
    let stride = segment_stride();
    // Pixel rays unnormalised, D = forward + right sx + up sy, in object space: affine in sx, sy.
    let to_local = mat3x3<f32>(hyper.to_local[0].xyz, hyper.to_local[1].xyz, hyper.to_local[2].xyz);
    let along = to_local * frame.forward.xyz;
    let across = to_local * hyper.right.xyz;
    let down = to_local * hyper.up.xyz;
    // Footprint pixel i is (lo.x + i % columns, lo.y + i / columns), stepped without divisions.
    var p = vec2<u32>(u32(lo.x) + first % columns, u32(lo.y) + first / columns);
    for (var i = first; i < last; i++) {
        if (i > first) {
            p.x++;
            if (p.x > u32(hi.x)) {
                p = vec2<u32>(u32(lo.x), p.y + 1u);
            }
        }
        let slot = (p.y * size.x + p.x) * stride + 1u + phase;
        // The first entry may lie before the ray's start (the splat surface reaches beyond the
        // bounds by its margin): the marcher clips it. Past the first, a pixel whose previous
        // boundary was not found is done.
        var previous = 0.0;
        if (phase > 0u) {
            previous = bitcast<f32>(atomicLoad(&segment_bounds[slot]));
            if (previous == bitcast<f32>(NO_DEPTH)) {
                continue;
            }
        }
        let sx = 2.0 * (f32(p.x) + 0.5) * frame.viewport.z - 1.0;
        let sy = 1.0 - 2.0 * (f32(p.y) + 0.5) * frame.viewport.w;
        let ray = along + across * sx + down * sy;
        // o + ray u meets the disk's plane in front of the eye (u > 0) where ray . n has the
        // offset's sign.
        let facing = dot(ray, normal);
        if (facing * offset <= 0.0) {
            continue;
        }
        let u = offset / facing;
        let off = origin + ray * u - centre;
        if (dot(off, off) > radius * radius) {
            continue;
        }
        // The parameter along the unit world direction (the marcher's t).
        let t = u * length(frame.forward.xyz + hyper.right.xyz * sx + hyper.up.xyz * sy);
        let nearest = bitcast<f32>(atomicLoad(&segment_bounds[slot + 1u]));
        if (t <= previous || t >= nearest) {
            continue;
        }
        if (!entering && support_distance(origin + ray * u) - segments.surface.x < -EXIT_SLACK * segments.lattice_min.w) {
            continue;
        }
        atomicMin(&segment_bounds[slot + 1u], bitcast<u32>(t));
    }
}
