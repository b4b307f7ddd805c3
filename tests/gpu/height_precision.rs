//! Height fields from 16-bit PNGs keep their fine steps: a ramp rising by two 8-bit steps across
//! the image, read from a 16-bit PNG, baked by `bake_height_image.wgsl`. A column's baked height
//! (the sum of its voxels' coverage over a cubic texel) follows the 16-bit ramp, far closer than
//! the ramp's own 8-bit quantisation, in the f32 bake (`voltex export`, `bake --depth 32`) and
//! in the render's 8-bit volume alike.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use voltex::bake::Baker;
use voltex::gpu::readback::read_texture;
use voltex::gpu::sources::Sources;

const N: u32 = 32; // voxels per axis
const PIXELS: u32 = 64; // ramp pixels along s

/// The ramp's value at pixel `x`: from 0.4 up by 2/255 across the image, on the 16-bit grid.
fn ramp(x: u32) -> u16 {
    ((0.4 + x as f64 / (PIXELS - 1) as f64 * 2.0 / 255.0) * 65535.0).round() as u16
}

/// The ramp sampled bilinearly at column `i`'s centre (pixel centres at (x + 0.5) / PIXELS),
/// from `value(x)`.
fn at_column(i: u32, value: impl Fn(u32) -> f64) -> f64 {
    let x = (i as f64 + 0.5) / N as f64 * PIXELS as f64 - 0.5;
    let x0 = x.floor() as u32;
    value(x0) * (1.0 - x.fract()) + value(x0 + 1) * x.fract()
}

#[test]
fn sixteen_bit_height_images_keep_their_fine_steps() {
    let dir = std::env::temp_dir().join(format!("voltex-height16-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let pixels: Vec<[u16; 4]> = (0..4).flat_map(|_| (0..PIXELS).map(|x| [ramp(x), 0, 0, u16::MAX])).collect();
    voltex::io::png::write_rgba16(&dir.join("ramp.png"), PIXELS, 4, &pixels).unwrap();
    let text = format!(
        "Scene(output: (width: 16, height: 16), camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)),\n\
         texels: {{ \"ramp\": (resolution: ({N}, 4, {N}), source: ImageHeight(image: \"ramp.png\", amplitude: 1.0,\n\
         color_low: (1.0, 1.0, 1.0), color_high: (1.0, 1.0, 1.0))) }})"
    );
    let path = dir.join("ramp.ron");
    std::fs::write(&path, text).unwrap();
    let scene = voltex::scene::load(&path).unwrap();
    let plan = voltex::render::baked_texel(&scene, "ramp").unwrap();
    let sources = Sources::project().unwrap();
    let (full, eight) = {
        let ctx = gpu!(ADAPTER);
        let full = Baker::full_precision(&sources).bake(&ctx, &plan.request).unwrap();
        let eight = Baker::new(&sources).bake(&ctx, &plan.request).unwrap();
        (read_texture(&ctx, &full.volume, 16).unwrap(), read_texture(&ctx, &eight.volume, 4).unwrap())
    };
    let full: Vec<f32> = bytemuck::pod_collect_to_vec(&full);
    let alpha = |i: u32, k: u32, full_precision: bool| {
        let v = (i + N * (1 + 4 * k)) as usize * 4 + 3; // row t = 1 of 4
        if full_precision {
            full[v] as f64
        } else {
            eight[v] as f64 / 255.0
        }
    };
    let height = |i: u32, f: bool| (0..N).map(|k| alpha(i, k, f)).sum::<f64>() / N as f64;
    let sixteen = |x: u32| ramp(x.min(PIXELS - 1)) as f64 / 65535.0;
    let eight_bit = |x: u32| (sixteen(x) * 255.0).round() / 255.0;
    let (mut err_full, mut err_eight, mut err_quantised) = (0.0f64, 0.0f64, 0.0f64);
    // Columns away from the wrap, where the bilinear ramp is the straight line.
    for i in 1..N - 1 {
        let truth = at_column(i, sixteen);
        err_full = err_full.max((height(i, true) - truth).abs());
        err_eight = err_eight.max((height(i, false) - truth).abs());
        err_quantised = err_quantised.max((at_column(i, eight_bit) - truth).abs());
    }
    eprintln!("column heights vs the 16-bit ramp: f32 bake {err_full:.2e}, rgba8 bake {err_eight:.2e}; the ramp at 8 bits {err_quantised:.2e}");
    assert!(err_quantised > 1e-3, "the ramp's 8-bit steps must be visible: {err_quantised}");
    assert!(err_full < 2e-5, "f32 bake: {err_full}");
    assert!(err_eight < 1.5e-4, "rgba8 bake: {err_eight}");
    std::fs::remove_dir_all(&dir).unwrap();
}
