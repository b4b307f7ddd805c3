// The hypertexture density of Gilet & Dischler 2009 (eq. 3 to 5) and its RGBA transfer function.
// Reads the kernel's `hyper`, `hyper_noises` and `transfer_tables`. CPU twin:
// src/cpu/hypertexture.rs (same names).
#include "shared/fields.wgsl"
#include "shared/transfer.wgsl"

// O(x - k V/|V|) with k combining the noises in order from 0: noise i gives
// t_i = T_i((1 + noise(f_i (x + r_i V))) / 2) (2D functions: T_i(.., O(x)), eq. 6) and then
// k += a_i t_i (Sum), k = k (1 - a_i t_i / A) + a_i t_i (Blend: the paper's v1 (1 - v2) + v2 in
// units of the largest amplitude A) or k = k (1 - t_i) + a_i t_i (Mix); the noise is 4D when
// `animated`. One loop iteration per noise.
const OPERATOR_BLEND: u32 = 1u;
const OPERATOR_MIX: u32 = 2u;
// Evaluations of `hyper_density` that ran the noises, for benchmarks (per invocation).
var<private> noised_evaluations: u32;
// Benchmarks only: every noise reads 0 (and is compiled out), to measure what noise costs.
override noise_off: bool = false;
// Animated hypertextures: every noise is 4D, its fourth coordinate speed times the frame's time
// (`hyper.march.w`); set when some noise of the object has a speed.
override animated: bool = false;

// Points farther than the largest shift (`hyper.march.z`) from the object have density 0
// whatever the noises say (|k V/|V|| <= sum of amplitudes): they skip the noises.
fn hyper_density(x: vec3<f32>) -> f32 {
    if (support_distance(x) > hyper.march.z) {
        return 0.0;
    }
    noised_evaluations += 1u;
    let v = vector_field(x);
    let dir = unit_or_zero(v);
    // The second entry of 2D shape transfer functions (eq. 6): the object's density at x.
    let density = object_density(x);
    var k = 0.0;
    for (var i = 0u; i < hyper.kinds.z; i++) {
        let n = hyper_noises[i];
        var value = 0.0;
        let q = (x + n.shift * v) * n.frequency * n.scale.xyz;
        if (animated && !noise_off) {
            value = simplex4(vec4<f32>(q, n.speed * hyper.march.w), n.seed);
        } else if (!noise_off) {
            value = simplex3_tiled(q, n.seed, vec3<i32>(n.tile.xyz));
        }
        let t = shape_lookup(n, 0.5 + 0.5 * value, density);
        let term = n.amplitude * t;
        if (n.combine == OPERATOR_BLEND) {
            // The paper's v1 (1 - v2) + v2, in units of the largest amplitude (`scale.w`).
            k = k * (1.0 - select(0.0, term / n.scale.w, n.scale.w > 0.0)) + term;
        } else if (n.combine == OPERATOR_MIX) {
            k = k * (1.0 - t) + term;
        } else {
            k += term;
        }
    }
    return modulate(object_density(x - k * dir));
}

// Perlin's bias: t^(ln b / ln 0.5), so that bias(b, 0.5) = b; 0 and 1 stay.
fn perlin_bias(b: f32, t: f32) -> f32 {
    if (t <= 0.0) {
        return 0.0;
    }
    return pow(t, log(b) / log(0.5));
}

// Perlin's gain: two biases of 1 - g mirrored about t = 0.5, so that gain(g, 0.5) = 0.5.
fn perlin_gain(g: f32, t: f32) -> f32 {
    if (t < 0.5) {
        return 0.5 * perlin_bias(1.0 - g, 2.0 * t);
    }
    return 1.0 - 0.5 * perlin_bias(1.0 - g, 2.0 - 2.0 * t);
}

// The density modulation functions of the hypertexture (`bias`, `gain`: 0.5 is the identity).
fn modulate(density: f32) -> f32 {
    let m = hyper.modulation;
    if (m.x == 0.5 && m.y == 0.5) {
        return density;
    }
    return perlin_gain(m.y, perlin_bias(m.x, clamp(density, 0.0, 1.0)));
}

// A noise's shape transfer function at noise value u: its table, or with rows (a 2D function,
// eq. 6) its two rows around the object density o, joined linearly: bilinear over the grid.
fn shape_lookup(n: HyperNoise, u: f32, o: f32) -> f32 {
    if (n.rows <= 1u) {
        return transfer_lookup(n.table, u);
    }
    let r = clamp(o, 0.0, 1.0) * f32(n.rows - 1u);
    let row = min(u32(r), n.rows - 2u);
    let a = transfer_lookup(n.table + row, u);
    let b = transfer_lookup(n.table + row + 1u, u);
    return mix(a, b, r - f32(row));
}

// The first of the colour transfer's four tables: after the last noise's shape tables.
fn color_tables() -> u32 {
    let last = hyper_noises[hyper.kinds.z - 1u];
    return last.table + max(last.rows, 1u);
}

// Colour (straight rgb) and opacity per opacity length at a density: the four tables after the
// noises' shape tables.
fn hyper_color(density: f32) -> vec4<f32> {
    let first = color_tables();
    return vec4<f32>(
        transfer_lookup(first, density),
        transfer_lookup(first + 1u, density),
        transfer_lookup(first + 2u, density),
        transfer_lookup(first + 3u, density),
    );
}

// Opacity per opacity length at a density (the colour transfer's fourth table).
fn hyper_opacity(density: f32) -> f32 {
    return transfer_lookup(color_tables() + 3u, density);
}
