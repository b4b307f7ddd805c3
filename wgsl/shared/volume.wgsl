// Sampling a sparse volume: the brick table (`volume_table`: a top grid of 128^3-voxel cells
// naming nodes of 16^3 brick numbers, brick 0 empty) and the atlases of 9^3-value bricks
// (`volume_density`, `volume_color`). Reads the kernel's `volume_params`, `volume_table`,
// `volume_density` and `volume_color`. CPU twin: src/vdb/sparse.rs (`locate`, `sample`).

const VOLUME_LEAF: i32 = 8;
const VOLUME_NODE: i32 = 16;
const VOLUME_BRICK: i32 = 9;
const VOLUME_NO_NODE: u32 = 0xffffffffu;

// The brick of the cell whose lower corner is voxel c (x), or 0 with the side in voxels of the
// empty box around c that holds no density (y: 8 for an empty leaf, 128 for an empty top cell).
fn volume_brick(c: vec3<i32>) -> vec2<u32> {
    let rel = c - volume_params.origin.xyz;
    let span = VOLUME_LEAF * VOLUME_NODE;
    let t = vec3<i32>(floor(vec3<f32>(rel) / f32(span)));
    let top = vec3<i32>(volume_params.table.xyz);
    if (any(t < vec3<i32>(0)) || any(t >= top)) {
        return vec2<u32>(0u, u32(span));
    }
    let node = volume_table[u32(t.x + top.x * (t.y + top.y * t.z))];
    if (node == VOLUME_NO_NODE) {
        return vec2<u32>(0u, u32(span));
    }
    let l = (rel - t * span) / VOLUME_LEAF;
    let brick = volume_table[node + u32(l.x + VOLUME_NODE * (l.y + VOLUME_NODE * l.z))];
    return vec2<u32>(brick, u32(VOLUME_LEAF));
}

// The atlas texel of value q (0..9 per axis) of brick b.
fn volume_texel(b: u32, q: vec3<i32>) -> vec3<i32> {
    let sx = volume_params.atlas.x;
    let sy = volume_params.atlas.y;
    let slot = vec3<u32>(b % sx, (b / sx) % sy, b / (sx * sy));
    return vec3<i32>(slot) * VOLUME_BRICK + q;
}

// The eight density values at the corners of the cell with lower corner c (zeros outside any
// brick), x fastest. Unrolled: lavapipe counts every loop iteration against its limit.
fn volume_corners(c: vec3<i32>) -> array<f32, 8> {
    let b = volume_brick(c).x;
    if (b == 0u) {
        return array<f32, 8>(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    }
    let q = volume_texel(b, c - vec3<i32>(floor(vec3<f32>(c) / f32(VOLUME_LEAF))) * VOLUME_LEAF);
    return array<f32, 8>(
        textureLoad(volume_density, q, 0).x,
        textureLoad(volume_density, q + vec3<i32>(1, 0, 0), 0).x,
        textureLoad(volume_density, q + vec3<i32>(0, 1, 0), 0).x,
        textureLoad(volume_density, q + vec3<i32>(1, 1, 0), 0).x,
        textureLoad(volume_density, q + vec3<i32>(0, 0, 1), 0).x,
        textureLoad(volume_density, q + vec3<i32>(1, 0, 1), 0).x,
        textureLoad(volume_density, q + vec3<i32>(0, 1, 1), 0).x,
        textureLoad(volume_density, q + vec3<i32>(1, 1, 1), 0).x,
    );
}

// The trilinear interpolant of cell corners `k` at fractions f in [0, 1]^3.
fn volume_lerp(k: array<f32, 8>, f: vec3<f32>) -> f32 {
    let x0 = mix(mix(k[0], k[1], f.x), mix(k[2], k[3], f.x), f.y);
    let x1 = mix(mix(k[4], k[5], f.x), mix(k[6], k[7], f.x), f.y);
    return mix(x0, x1, f.z);
}

// Density at index point p: the trilinear interpolant of the voxels.
fn volume_density_at(p: vec3<f32>) -> f32 {
    let c = floor(p);
    return volume_lerp(volume_corners(vec3<i32>(c)), p - c);
}

// Colour at index point p (white without a colour grid).
fn volume_color_at(p: vec3<f32>) -> vec3<f32> {
    if (volume_params.table.w == 0u) {
        return vec3<f32>(1.0);
    }
    let c = floor(p);
    let ci = vec3<i32>(c);
    let b = volume_brick(ci).x;
    if (b == 0u) {
        return vec3<f32>(0.0);
    }
    let q = volume_texel(b, ci - vec3<i32>(floor(c / f32(VOLUME_LEAF))) * VOLUME_LEAF);
    let f = p - c;
    let y0 = mix(
        mix(textureLoad(volume_color, q, 0).xyz, textureLoad(volume_color, q + vec3<i32>(1, 0, 0), 0).xyz, f.x),
        mix(textureLoad(volume_color, q + vec3<i32>(0, 1, 0), 0).xyz, textureLoad(volume_color, q + vec3<i32>(1, 1, 0), 0).xyz, f.x),
        f.y,
    );
    let y1 = mix(
        mix(textureLoad(volume_color, q + vec3<i32>(0, 0, 1), 0).xyz, textureLoad(volume_color, q + vec3<i32>(1, 0, 1), 0).xyz, f.x),
        mix(textureLoad(volume_color, q + vec3<i32>(0, 1, 1), 0).xyz, textureLoad(volume_color, q + vec3<i32>(1, 1, 1), 0).xyz, f.x),
        f.y,
    );
    return mix(y0, y1, f.z);
}

// Parameters (entry, exit) where the ray o + t d (index space) is inside the box lo..hi;
// entry > exit when it misses. Zero direction components are nudged, never divided by.
fn volume_span(o: vec3<f32>, d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    let tiny = vec3<f32>(1e-30);
    let safe = select(d, select(-tiny, tiny, d >= vec3<f32>(0.0)), abs(d) < tiny);
    let a = (lo - o) / safe;
    let b = (hi - o) / safe;
    return vec2<f32>(max(max(min(a.x, b.x), min(a.y, b.y)), min(a.z, b.z)), min(min(max(a.x, b.x), max(a.y, b.y)), max(a.z, b.z)));
}
