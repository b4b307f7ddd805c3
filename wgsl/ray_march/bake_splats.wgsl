// Splat sets of a hypertexture object (Gilet & Dischler 2009, section 5): one thread per lattice cell makes a surface splat (a disk on the boundary enlarged by the largest shift, normal outward) where the boundary crosses the cell, and an interior splat (a sphere) where the cell's centre is inside. CPU twin: src/cpu/bake_splats.rs.
#include "shared/types.wgsl"
#include "shared/fields.wgsl"

// The splat surface is where support_distance = segments.surface.x. A cell whose centre lies
// within half a cell diagonal of it holds some of it: the centre is moved onto the surface by two
// Newton steps along the gradient (central differences). Every point of the surface lies in some
// such cell, within a diagonal of that cell's splat, so disks of SURFACE_RADIUS cells (a little
// over sqrt(3)) leave no gaps. Interior spheres cover their cell, with radii growing with depth
// up to INTERIOR_RADIUS cells, or a block of cells deeper inside.
const HALF_DIAGONAL: f32 = 0.8660254;
const SURFACE_RADIUS: f32 = 1.8;
const INTERIOR_RADIUS: f32 = 2.0;

@group(0) @binding(0) var<uniform> hyper: HyperParams;
@group(0) @binding(1) var<uniform> segments: SegmentParams;
@group(0) @binding(2) var<storage, read> mesh_grid: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> mesh_depth: array<u32>;
@group(0) @binding(4) var<storage, read_write> surface_splats: array<Splat>;
@group(0) @binding(5) var<storage, read_write> interior_splats: array<Splat>;
// Splats written so far: surface, interior.
@group(0) @binding(6) var<storage, read_write> splat_counts: array<atomic<u32>>;

// Distance above the splat surface (negative inside).
fn level(x: vec3<f32>) -> f32 {
    return support_distance(x) - segments.surface.x;
}

fn gradient(x: vec3<f32>, e: f32) -> vec3<f32> {
    let dx = vec3<f32>(e, 0.0, 0.0);
    let dy = vec3<f32>(0.0, e, 0.0);
    let dz = vec3<f32>(0.0, 0.0, e);
    return vec3<f32>(level(x + dx) - level(x - dx), level(x + dy) - level(x - dy), level(x + dz) - level(x - dz))
        / (2.0 * e);
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= segments.lattice.xyz)) {
        return;
    }
    let cell = segments.lattice_min.w;
    let x = segments.lattice_min.xyz + (vec3<f32>(id) + 0.5) * cell;
    let s = level(x);
    if (abs(s) <= HALF_DIAGONAL * cell) {
        let e = 0.25 * cell;
        var p = x;
        var g = gradient(p, e);
        for (var i = 0u; i < 2u; i++) {
            let g2 = dot(g, g);
            if (g2 > 1e-12) {
                p -= level(p) * g / g2;
                g = gradient(p, e);
            }
        }
        let len = length(g);
        if (len > 1e-6) {
            let slot = atomicAdd(&splat_counts[0], 1u);
            surface_splats[slot] = Splat(vec4<f32>(p, SURFACE_RADIUS * cell), vec4<f32>(g / len, 0.0));
        }
    }
    if (s >= 0.0) {
        return;
    }
    // Deeper inside, blocks of 8^3, 4^3 or 2^3 cells whose circumscribed sphere lies inside the
    // splat surface are one sphere each, made by the block's first cell: every cell of a block
    // finds the same block, so each cell is covered once by the largest that fits.
    for (var m = 3u; m > 0u; m--) {
        let k = 1u << m;
        let corner = id & vec3<u32>(~(k - 1u));
        let centre = segments.lattice_min.xyz + (vec3<f32>(corner) + 0.5 * f32(k)) * cell;
        let r = f32(k) * cell * HALF_DIAGONAL;
        if (level(centre) <= -r) {
            if (all(id == corner)) {
                interior_splats[atomicAdd(&splat_counts[1], 1u)] = Splat(vec4<f32>(centre, r), vec4<f32>(0.0));
            }
            return;
        }
    }
    let r = clamp(-s, HALF_DIAGONAL * cell, INTERIOR_RADIUS * cell);
    interior_splats[atomicAdd(&splat_counts[1], 1u)] = Splat(vec4<f32>(x, r), vec4<f32>(0.0));
}
