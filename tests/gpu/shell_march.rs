//! ShellMarch (issue 31): the kernel against its f64 twin on the example scenes, skipping that
//! changes no pixel, every ray finished with nothing dropped, and the exact answer on a box of fog.
use crate::common::adapter::Expectations;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use std::path::{Path, PathBuf};

use glam::DVec3;
use voltex::io::Image;
use voltex::methods::shell_march::{march_shell, ShellSet};
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene;

fn shell_march(size: u32) -> RenderOptions {
    RenderOptions {
        size: Some((size, size)),
        method: Some(MethodKind::named("ShellMarch").unwrap()),
        ..Default::default()
    }
}

fn example(dir: &str, name: &str) -> PathBuf {
    voltex::project_root().join("scenes").join(dir).join(name)
}

/// What one frame of the kernel gave: its layer, the twin's, and its counters.
struct Marched {
    gpu: Image,
    cpu: Image,
    /// Samples taken, samples skipped, intervals or nodes dropped, pieces mapped exactly.
    counts: [u32; 4],
    /// Pixels whose ray was not finished after the frame's dispatches.
    unfinished: usize,
}

/// Renders `scene` (text, or the file) and runs the twin on the same frame and volumes.
fn march(scene: &scene::Scene, opts: &RenderOptions, twin: bool) -> Marched {
    let bp = Blueprint::new(scene, opts).unwrap();
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    assert_eq!(voltex::metrics::count_nonfinite(&frame.image), 0, "no NaN or infinity in any pixel");
    let gpu = r.read_texture(&ctx, "shell_march_rgba").unwrap();
    let i = r.blueprint.find_instance("ShellMarch").expect("a ShellMarch instance");
    let read = |name| r.read_instance_buffer(&ctx, i, name).unwrap();
    let counts: Vec<u32> = bytemuck::pod_collect_to_vec(&read("shell_march_counts"));
    let states: Vec<voltex::types::ReferenceState> = bytemuck::pod_collect_to_vec(&read("shell_march_state"));
    let (texels, normals) = (read("texel_atlas"), read("normal_atlas"));
    drop(ctx);
    let unfinished = states.iter().filter(|s| s.resume[2] == 0.0).count();
    let bp = &r.blueprint;
    let set = bp.group::<ShellSet>().expect("a frame with ShellMarch objects");
    let (view, objects) = voltex::methods::shell_march::frame_twin_inputs(
        &bp.objects,
        &bp.bakes,
        set,
        (&bp.frame, bp.size, bp.eye),
        &texels,
        &normals,
    );
    let cpu =
        if twin { march_shell::march_shell(&view, &objects, 1e-3) } else { vec![[0.0; 4]; gpu.pixels.len()] };
    let cpu = Image::from_pixels(view.width, view.height, cpu.iter().map(|p| p.map(|c| c as f32)).collect())
        .unwrap();
    Marched { gpu, cpu, counts: [counts[0], counts[1], counts[2], counts[3]], unfinished }
}

fn load(path: &Path) -> scene::Scene {
    scene::load(path).unwrap()
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

/// The f32 kernel and the f64 twin agree on the example scenes (several objects' layouts,
/// per-pixel lighting, opaque bases, a thick shell whose prisms fold): mean difference below
/// 2e-3, every ray finished, nothing dropped.
#[test]
fn kernel_matches_its_f64_twin() {
    let scenes = [
        example("shell_march", "torus_egg.ron"),
        example("shell_march", "sphere_balls.ron"),
        example("shell_march", "terrain.ron"),
        example("view_slices", "flat_box.ron"),
        example("hard_cases", "thick_shell.ron"),
    ];
    let mut exact = 0;
    for path in scenes {
        let m = march(&load(&path), &shell_march(32), true);
        let (max, mean) = differences(&m.gpu, &m.cpu);
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!(
            "{name}: GPU vs f64 twin: max {max:.2e}, mean {mean:.2e}; samples {} taken, {} skipped; {} exact pieces; unfinished {} dropped {}",
            m.counts[0], m.counts[1], m.counts[3], m.unfinished, m.counts[2]
        );
        assert!(mean < 2e-3 && max < 0.25, "{name}: max {max}, mean {mean}");
        assert_eq!((m.unfinished, m.counts[2]), (0, 0), "{name}: unfinished rays, dropped intervals");
        let covered = m.cpu.pixels.iter().filter(|p| p[3] > 0.01).count();
        assert!(covered > 20, "{name}: the twin sees the object ({covered} pixels)");
        exact += m.counts[3];
    }
    assert!(exact > 0, "some piece is mapped exactly (a folded prism, or beyond the tolerance)");
}

/// The kernel walks the BVH once per 8x8 tile of pixels: an image whose sides are no multiple of
/// 8 (tiles cut by its edge, with pixels that march nothing) still matches the twin, every ray
/// finished, nothing dropped.
#[test]
fn partial_tiles_match_the_twin() {
    let m = march(&load(&example("shell_march", "torus_egg.ron")), &shell_march(37), true);
    let (max, mean) = differences(&m.gpu, &m.cpu);
    eprintln!("37x37: GPU vs f64 twin: max {max:.2e}, mean {mean:.2e}");
    assert!(mean < 2e-3 && max < 0.25, "max {max}, mean {mean}");
    assert_eq!((m.unfinished, m.counts[2]), (0, 0), "unfinished rays, dropped intervals");
}

/// Empty-space skipping changes no pixel, bit for bit, and skips samples.
#[test]
fn skipping_changes_no_pixel() {
    let path = example("shell_march", "torus_egg.ron");
    let text = std::fs::read_to_string(&path).unwrap();
    let without = text.replace("method: ShellMarch()", "method: ShellMarch(skip_empty: false)");
    assert_ne!(text, without);
    let on = march(&load(&path), &shell_march(48), false);
    let off = march(&scene::parse(&without, &path).unwrap(), &shell_march(48), false);
    eprintln!("skipping: {:?}, without: {:?}", on.counts, off.counts);
    assert!(on.counts[1] > 0 && off.counts[1] == 0, "skipped {} and {}", on.counts[1], off.counts[1]);
    assert!(on.counts[0] < off.counts[0], "fewer samples taken");
    let differ =
        on.gpu.pixels.iter().zip(&off.gpu.pixels).filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits));
    assert_eq!(differ.count(), 0, "pixels changed by skipping");
}

/// `example` drawn with `knobs` added to its `ShellMarch(...)`.
fn with_knobs(dir: &str, name: &str, knobs: &str) -> scene::Scene {
    let path = example(dir, name);
    let text = std::fs::read_to_string(&path).unwrap();
    let changed = text
        .replace("method: ShellMarch()", &format!("method: ShellMarch({knobs})"))
        .replace("method: ShellMarch(lighting", &format!("method: ShellMarch({knobs}, lighting"));
    assert_ne!(text, changed, "{name} is drawn with ShellMarch()");
    scene::parse(&changed, &path).unwrap()
}

/// The footprint filter (levels of the bake's layers copied into `shell_mips`, read at the
/// level of each interval's footprint, steps in the level's voxels) agrees with the twin, which
/// makes its levels with the twin of the MIP kernel; it changes the image, and skipping (by
/// pyramids of the opacity dilated by each level's reach) still changes no pixel. sphere_balls
/// is lit per pixel: its normals are filtered the same way.
#[test]
fn the_footprint_filter_matches_its_twin_and_skips_exactly() {
    for (name, bias) in [("torus_egg.ron", -1.0), ("terrain.ron", 0.0), ("sphere_balls.ron", 0.0)] {
        let knobs = format!("filter: Footprint, mip_bias: {bias}");
        let filtered = with_knobs("shell_march", name, &knobs);
        let m = march(&filtered, &shell_march(48), true);
        let (max, mean) = differences(&m.gpu, &m.cpu);
        eprintln!("{name} filtered: GPU vs f64 twin: max {max:.2e}, mean {mean:.2e}; counts {:?}", m.counts);
        assert!(mean < 2e-3 && max < 0.25, "{name}: max {max}, mean {mean}");
        assert_eq!((m.unfinished, m.counts[2]), (0, 0), "{name}: unfinished rays, dropped intervals");
        let plain = march(&load(&example("shell_march", name)), &shell_march(48), false);
        let (changed, _) = differences(&m.gpu, &plain.gpu);
        assert!(changed > 0.02, "{name}: filtering changes the image (largest change {changed})");
        let unskipped = with_knobs("shell_march", name, &format!("{knobs}, skip_empty: false"));
        let off = march(&unskipped, &shell_march(48), false);
        assert!(
            m.counts[1] > 0 && off.counts[1] == 0,
            "{name}: skipped {} and {}",
            m.counts[1],
            off.counts[1]
        );
        let differ = m
            .gpu
            .pixels
            .iter()
            .zip(&off.gpu.pixels)
            .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits));
        assert_eq!(differ.count(), 0, "{name}: pixels changed by skipping");
    }
}

/// A box of uniform fog (a flat shell over a plane): the opacity of every pixel is exactly
/// `1 - (1 - a)^(path / opacity_length)`, sides and seams between prisms included.
#[test]
fn box_of_fog_is_exact() {
    let size = 48;
    let path = example("view_slices", "flat_box.ron");
    let scene = load(&path);
    let eye = scene.camera.eye;
    let m = march(&scene, &shell_march(size), false);
    let bp = Blueprint::new(&scene, &shell_march(size)).unwrap();
    let set = bp.group::<ShellSet>().unwrap();
    let frame = (&bp.frame, bp.size, bp.eye);
    let (view, _) = voltex::methods::shell_march::frame_twin_inputs(
        &bp.objects,
        &bp.bakes,
        set,
        frame,
        &[0; 4 * 8 * 8 * 64],
        &[0; 4],
    );
    let mut worst = (0.0f64, 0, 0);
    let mut inside = 0;
    for y in 0..size {
        for x in 0..size {
            let d = view.ray(x, y);
            let lo = (DVec3::new(-1.0, -1.0, 0.0) - eye) / d;
            let hi = (DVec3::new(1.0, 1.0, 0.5) - eye) / d;
            let (t0, t1) = (lo.min(hi).max_element(), lo.max(hi).min_element());
            let path = (t1 - t0).max(0.0);
            // The bake stores 0.5 as rgba8: 127 or 128, as the adapter rounds.
            let expected = [127.0, 128.0].map(|v: f64| 1.0 - (1.0 - v / 255.0).powf(path / 0.5));
            let got = m.gpu.get(x, y)[3] as f64;
            let err = expected.iter().map(|e| (got - e).abs()).fold(f64::INFINITY, f64::min);
            if err > worst.0 {
                worst = (err, x, y);
            }
            inside += (path > 0.0) as u32;
        }
    }
    eprintln!(
        "box of fog: worst coverage error {:.2e} at pixel ({}, {}), {inside} pixels inside",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 < 2e-3, "coverage off by {} at pixel ({}, {})", worst.0, worst.1, worst.2);
    assert!(inside > 500);
}
