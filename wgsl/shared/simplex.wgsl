// 3D simplex noise (Gustavson 2005, "Simplex noise demystified", the noise the paper uses) with
// gradients picked by an integer hash of the lattice corner and a seed instead of a permutation
// table, so every noise of a hypertexture is independent. CPU twin: src/cpu/noise_simplex.rs.
#include "shared/noise.wgsl"

// The gradient of corner `c` dotted with `x`: the 12 cube-edge directions (Perlin 2002's selection
// from 4 hash bits), chosen by comparisons only so that CPU and GPU pick the same one.
fn simplex_gradient(c: vec3<i32>, seed: u32, x: vec3<f32>) -> f32 {
    let h = pcg_hash(bitcast<u32>(c.x) + pcg_hash(bitcast<u32>(c.y) + pcg_hash(bitcast<u32>(c.z) + pcg_hash(seed)))) & 15u;
    let u = select(x.y, x.x, h < 8u);
    let v = select(select(x.z, x.x, h == 12u || h == 14u), x.y, h < 4u);
    return select(-u, u, (h & 1u) == 0u) + select(-v, v, (h & 2u) == 0u);
}

// Periodic noise: a point moved by 3a cells along x moves its skewed lattice coordinates by the
// whole vector (4a, a, a) (likewise b along y, c along z), so the noise repeats if corners that
// differ by those vectors get one gradient. They do when hashed by their class: with
// w = (5x - y - z, 5y - z - x, 5z - x - y), two corners differ by such vectors exactly when their
// w agree modulo (18a, 18b, 18c) (18 w / (18a, 18b, 18c) are the coordinates in that basis).
fn simplex_wrap(c: vec3<i32>, tile: vec3<i32>) -> vec3<i32> {
    if (tile.x <= 0) {
        return c;
    }
    let w = vec3<i32>(5 * c.x - c.y - c.z, 5 * c.y - c.z - c.x, 5 * c.z - c.x - c.y);
    let m = 18 * tile;
    return ((w % m) + m) % m;
}

// One corner's contribution: (0.6 - |x|^2)^4 (g . x) inside its sphere of influence.
fn simplex_corner(c: vec3<i32>, seed: u32, x: vec3<f32>, tile: vec3<i32>) -> f32 {
    let t = 0.6 - dot(x, x);
    if (t <= 0.0) {
        return 0.0;
    }
    let t2 = t * t;
    return t2 * t2 * simplex_gradient(simplex_wrap(c, tile), seed, x);
}

// Simplex noise of `p` in [-1, 1] (32 times the corner sum, clamped). No loops: lavapipe counts
// loop iterations per invocation (see ray_march.wgsl).
fn simplex3(p: vec3<f32>, seed: u32) -> f32 {
    return simplex3_tiled(p, seed, vec3<i32>(0));
}

// Simplex noise repeating every (3a, 3b, 3c) cells when `tile` = (a, b, c) > 0 (0: not periodic).
fn simplex3_tiled(p: vec3<f32>, seed: u32, tile: vec3<i32>) -> f32 {
    let skew = (p.x + p.y + p.z) * (1.0 / 3.0);
    let cell = floor(p + vec3<f32>(skew));
    let unskew = (cell.x + cell.y + cell.z) * (1.0 / 6.0);
    let x0 = p - cell + vec3<f32>(unskew);
    // Rank order of x0's coordinates decides which simplex of the cube holds p.
    let g = step(x0.yzx, x0.xyz);
    let l = vec3<f32>(1.0) - g;
    let i1 = min(g, l.zxy);
    let i2 = max(g, l.zxy);
    let x1 = x0 - i1 + vec3<f32>(1.0 / 6.0);
    let x2 = x0 - i2 + vec3<f32>(1.0 / 3.0);
    let x3 = x0 - vec3<f32>(0.5);
    let c = vec3<i32>(cell);
    let n = simplex_corner(c, seed, x0, tile) + simplex_corner(c + vec3<i32>(i1), seed, x1, tile)
        + simplex_corner(c + vec3<i32>(i2), seed, x2, tile) + simplex_corner(c + vec3<i32>(1), seed, x3, tile);
    return clamp(32.0 * n, -1.0, 1.0);
}

// The gradient of 4D corner `c` dotted with `x`: the 32 edge midpoints of a tesseract (one
// coordinate 0, the others +-1; Gustavson's grad4) from 5 hash bits.
fn simplex_gradient4(c: vec4<i32>, seed: u32, x: vec4<f32>) -> f32 {
    let h = pcg_hash(bitcast<u32>(c.x) + pcg_hash(bitcast<u32>(c.y) + pcg_hash(bitcast<u32>(c.z)
        + pcg_hash(bitcast<u32>(c.w) + pcg_hash(seed))))) & 31u;
    // The three coordinates other than the zero one (h >> 3), in order.
    var o = x.yzw;
    switch h >> 3u {
        case 1u: { o = x.xzw; }
        case 2u: { o = x.xyw; }
        case 3u: { o = x.xyz; }
        default: {}
    }
    return select(-o.x, o.x, (h & 1u) == 0u) + select(-o.y, o.y, (h & 2u) == 0u) + select(-o.z, o.z, (h & 4u) == 0u);
}

fn simplex_corner4(c: vec4<i32>, seed: u32, x: vec4<f32>) -> f32 {
    let t = 0.6 - dot(x, x);
    if (t <= 0.0) {
        return 0.0;
    }
    let t2 = t * t;
    return t2 * t2 * simplex_gradient4(c, seed, x);
}

// 4D simplex noise in [-1, 1] (27 times the corner sum, clamped): the fourth coordinate is time,
// for animated hypertextures. The rank of each coordinate of x0 among the four picks the simplex.
fn simplex4(p: vec4<f32>, seed: u32) -> f32 {
    let f4 = 0.309016994374947451; // (sqrt(5) - 1) / 4
    let g4 = 0.138196601125010504; // (5 - sqrt(5)) / 20
    let skew = (p.x + p.y + p.z + p.w) * f4;
    let cell = floor(p + vec4<f32>(skew));
    let unskew = (cell.x + cell.y + cell.z + cell.w) * g4;
    let x0 = p - cell + vec4<f32>(unskew);
    let is_x = step(x0.yzw, x0.xxx);
    let is_yz = step(x0.zww, x0.yyz);
    var rank = vec4<f32>(is_x.x + is_x.y + is_x.z, vec3<f32>(1.0) - is_x);
    rank.y += is_yz.x + is_yz.y;
    rank.z += 1.0 - is_yz.x + is_yz.z;
    rank.w += 2.0 - is_yz.y - is_yz.z;
    let i1 = clamp(rank - vec4<f32>(2.0), vec4<f32>(0.0), vec4<f32>(1.0));
    let i2 = clamp(rank - vec4<f32>(1.0), vec4<f32>(0.0), vec4<f32>(1.0));
    let i3 = clamp(rank, vec4<f32>(0.0), vec4<f32>(1.0));
    let x1 = x0 - i1 + vec4<f32>(g4);
    let x2 = x0 - i2 + vec4<f32>(2.0 * g4);
    let x3 = x0 - i3 + vec4<f32>(3.0 * g4);
    let x4 = x0 - vec4<f32>(1.0 - 4.0 * g4);
    let c = vec4<i32>(cell);
    let n = simplex_corner4(c, seed, x0) + simplex_corner4(c + vec4<i32>(i1), seed, x1)
        + simplex_corner4(c + vec4<i32>(i2), seed, x2) + simplex_corner4(c + vec4<i32>(i3), seed, x3)
        + simplex_corner4(c + vec4<i32>(1), seed, x4);
    return clamp(27.0 * n, -1.0, 1.0);
}
