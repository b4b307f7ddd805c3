//! EWA-style splatting segments (Gilet & Dischler 2009, section 5.1): the kernels against their
//! f64 twin (also with chords cut into pieces and footprints into small blocks), images against
//! the whole-bounds march on a semi-transparent soft sphere (close, no holes between splats, and
//! a single slab, which does not order the splats, clearly worse; also transformed and seen from
//! inside), and bad knobs.
use crate::common::adapter::{gpu, Expectations};
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::hypertexture::splats;
use voltex::io::Image;
use voltex::methods::ray_march::splat_segments::splat_segments;
use voltex::methods::ray_march::RayMarchPlan;
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene;
use voltex::types::MarchState;

const BUMPS: &str = "[(shape: Curve([(0.0, 0.0, 0.0), (1.0, 1.0, 0.0)]), amplitude: 0.12, frequency: 3.0, \
    shift: 0.5), (shape: Table([1.0, 0.0, 1.0]), amplitude: 0.04, frequency: 8.0, seed: 2)]";
/// Semi-transparent, and bluer where denser: the far side shows through, and depth order shows.
const HAZE: &str =
    "Ramp([(0.0, (0.9, 0.8, 0.7, 0.0)), (0.2, (0.9, 0.8, 0.7, 0.3)), (1.0, (0.3, 0.5, 0.9, 0.6))])";

fn scene_text(method: &str) -> String {
    placed_text(("(0.0, -4.0, 1.0)", "(0.0, 0.0, 0.0)"), "()", method)
}

/// The test scene with the camera's (eye, target) and the node's transform.
fn placed_text((eye, target): (&str, &str), transform: &str, method: &str) -> String {
    format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 48, height: 48),\n    camera: (eye: {eye}, target: \
         {target}, up: (0.0, 0.0, 1.0), fov_y: 40.0),\n    lights: [Directional(direction: (-0.5, 0.6, \
         -0.7))],\n    hypertextures: {{ \"h\": (object: Sphere(radius: 1.0), noises: {BUMPS}, color: {HAZE}, \
         opacity_length: 0.3) }},\n    nodes: [(name: \"n\", transform: {transform}, hypertexture: \"h\", method: {method})],\n)\n"
    )
}

fn scene_of(method: &str) -> scene::Scene {
    let text = scene_text(method);
    scene::parse(&text, Path::new("test.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Renders `scene` (with `splatting`, when given, as the object's `SegmentParams::splatting`:
/// slabs, pixels per block, pieces, samples per piece) and returns the image, the march states
/// and the blueprint.
fn render(
    scene: &scene::Scene,
    opts: &RenderOptions,
    splatting: Option<[u32; 4]>,
) -> (Image, Vec<MarchState>, Blueprint) {
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut bp = Blueprint::new(scene, opts).unwrap();
    for m in bp.objects.iter_mut().filter_map(|o| o.method_mut::<RayMarchPlan>()) {
        m.segments.splatting = splatting.unwrap_or(m.segments.splatting);
    }
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let image = r.render(&ctx).unwrap().image;
    let instance = r.blueprint.find_instance("RayMarch").unwrap();
    let states =
        bytemuck::pod_collect_to_vec(&r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap());
    drop(ctx);
    (image, states, Blueprint::new(scene, opts).unwrap())
}

/// Unshaded, 8 slabs: every pixel of the kernels' march state against the twin, which tests every
/// splat against every ray; then with footprints cut into blocks of 2 pixels and every chord
/// into pieces of 6 samples (24 pieces: longer than the longest chord, 2 r / step + 2 = 141).
#[test]
fn splatting_kernels_match_twin() {
    let scene = scene_of("RayMarch(step: 0.02, segments: Splatting(slabs: 8, splat_grid: 16))");
    let opts = sized(32, 32);
    let (_, states, bp) = render(&scene, &opts, None);
    let (_, pieces, _) = render(&scene, &opts, Some([8, 2, 24, 6]));
    let plan = bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).unwrap();
    assert_eq!(plan.dispatches, 0, "the marcher dispatches nothing for a splatted object");
    let [_, pixels, parts, samples] = plan.segments.splatting;
    let ctx = gpu!(ADAPTER);
    let set = plan.bake_splats(&ctx, None).unwrap();
    let (_, interior) = splats::read(&ctx, &set).unwrap();
    drop(ctx);
    let tables = bake_transfer(&plan.packed.functions, &plan.packed.points);
    let model = Model { params: &plan.params, noises: &plan.packed.noises, tables: &tables, grid: None };
    let (mut worst, mut worst_pieces, mut sum, mut covered) = (0.0f64, 0.0f64, 0.0, 0);
    for y in 0..32 {
        for x in 0..32 {
            let cpu = splat_segments(&bp.frame, &model, &plan.segments, &interior, x, y);
            let i = (y * 32 + x) as usize;
            for (c, twin) in cpu.iter().enumerate() {
                let d = (states[i].color[c] as f64 - twin).abs();
                worst = worst.max(d);
                sum += d / 4.0;
                worst_pieces = worst_pieces.max((pieces[i].color[c] as f64 - twin).abs());
            }
            covered += (cpu[3] > 0.05) as usize;
            assert_eq!(states[i].resume[2], 1.0, "pixel ({x}, {y}) finished");
        }
    }
    eprintln!(
        "{} interior splats, work {pixels} pixel(s) x {parts} piece(s) of {samples} samples; kernel vs twin: max \
         {worst:.2e}, mean {:.2e}; in blocks of 2 pixels and pieces of 6 samples: max {worst_pieces:.2e}; {covered} \
         pixels covered",
        interior.len(),
        sum / 1024.0
    );
    assert!(covered > 300, "{covered} pixels covered");
    // f32 against f64 and sums kept to 1/4096 per splat and slab.
    assert!(worst < 5e-3 && worst_pieces < 5e-3, "max {worst} / {worst_pieces}");
    assert!(sum / 1024.0 < 5e-4, "mean {}", sum / 1024.0);
}

/// Phong, a semi-transparent bumpy sphere: Splatting with 16 slabs is close to the bounds march
/// (same samples, but each slab's optical depth is the splats' weighted mean and its colour the
/// mean over the slab, unordered within it: a smoother reconstruction, so not equal), covers every
/// pixel the bounds march covers (no holes between splats), and one slab (no depth order at
/// all between the splats) is clearly worse.
#[test]
fn soft_sphere_is_close_to_the_bounds_march() {
    let opts = sized(48, 48);
    let render_method = |segments: &str| {
        render(&scene_of(&format!("RayMarch(step: 0.02, shading: Phong, segments: {segments})")), &opts, None)
    };
    let (bounds, bounds_states, _) = render_method("Bounds");
    let (splatted, states, _) = render_method("Splatting(slabs: 16, splat_grid: 16)");
    let (one, _, _) = render_method("Splatting(slabs: 1, splat_grid: 16)");
    let flip = |a: &Image, b: &Image| voltex::metrics::flip(a, b).unwrap().mean;
    let (f16, f1) = (flip(&splatted, &bounds), flip(&one, &bounds));
    let mut holes = 0;
    let mut worst = 0.0f32;
    for (s, b) in states.iter().zip(&bounds_states) {
        worst = worst.max((s.color[3] - b.color[3]).abs());
        holes += (b.color[3] > 0.05 && s.color[3] < 0.5 * b.color[3]) as usize;
    }
    let evals = |s: &[MarchState]| s.iter().map(|s| s.resume[1] as f64).sum::<f64>();
    eprintln!(
        "Splatting(16) vs Bounds: FLIP {f16:.4}; Splatting(1): FLIP {f1:.4}; coverage differs by at most {worst:.3}, \
         {holes} holes; density evaluations {:.0} vs {:.0}",
        evals(&states),
        evals(&bounds_states)
    );
    assert!(f16 < 0.02, "FLIP {f16}");
    assert!(f1 > 2.0 * f16 && f1 > 0.03, "one slab: FLIP {f1}");
    assert_eq!(holes, 0, "{holes} pixels lose their matter");
    assert!(worst < 0.1, "coverage differs by {worst}");
}

/// A sphere rotated and scaled unevenly (footprints and Gaussians follow the node's transform)
/// and the eye inside the object (every footprint reaching the eye's plane is the whole screen,
/// chords start at the near plane): close to the bounds march, and no holes.
#[test]
fn transformed_and_inside_views_are_close_to_the_bounds_march() {
    let opts = sized(48, 48);
    for (camera, transform) in common::TRANSFORMED_AND_INSIDE_VIEWS {
        let march = |segments: &str| {
            let text = placed_text(camera, transform, &format!("RayMarch(step: 0.02, segments: {segments})"));
            render(&scene::parse(&text, Path::new("test.ron")).unwrap(), &opts, None)
        };
        let (bounds, bounds_states, _) = march("Bounds");
        let (splatted, states, _) = march("Splatting(slabs: 16, splat_grid: 16)");
        let flip = voltex::metrics::flip(&splatted, &bounds).unwrap().mean;
        let holes = states
            .iter()
            .zip(&bounds_states)
            .filter(|(s, b)| b.color[3] > 0.05 && s.color[3] < 0.5 * b.color[3])
            .count();
        eprintln!("eye {}, transform {transform}: FLIP {flip:.4}, {holes} holes", camera.0);
        assert!(flip < 0.02, "FLIP {flip}");
        assert_eq!(holes, 0);
    }
}

/// Knobs out of range are errors at their line:col; slabs that do not fit a storage binding are
/// a clear error naming the object.
#[test]
fn bad_splatting_knobs_are_errors() {
    for (knob, expected) in [
        ("Splatting(slabs: 0)", "expected a depth slab count in 1..=64, found 0"),
        ("Splatting(slabs: 65)", "expected a depth slab count in 1..=64, found 65"),
        ("Splatting(splat_grid: 2)", "found 2"),
        ("Splatting(slab: 4)", "slab"),
    ] {
        let text = scene_text(&format!("RayMarch(segments: {knob})"));
        let err = scene::parse(&text, Path::new("test.ron")).err().unwrap().to_string();
        // The column lies within the knob (1-based).
        let start = text.lines().nth(6).unwrap().find(knob).unwrap() + 1;
        let col: usize = err.split(':').nth(2).unwrap().parse().unwrap();
        eprintln!("{knob}: {err}");
        assert!(err.starts_with("test.ron:7:"), "{err}");
        assert!((start..start + knob.len()).contains(&col), "{err}: knob at columns {start}..");
        assert!(err.contains(expected), "{err}");
    }
    let scene = scene_of("RayMarch(segments: Splatting(slabs: 64))");
    let err = Blueprint::new(&scene, &sized(1024, 1024)).err().unwrap().to_string();
    eprintln!("{err}");
    assert!(err.contains("object \"n\": Splatting with 64 slabs at 1024x1024 needs 1804 MiB"), "{err}");
}
