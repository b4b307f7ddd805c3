// Periodic 2D Perlin noise with its analytic gradient, seeded by an integer hash (no permutation
// table). CPU twin: src/cpu/bake.rs (same names).

// PCG hash (Jarzynski & Olano 2020): a good 32-bit integer hash, cheap on GPUs.
fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Unit gradient of lattice point `cell`, wrapped by `period` so the noise tiles.
// Eight directions picked by a switch (not sin/cos) so CPU and GPU agree bit for bit.
fn lattice_gradient(cell: vec2<i32>, period: i32, seed: u32) -> vec2<f32> {
    let c = vec2<u32>(((cell % period) + period) % period);
    let h = pcg_hash(c.x + pcg_hash(c.y + pcg_hash(seed))) & 7u;
    let d = 0.70710678;
    var g = vec2<f32>(1.0, 0.0);
    switch h {
        case 1u: { g = vec2<f32>(d, d); }
        case 2u: { g = vec2<f32>(0.0, 1.0); }
        case 3u: { g = vec2<f32>(-d, d); }
        case 4u: { g = vec2<f32>(-1.0, 0.0); }
        case 5u: { g = vec2<f32>(-d, -d); }
        case 6u: { g = vec2<f32>(0.0, -1.0); }
        case 7u: { g = vec2<f32>(d, -d); }
        default: {}
    }
    return g;
}

// Perlin noise of `p` (tile units: period 1 in x and y) on a lattice of `period` cells per tile.
// Returns (value, d value/dp) with the value in [-1,1] (sqrt 2 times classic 2D Perlin, whose
// bound with unit gradients is sqrt(2)/2). The quintic fade makes the gradient continuous.
fn perlin_periodic(p: vec2<f32>, period: u32, seed: u32) -> vec3<f32> {
    let fp = f32(period);
    let q = p * fp;
    let cell_f = floor(q);
    let f = q - cell_f;
    let cell = vec2<i32>(cell_f);
    let per = i32(period);
    let g00 = lattice_gradient(cell, per, seed);
    let g10 = lattice_gradient(cell + vec2<i32>(1, 0), per, seed);
    let g01 = lattice_gradient(cell + vec2<i32>(0, 1), per, seed);
    let g11 = lattice_gradient(cell + vec2<i32>(1, 1), per, seed);
    let n00 = dot(g00, f);
    let n10 = dot(g10, f - vec2<f32>(1.0, 0.0));
    let n01 = dot(g01, f - vec2<f32>(0.0, 1.0));
    let n11 = dot(g11, f - vec2<f32>(1.0, 1.0));
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let du = 30.0 * f * f * (f * (f - 2.0) + 1.0);
    let k = n00 - n10 - n01 + n11;
    let value = n00 + u.x * (n10 - n00) + u.y * (n01 - n00) + u.x * u.y * k;
    let gk = g00 - g10 - g01 + g11;
    let grad = g00 + u.x * (g10 - g00) + u.y * (g01 - g00) + u.x * u.y * gk
        + du * vec2<f32>(n10 - n00 + u.y * k, n01 - n00 + u.x * k);
    return vec3<f32>(value, grad * fp) * 1.41421356;
}

// Fractal sum of `octaves` periodic Perlin octaves (frequency doubles, amplitude halves), normalized
// back to [-1,1]. Returns (value, gradient) like `perlin_periodic`.
fn perlin_fbm_periodic(p: vec2<f32>, frequency: u32, octaves: u32, seed: u32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    var amplitude = 1.0;
    var total = 0.0;
    var period = max(frequency, 1u);
    let count = clamp(octaves, 1u, 16u);
    for (var o = 0u; o < count; o++) {
        sum += amplitude * perlin_periodic(p, period, seed ^ (o * 2654435769u));
        total += amplitude;
        amplitude *= 0.5;
        period *= 2u;
    }
    return sum / total;
}
