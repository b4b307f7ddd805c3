// EWA-style splatting, second step: per pixel, its depth slabs (splat_segments.wgsl) composited front to back into the march state the RayMarch composite blends. CPU twin: src/methods/ray_march/splat_segments.rs.
#include "shared/types.wgsl"
#include "shared/segments.wgsl"

// Within a slab the splats' sums are normalised by their weights: the mean optical depth per
// covered sample (weighted), times the samples between the first and last covered, and the
// optical-depth-weighted mean colour. Slabs are ordered; what lies within one is not (the
// paper's slice-based clipping): the error shrinks as slabs get thinner.
const MIN_TRANSMITTANCE: f32 = 1e-4;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<uniform> hyper: HyperParams;
@group(0) @binding(2) var<uniform> segments: SegmentParams;
@group(0) @binding(3) var<storage, read> splat_slabs: array<u32>;
@group(0) @binding(4) var<storage, read_write> ray_march_state: array<MarchState>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = viewport_pixel(id.xy);
    if (pixel == NO_PIXEL) {
        return;
    }
    let base = pixel * slab_stride();
    let n = splat_slabs[base + 2u];
    var rgb = vec3<f32>(0.0);
    var transmittance = 1.0;
    for (var j = 0u; j < segments.splatting.x && transmittance >= MIN_TRANSMITTANCE; j++) {
        let w = base + SLAB_HEADER + SLAB_WORDS * j;
        let share = f32(splat_slabs[w + 4u]) / SHARE_SCALE;
        let tau = f32(splat_slabs[w]) / TAU_SCALE;
        let last = splat_slabs[w + 6u];
        if (last == 0u || share <= 0.0 || tau <= 0.0) {
            continue;
        }
        let covered = f32(last - ~splat_slabs[w + 5u]);
        let samples = f32(slab_start(j + 1u, n) - slab_start(j, n));
        let alpha = 1.0 - exp(-tau / (share * samples) * covered);
        let weighted = vec3<f32>(f32(splat_slabs[w + 1u]), f32(splat_slabs[w + 2u]), f32(splat_slabs[w + 3u]));
        let colour = weighted / TAU_SCALE / tau;
        rgb += colour * alpha * transmittance;
        transmittance *= 1.0 - alpha;
    }
    let evaluations = f32(splat_slabs[base]);
    ray_march_state[pixel] = MarchState(
        vec4<f32>(rgb, 1.0 - transmittance),
        vec4<f32>(0.0, evaluations, 1.0, f32(splat_slabs[base + 1u])),
    );
}
