//! The reference renderer: the GPU kernel against its f64 CPU twin on every example scene, the
//! exact answer on an analytic box of fog (sides included), and brightness independent of the step.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use std::path::{Path, PathBuf};

use glam::DVec3;
use voltex::cpu::prism_map;
use voltex::gpu::GpuContext;
use voltex::io::Image;
use voltex::methods::reference::trace_reference::{self, TraceObject, TraceView};
use voltex::methods::reference::ReferenceSet;
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene;

fn reference(size: u32) -> RenderOptions {
    RenderOptions {
        size: Some((size, size)),
        method: Some(MethodKind::named("Reference").unwrap()),
        ..Default::default()
    }
}

fn example(name: &str) -> PathBuf {
    voltex::project_root().join("scenes/view_slices").join(name)
}

struct Traced {
    gpu: Image,
    cpu: Image,
    /// The most intervals any pixel's ray has (the kernel holds 16 per window).
    max_intervals: usize,
    /// The texel atlas the kernel read (rgba8).
    texels: Vec<u8>,
}

/// The kernel's premultiplied layer and the twin's, for the same frame and the same volumes.
fn gpu_and_twin(scene: &Path, opts: &RenderOptions) -> Traced {
    let scene = scene::load(scene).unwrap();
    let bp = Blueprint::new(&scene, opts).unwrap();
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    assert_eq!(voltex::metrics::count_nonfinite(&frame.image), 0, "no NaN or infinity in any pixel");
    let gpu = r.read_texture(&ctx, "reference_rgba").unwrap();
    let (texels, normals) = atlases(&ctx, &r);
    drop(ctx);
    let (view, objects) = twin_inputs(&r.blueprint, &texels, &normals);
    let cpu = trace_reference::trace_reference(&view, &objects);
    let cpu = Image::from_pixels(view.width, view.height, cpu.iter().map(|p| p.map(|c| c as f32)).collect())
        .unwrap();
    let mut max_intervals = 0;
    for y in 0..view.height {
        for x in 0..view.width {
            let d = view.ray(x, y);
            let n: usize = objects
                .iter()
                .flat_map(|o| &o.prisms)
                .map(|p| prism_map::ray_intervals(d, p, 0.0, f64::INFINITY).len())
                .sum();
            max_intervals = max_intervals.max(n);
        }
    }
    Traced { gpu, cpu, max_intervals, texels }
}

/// Largest per-channel difference, and the mean absolute difference over all channels.
fn differences(a: &Image, b: &Image) -> (f64, f64) {
    let max = voltex::metrics::max_abs_diff(a, b).unwrap();
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..4).map(|c| (p[c] as f64 - q[c] as f64).abs()).sum::<f64>())
        .sum();
    (max, sum / (4 * a.pixels.len()) as f64)
}

/// The f32 kernel and the f64 twin agree on every example scene: mean difference below 1e-4
/// and no channel off by more than 0.01 (a sample landing on the other side of a texel edge).
#[test]
fn kernel_matches_its_f64_twin_on_every_example_scene() {
    let mut many = 0;
    for name in ["torus_egg.ron", "terrain.ron", "sphere_balls.ron", "cloud_over_moss.ron", "flat_box.ron"] {
        let t = gpu_and_twin(&example(name), &reference(32));
        let (max, mean) = differences(&t.gpu, &t.cpu);
        eprintln!(
            "{name}: GPU vs f64 twin: max {max:.2e}, mean {mean:.2e}, up to {} intervals per ray",
            t.max_intervals
        );
        assert!(mean < 1e-4 && max < 1e-2, "{name}: max {max}, mean {mean}");
        let covered = t.cpu.pixels.iter().filter(|p| p[3] > 0.01).count();
        assert!(covered > 20, "{name}: the twin sees the object ({covered} pixels)");
        if t.max_intervals > 16 {
            many += 1;
        }
    }
    assert!(many > 0, "some ray meets more intervals than one window holds");
}

/// A box of uniform fog (a flat shell over a plane): the opacity of every pixel is exactly
/// `1 - (1 - a)^(path / opacity_length)` with the path through the box, sides included.
#[test]
fn box_of_fog_is_exact() {
    let size = 48;
    let t = gpu_and_twin(&example("flat_box.ron"), &reference(size));
    let scene = scene::load(&example("flat_box.ron")).unwrap();
    let eye = scene.camera.eye;
    let bp = Blueprint::new(&scene, &reference(size)).unwrap();
    let (view, _) = twin_inputs(&bp, &[0; 4 * 8 * 8 * 64], &[0; 4]);
    // The bake stores 0.5 as rgba8: 127 or 128, as the adapter rounds (llvmpipe 128, NVIDIA 127).
    let a = t.texels[3] as f64 / 255.0;
    assert!((a - 0.5).abs() < 1.0 / 255.0, "stored opacity {a}");
    let mut worst = [(0.0f64, 0, 0); 2];
    let mut inside = 0;
    for y in 0..size {
        for x in 0..size {
            let d = view.ray(x, y);
            // Slab test against the box [-1, 1] x [-1, 1] x [0, 0.5].
            let lo = (DVec3::new(-1.0, -1.0, 0.0) - eye) / d;
            let hi = (DVec3::new(1.0, 1.0, 0.5) - eye) / d;
            let (t0, t1) = (lo.min(hi).max_element(), lo.max(hi).min_element());
            let path = (t1 - t0).max(0.0);
            let expected = 1.0 - (1.0 - a).powf(path / 0.5);
            for (img, worst) in [&t.gpu, &t.cpu].into_iter().zip(&mut worst) {
                let err = (img.get(x, y)[3] as f64 - expected).abs();
                if err > worst.0 {
                    *worst = (err, x, y);
                }
            }
            inside += (path > 0.0) as u32;
        }
    }
    for ((err, x, y), what) in worst.into_iter().zip(["kernel", "twin"]) {
        eprintln!(
            "box of fog: {what}: worst coverage error {err:.2e} at pixel ({x}, {y}), {inside} pixels inside"
        );
        assert!(err < 2e-3, "{what}: coverage off by {err} at pixel ({x}, {y})");
    }
    assert!(inside > 500);
}

/// Halving the step changes the error, not the brightness.
#[test]
fn step_changes_error_not_brightness() {
    let scene = scene::load(&example("sphere_balls.ron")).unwrap();
    let mean = |step: f64| {
        let opts = RenderOptions { step: Some(step), ..reference(32) };
        let bp = Blueprint::new(&scene, &opts).unwrap();
        let ctx = gpu!(ADAPTER);
        let img = Renderer::new(&ctx, bp).unwrap().render(&ctx).unwrap().image;
        img.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / img.pixels.len() as f64
    };
    let (coarse, fine) = (mean(0.02), mean(0.005));
    eprintln!("mean brightness: {coarse:.5} with step 0.02, {fine:.5} with 0.005");
    assert!((coarse - fine).abs() / fine < 0.01, "{coarse} against {fine}");
}

/// Supersampling averages each pixel's area: a 2x2 render of the box of fog equals the mean of the
/// four sub-pixel renders, and stays within the range of the point-sampled image.
#[test]
fn supersampled_reference_is_the_pixel_average() {
    let scene = scene::load(&example("flat_box.ron")).unwrap();
    let render = |opts: RenderOptions| {
        let bp = Blueprint::new(&scene, &opts).unwrap();
        let ctx = crate::common::adapter::device(&ADAPTER);
        Renderer::new(&ctx, bp).unwrap().render(&ctx).unwrap().image
    };
    let fine = render(reference(32));
    let averaged = render(RenderOptions { supersample: Some(2), ..reference(16) });
    assert_eq!((averaged.width, averaged.height), (16, 16));
    let expected = fine.box_downsample(2);
    let (max, _) = differences(&averaged, &expected);
    assert!(max < 1e-5, "supersampled against averaged: {max}");
}

/// The texel and normal atlases of the frame's Reference objects as the kernel read them.
fn atlases(ctx: &GpuContext, r: &Renderer) -> (Vec<u8>, Vec<u8>) {
    let i = r.blueprint.find_instance("Reference").expect("a Reference instance");
    let read = |name| r.read_instance_buffer(ctx, i, name).unwrap();
    (read("texel_atlas"), read("normal_atlas"))
}

/// Inputs of the f64 twin for the blueprint's frame.
fn twin_inputs(bp: &Blueprint, texels: &[u8], normals: &[u8]) -> (TraceView, Vec<TraceObject>) {
    let set = bp.group::<ReferenceSet>().expect("a frame with Reference objects");
    let frame = (&bp.frame, bp.size, bp.eye);
    voltex::methods::reference::frame_twin_inputs(&bp.objects, &bp.bakes, set, frame, texels, normals)
}
