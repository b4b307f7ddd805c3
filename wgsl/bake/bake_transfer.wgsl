// Samples a hypertexture's transfer functions (Hermite shape curves, sampled tables, RGBA ramps) into TRANSFER_SIZE-entry tables; CPU twin src/cpu/bake_transfer.rs.
#include "shared/types.wgsl"
#include "shared/transfer.wgsl"

// TransferFunction.kind (twins: HERMITE, LINEAR in src/cpu/bake_transfer.rs).
const HERMITE: u32 = 0u;
const LINEAR: u32 = 1u;

@group(0) @binding(0) var<storage, read> transfer_points: array<TransferPoint>;
@group(0) @binding(1) var<storage, read> transfer_functions: array<TransferFunction>;
@group(0) @binding(2) var<storage, read_write> transfer_tables: array<f32>;

// The function at x: constant beyond its first and last points; between two points a cubic
// Hermite segment with the points' slopes (clamped to [0, 1]) or a straight line.
fn transfer_curve(f: TransferFunction, x: f32) -> f32 {
    let first = transfer_points[f.first];
    let last = transfer_points[f.first + f.count - 1u];
    if (x <= first.x) {
        return first.y;
    }
    if (x >= last.x) {
        return last.y;
    }
    var k = f.first;
    for (var j = f.first + 1u; j + 1u < f.first + f.count; j++) {
        if (transfer_points[j].x <= x) {
            k = j;
        }
    }
    let a = transfer_points[k];
    let b = transfer_points[k + 1u];
    let h = b.x - a.x;
    let t = (x - a.x) / h;
    if (f.kind == LINEAR) {
        return mix(a.y, b.y, t);
    }
    let t2 = t * t;
    let t3 = t2 * t;
    let y = (2.0 * t3 - 3.0 * t2 + 1.0) * a.y + (t3 - 2.0 * t2 + t) * h * a.slope + (3.0 * t2 - 2.0 * t3) * b.y
        + (t3 - t2) * h * b.slope;
    return clamp(y, 0.0, 1.0);
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= TRANSFER_SIZE || id.y >= arrayLength(&transfer_functions)) {
        return;
    }
    let x = f32(id.x) / f32(TRANSFER_SIZE - 1u);
    transfer_tables[id.y * TRANSFER_SIZE + id.x] = transfer_curve(transfer_functions[id.y], x);
}
