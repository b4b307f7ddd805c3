//! Known answers of the baked self-shadowing: a uniform slab lit from above and at an angle,
//! and a column shadowing its neighbour across the tile's edge.

use super::*;

const N: u32 = 16;

/// A texel of `res` whose alpha is `alpha(x, y, z)` and colour 1 (premultiplied: alpha).
fn texel(res: [u32; 3], alpha: impl Fn(u32, u32, u32) -> f32) -> Vec<[f32; 4]> {
    let mut v = Vec::new();
    for z in 0..res[2] {
        for y in 0..res[1] {
            for x in 0..res[0] {
                let a = alpha(x, y, z);
                v.push([1.0, 0.5, 0.25, a]);
            }
        }
    }
    v
}

fn at(res: [u32; 3], v: &[[f32; 4]], x: u32, y: u32, z: u32) -> [f32; 4] {
    v[(x + res[0] * (y + res[1] * z)) as usize]
}

#[test]
fn a_slab_lit_from_above_falls_off_as_exp_of_depth() {
    // The bottom 12 of 16 layers hold alpha 0.5, the top 4 are empty.
    let res = [8, 8, N];
    let (a, sigma) = (0.5, 6.0);
    let v = texel(res, |_, _, z| if z < 12 { a } else { 0.0 });
    for bias in [0.0, 1.5] {
        let p = shadow_params(res, [0.0, 0.0, 1.0], sigma, 0.0, bias as f32);
        let out = shadow_texel(&p, &v);
        for z in 0..N {
            // From `bias` voxels above the voxel's centre up to the slab's top (w = 12 / N).
            let depth = (12.0 - (z as f64 + 0.5) - bias).max(0.0) / N as f64;
            let expected = (-sigma as f64 * a as f64 * depth).exp();
            let got = at(res, &out, 3, 5, z)[0] as f64;
            assert!((got - expected).abs() < 1e-6, "bias {bias}, layer {z}: {got} against {expected}");
            assert_eq!(at(res, &out, 3, 5, z)[3], at(res, &v, 3, 5, z)[3], "alpha is kept");
        }
    }
}

#[test]
fn a_slab_lit_at_an_angle_falls_off_as_exp_of_depth_over_cos() {
    // A slab filling the box (x, y wrap, so it is infinite); light 50 degrees off the vertical,
    // along a direction that is not a lattice one, through a box that is not cubic.
    let res = [12, 20, N];
    let (a, sigma) = (0.75, 3.0);
    let v = texel(res, |_, _, _| a);
    let theta = 50f64.to_radians();
    let toward = [(theta.sin() * 0.6) as f32, (theta.sin() * 0.8) as f32, theta.cos() as f32];
    for ambient in [0.0, 0.25] {
        let p = shadow_params(res, toward, sigma, ambient, 0.0);
        let out = shadow_texel(&p, &v);
        for z in 0..N {
            let depth = (N as f64 - (z as f64 + 0.5)) / N as f64;
            let t = (-sigma as f64 * a as f64 * depth / theta.cos()).exp();
            let expected = 0.5 * (ambient as f64 + (1.0 - ambient as f64) * t);
            for (x, y) in [(0, 0), (7, 13), (11, 19)] {
                let got = at(res, &out, x, y, z)[1] as f64;
                assert!((got - expected).abs() < 1e-6, "({x}, {y}, {z}): {got} against {expected}");
            }
        }
    }
}

#[test]
fn a_column_shadows_its_neighbour_across_the_tile_edge() {
    // An opaque column at x = 0; light towards +x and up at 45 degrees (cubic texel). The voxel
    // at x = N - 1 reaches the light through the column's copy in the next tile (x = N), crossing
    // it along a diagonal sqrt(2) / N long; x = N - 2 crosses it too, after one empty voxel.
    let res = [N, 4, N];
    let sigma = 8.0;
    let v = texel(res, |x, _, _| if x == 0 { 1.0 } else { 0.0 });
    let p = shadow_params(res, [1.0, 0.0, 1.0], sigma, 0.0, 0.0);
    let out = shadow_texel(&p, &v);
    let through_column = (-sigma as f64 * 2f64.sqrt() / N as f64).exp();
    for z in 0..N - 2 {
        for x in [N - 1, N - 2] {
            let got = at(res, &out, x, 1, z)[0] as f64;
            assert!((got - through_column).abs() < 1e-6, "({x}, {z}): {got} against {through_column}");
        }
    }
    // The voxel right of the column (x = 1) sees the light without crossing it: lit.
    assert_eq!(at(res, &out, 1, 1, 3)[0], 1.0);
    // Without the wrap the same voxel would be lit: the column is not on its way inside the tile.
    assert!(through_column < 0.55);
}

#[test]
fn a_horizontal_light_ends_after_the_step_limit() {
    let res = [8, 8, 8];
    let v = texel(res, |_, _, _| 0.0);
    let p = shadow_params(res, [1.0, 0.0, 0.0], 4.0, 0.0, 0.0);
    assert_eq!(shadow_texel(&p, &v), v, "empty texel, light along s: unshadowed, and the march ends");
}

#[test]
fn a_voxel_inside_a_solid_takes_the_shadow_where_the_light_enters_it() {
    // An opaque slab (z < 10) under a semi-transparent layer (10 <= z < 13): every voxel of the
    // slab gets the layer's transmittance, as its top surface does; the layer's own voxels
    // count what is above them.
    let res = [4, 4, N];
    let sigma = 4.0;
    let v = texel(res, |_, _, z| match z {
        0..10 => 1.0,
        10..13 => 0.5,
        _ => 0.0,
    });
    let out = shadow_texel(&shadow_params(res, [0.0, 0.0, 1.0], sigma, 0.0, 0.0), &v);
    let layer = (-sigma as f64 * 0.5 * 3.0 / N as f64).exp();
    for z in 0..10 {
        assert!((at(res, &out, 2, 1, z)[0] as f64 - layer).abs() < 1e-6, "slab layer {z}");
    }
    let middle = (-sigma as f64 * 0.5 * 1.5 / N as f64).exp();
    assert!((at(res, &out, 2, 1, 11)[0] as f64 - middle).abs() < 1e-6);
}
