// Soft objects (density 1 at the core falling to 0 on the boundary) and the vector fields of the
// paper's Figure 8, in object space. Reads the kernel's `hyper: HyperParams` and, for mesh
// and point-set objects, `mesh_grid` and `mesh_depth` (bake_mesh_grid.wgsl, bake_point_grid.wgsl). CPU twin:
// src/cpu/hypertexture.rs (same names).
#include "shared/simplex.wgsl"

// HyperParams.kinds.x (twins: OBJECT_* in src/hypertexture/mod.rs).
const OBJECT_SPHERE: u32 = 0u;
const OBJECT_ELLIPSOID: u32 = 1u;
const OBJECT_TORUS: u32 = 2u;
const OBJECT_BOX: u32 = 3u;
const OBJECT_MESH: u32 = 4u;
const OBJECT_POINTS: u32 = 5u;
// HyperParams.kinds.y (twins: FIELD_*).
const FIELD_CLOSEST_SURFACE: u32 = 0u;
const FIELD_FROM_CENTRE: u32 = 1u;
const FIELD_CONSTANT: u32 = 2u;
const FIELD_SWIRL: u32 = 3u;
// Vectors shorter than this have no direction (the paper's null vector).
const TINY: f32 = 1e-12;

fn unit_or_zero(v: vec3<f32>) -> vec3<f32> {
    let len = length(v);
    return select(vec3<f32>(0.0), v / len, len > TINY);
}

fn mesh_cell(i: vec3<u32>, n: u32, base: u32) -> vec4<f32> {
    return mesh_grid[base + i.x + n * (i.y + n * i.z)];
}

// A mesh or point-set object's grid at x (clamped to the grid), trilinear: xyz the vector to
// the closest surface point, w the signed distance (positive inside).
fn mesh_sample(x: vec3<f32>) -> vec4<f32> {
    return grid_sample(x, 0u);
}

// A point set's kernel sum over its saturation at x (the second block of its grid).
fn points_density(x: vec3<f32>) -> f32 {
    let n = u32(hyper.grid_min.w);
    return grid_sample(x, n * n * n).x;
}

// The grid block starting at `base` at x, trilinear. No loops: no loop budget spent.
fn grid_sample(x: vec3<f32>, base: u32) -> vec4<f32> {
    let n = u32(hyper.grid_min.w);
    let lo = hyper.grid_min.xyz;
    let u = clamp((x - lo) / (hyper.grid_max.xyz - lo), vec3<f32>(0.0), vec3<f32>(1.0)) * f32(n - 1u);
    let i = min(vec3<u32>(u), vec3<u32>(n - 2u));
    let f = u - vec3<f32>(i);
    let x0 = mix(mesh_cell(i, n, base), mesh_cell(i + vec3<u32>(1u, 0u, 0u), n, base), f.x);
    let x1 = mix(mesh_cell(i + vec3<u32>(0u, 1u, 0u), n, base), mesh_cell(i + vec3<u32>(1u, 1u, 0u), n, base), f.x);
    let x2 = mix(mesh_cell(i + vec3<u32>(0u, 0u, 1u), n, base), mesh_cell(i + vec3<u32>(1u, 0u, 1u), n, base), f.x);
    let x3 = mix(mesh_cell(i + vec3<u32>(0u, 1u, 1u), n, base), mesh_cell(i + vec3<u32>(1u, 1u, 1u), n, base), f.x);
    return mix(mix(x0, x1, f.y), mix(x2, x3, f.y), f.z);
}

// O(x): sphere 1 - |x| / r; ellipsoid 1 - |x / radii|; torus (axis z) 1 - (distance to the core
// circle) / minor; box 1 - max_i |x_i| / half_i; mesh: the inside distance over the largest
// inside distance; points: the kernel sum over the saturation. Clamped to [0, 1].
fn object_density(x: vec3<f32>) -> f32 {
    let s = hyper.object;
    var d = 0.0;
    switch hyper.kinds.x {
        case OBJECT_ELLIPSOID: {
            d = 1.0 - length(x / s.xyz);
        }
        case OBJECT_TORUS: {
            d = 1.0 - length(vec2<f32>(length(x.xy) - s.x, x.z)) / s.y;
        }
        case OBJECT_BOX: {
            let q = abs(x) / s.xyz;
            d = 1.0 - max(max(q.x, q.y), q.z);
        }
        case OBJECT_MESH: {
            d = mesh_sample(x).w / bitcast<f32>(mesh_depth[0]);
        }
        case OBJECT_POINTS: {
            d = points_density(x);
        }
        default: {
            d = 1.0 - length(x) / s.x;
        }
    }
    return clamp(d, 0.0, 1.0);
}

// A lower bound of the distance from x to where the object's density is positive: exact for
// the sphere, torus and box; for the ellipsoid (|x / radii| - 1) times its smallest radius; for a
// mesh the distance to the grid's box outside it, and inside it the interpolated outside distance
// over sqrt(3) (trilinear interpolation of samples of a distance rises at most that fast); for a
// point set the interpolated distance to its kernels' balls less two grid-cell diagonals (the
// interpolated density is positive at most a diagonal beyond a sample inside a ball, and the
// interpolated distance at most a diagonal above the distance to that sample).
fn support_distance(x: vec3<f32>) -> f32 {
    let s = hyper.object;
    switch hyper.kinds.x {
        case OBJECT_ELLIPSOID: {
            return (length(x / s.xyz) - 1.0) * min(min(s.x, s.y), s.z);
        }
        case OBJECT_TORUS: {
            return length(vec2<f32>(length(x.xy) - s.x, x.z)) - s.y;
        }
        case OBJECT_BOX: {
            let q = abs(x) - s.xyz;
            return length(max(q, vec3<f32>(0.0))) + min(max(max(q.x, q.y), q.z), 0.0);
        }
        case OBJECT_MESH: {
            let out = max(hyper.grid_min.xyz - x, x - hyper.grid_max.xyz);
            if (any(out > vec3<f32>(0.0))) {
                return length(max(out, vec3<f32>(0.0)));
            }
            return -mesh_sample(x).w * 0.57735;
        }
        case OBJECT_POINTS: {
            let out = max(hyper.grid_min.xyz - x, x - hyper.grid_max.xyz);
            if (any(out > vec3<f32>(0.0))) {
                return length(max(out, vec3<f32>(0.0)));
            }
            let cell = (hyper.grid_max.x - hyper.grid_min.x) / (hyper.grid_min.w - 1.0);
            return -mesh_sample(x).w - 3.4641016 * cell;
        }
        default: {
            return length(x) - s.x;
        }
    }
}

// The closest point of the object's boundary (ellipsoid: the radial projection, exact on its
// axes; mesh: from the grid, taken at the closest point of the grid's box outside it). Where it
// is not unique and has no preferred direction (a sphere's centre, a torus's core circle) x
// itself, so the field vanishes there.
fn closest_surface_point(x: vec3<f32>) -> vec3<f32> {
    let s = hyper.object;
    switch hyper.kinds.x {
        case OBJECT_ELLIPSOID: {
            let k = length(x / s.xyz);
            return select(x, x / k, k > TINY);
        }
        case OBJECT_TORUS: {
            let r = length(x.xy);
            let around = select(vec2<f32>(1.0, 0.0), x.xy / r, r > TINY);
            let ring = vec3<f32>(around * s.x, 0.0);
            let q = x - ring;
            let len = length(q);
            return select(x, ring + q * (s.y / len), len > TINY);
        }
        case OBJECT_BOX: {
            let h = s.xyz;
            let a = abs(x);
            if (any(a > h)) {
                return clamp(x, -h, h);
            }
            // Inside: onto the nearest face.
            let gap = h - a;
            let side = select(vec3<f32>(-1.0), vec3<f32>(1.0), x >= vec3<f32>(0.0));
            var p = x;
            if (gap.x <= gap.y && gap.x <= gap.z) {
                p.x = side.x * h.x;
            } else if (gap.y <= gap.z) {
                p.y = side.y * h.y;
            } else {
                p.z = side.z * h.z;
            }
            return p;
        }
        case OBJECT_MESH, OBJECT_POINTS: {
            let c = clamp(x, hyper.grid_min.xyz, hyper.grid_max.xyz);
            return c + mesh_sample(c).xyz;
        }
        default: {
            let len = length(x);
            return select(x, x * (s.x / len), len > TINY);
        }
    }
}

// The unperturbed field: towards the closest surface point; away from a shifted centre (inside the
// object, towards it outside) with the closest-surface length; a constant vector; or the
// closest-surface vector turned around an axis by `twist` (its tangential part over its length).
fn base_field(x: vec3<f32>) -> vec3<f32> {
    let c = closest_surface_point(x) - x;
    switch hyper.kinds.y {
        case FIELD_FROM_CENTRE: {
            let side = select(-1.0, 1.0, object_density(x) > 0.0);
            return unit_or_zero(x - hyper.field.xyz) * (side * length(c));
        }
        case FIELD_CONSTANT: {
            return hyper.field.xyz;
        }
        case FIELD_SWIRL: {
            let around = unit_or_zero(cross(hyper.field.xyz, x - hyper.field_center.xyz));
            return c + around * (hyper.field.w * length(c));
        }
        default: {
            return c;
        }
    }
}

// V(x): the base field, perturbed when `perturb.y` (a frequency) is positive: its direction by a
// vector noise scaled by `perturb.x` times its length, its length by 1 + perturb.z * noise.
fn vector_field(x: vec3<f32>) -> vec3<f32> {
    var v = base_field(x);
    let p = hyper.perturb;
    if (p.y > 0.0) {
        let q = x * p.y;
        let seed = hyper.kinds.w;
        let n = vec3<f32>(simplex3(q, seed), simplex3(q, seed + 1u), simplex3(q, seed + 2u));
        v = (v + n * (p.x * length(v))) * (1.0 + p.z * simplex3(q, seed + 3u));
    }
    return v;
}
