//! The implicit and Perlin height-field bake kernels against their CPU twins
//! (`src/cpu/bake.rs`): every voxel of a texel in both lightings (baked shading; albedo and
//! normals for per-pixel lighting), on shapes of every kind and a several-octave field.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use voltex::bake::{BakeRequest, BakeSource, Baker};
use voltex::cpu::bake::{bake_heightfield, bake_implicit, bake_params, pack_shapes, Primitive, TexelVoxels};
use voltex::gpu::readback::read_texture;

/// Bakes `source` on the GPU: the colour (rgba8unorm) and normal (rgba8snorm) volumes.
fn bake(
    source: BakeSource,
    res: [u32; 3],
    per_pixel: bool,
    light: [f32; 3],
    ambient: f32,
) -> (Vec<u8>, Vec<u8>) {
    let request = BakeRequest {
        resolution: res,
        source,
        per_pixel,
        light,
        ambient,
        derived: Default::default(),
        layers: false,
        shadow: None,
    };
    let ctx = gpu!(ADAPTER);
    let baked = Baker::new(&voltex::gpu::sources::Sources::project().unwrap()).bake(&ctx, &request).unwrap();
    let volume = read_texture(&ctx, &baked.volume, 4).unwrap();
    let normals = if per_pixel { read_texture(&ctx, &baked.normals, 4).unwrap() } else { Vec::new() };
    (volume, normals)
}

/// Compares the GPU's volumes with the twin's: (voxels off by more than one 8-bit step, the
/// worst step, voxels with matter, the worst normal difference where there is matter).
fn compare(
    res: [u32; 3],
    gpu: &(Vec<u8>, Vec<u8>),
    twin: &(TexelVoxels, TexelVoxels),
) -> (u32, i32, u32, f32) {
    let (mut off, mut worst, mut matter, mut worst_normal) = (0, 0, 0, 0.0f32);
    for z in 0..res[2] {
        for y in 0..res[1] {
            for x in 0..res[0] {
                let v = [x, y, z];
                let i = 4 * twin.0.index(v);
                let c = twin.0.get(v);
                let d = (0..4)
                    .map(|k| (gpu.0[i + k] as i32 - (c[k] * 255.0).round() as i32).abs())
                    .max()
                    .unwrap();
                worst = worst.max(d);
                off += (d > 1) as u32;
                if c[3] > 0.05 {
                    matter += 1;
                    if !gpu.1.is_empty() {
                        let n = twin.1.get(v);
                        let g = |k: usize| (gpu.1[i + k] as i8 as f32 / 127.0).max(-1.0);
                        worst_normal = (0..3).map(|k| (g(k) - n[k]).abs()).fold(worst_normal, f32::max);
                    }
                }
            }
        }
    }
    (off, worst, matter, worst_normal)
}

/// `bake_implicit.wgsl`: a sphere, a torus, an ellipsoid and metaballs in one union (the
/// nearest shape colours a voxel), on a texel whose sides differ; every voxel within one 8-bit
/// step but a few where a surface crosses it, normals within 8-bit rounding.
#[test]
fn implicit_bake_matches_its_twin() {
    let shapes = [
        (Primitive::Sphere { center: [0.3, 0.35, 0.45], radius: 0.22 }, [0.9, 0.3, 0.2], 0.8),
        (Primitive::Torus { center: [0.65, 0.6, 0.4], major: 0.22, minor: 0.07 }, [0.2, 0.7, 0.3], 1.0),
        (Primitive::Ellipsoid { center: [0.7, 0.25, 0.6], radii: [0.15, 0.1, 0.3] }, [0.3, 0.4, 0.9], 0.5),
        (
            Primitive::Metaballs {
                balls: vec![([0.25, 0.75, 0.3], 0.12), ([0.38, 0.8, 0.35], 0.1)],
                threshold: 0.5,
            },
            [0.8, 0.8, 0.2],
            0.9,
        ),
    ];
    let packed = pack_shapes(&shapes);
    let res = [24, 20, 16];
    let (light, ambient) = ([0.3, 0.4, 0.8], 0.3);
    for per_pixel in [false, true] {
        let gpu = bake(BakeSource::Implicit(packed.clone()), res, per_pixel, light, ambient);
        let twin = bake_implicit(&bake_params(res, shapes.len() as u32, light, ambient), &packed, per_pixel);
        let (off, worst, matter, normal) = compare(res, &gpu, &twin);
        let n = res.iter().product::<u32>();
        println!("implicit, per_pixel {per_pixel}: {matter} of {n} voxels with matter, {off} off by more than a step (worst {worst}), normals {normal:.3}");
        assert!(matter > n / 10 && matter < n / 2, "{matter} voxels with matter");
        assert!(off * 500 < n && worst <= 4, "per_pixel {per_pixel}: {off} voxels off, worst {worst}");
        assert!(normal < 0.02, "per_pixel {per_pixel}: normals differ by {normal}");
    }
}

/// `bake_heightfield.wgsl`: a four-octave periodic Perlin field with darkening, both lightings.
#[test]
fn heightfield_bake_matches_its_twin() {
    let hf = voltex::types::HeightfieldParams {
        frequency: 3,
        octaves: 4,
        seed: 7,
        amplitude: 0.6,
        base: 0.15,
        opacity: 0.9,
        darkening: 0.6,
        color_low: [0.2, 0.3, 0.1, 0.0],
        color_high: [0.6, 0.8, 0.3, 0.0],
        ..Default::default()
    };
    let res = [32, 24, 16];
    let (light, ambient) = ([-0.3, 0.5, 0.8], 0.25);
    for per_pixel in [false, true] {
        let gpu = bake(BakeSource::Heightfield(hf), res, per_pixel, light, ambient);
        let twin = bake_heightfield(&bake_params(res, 0, light, ambient), &hf, per_pixel);
        let (off, worst, matter, normal) = compare(res, &gpu, &twin);
        let n = res.iter().product::<u32>();
        println!("heightfield, per_pixel {per_pixel}: {matter} of {n} voxels with matter, {off} off by more than a step (worst {worst}), normals {normal:.3}");
        assert!(matter > n / 5 && matter < n, "{matter} voxels with matter");
        assert!(off * 500 < n && worst <= 4, "per_pixel {per_pixel}: {off} voxels off, worst {worst}");
        assert!(normal < 0.02, "per_pixel {per_pixel}: normals differ by {normal}");
    }
}
