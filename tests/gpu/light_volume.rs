//! Light volumes (`RayMarch(shading: PhongShadows, shadows: LightVolume(..))`): the bake kernel
//! against its f64 twin, whole images against the twin march, the analytic transmittance of a
//! constant-density slab lit from above, convergence to shadow rays as the grid grows, and bad
//! input reported at its position.
use crate::common::adapter::Expectations;
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use glam::DVec3;
use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::methods::ray_march::light_volume::{bake_light_volume, light_transmittance, unpack};
use voltex::methods::ray_march::march::{ray_march_lit, MarchView};
use voltex::methods::ray_march::RayMarchPlan;
use voltex::render::{Blueprint, Renderer};
use voltex::scene;

/// A scene with hypertexture `h` (RON) on one node drawn with `method`, lit along `light`.
fn one(hypertexture: &str, method: &str, light: &str) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 32, height: 32),\n    camera: (eye: (0.0, -4.5, 1.2), \
         target: (0.0, 0.0, 0.0), fov_y: 35.0),\n    lights: [Directional(direction: {light})],\n    \
         hypertextures: {{ \"h\": {hypertexture} }},\n    nodes: [(name: \"n\", transform: (rotate: (10.0, 0.0, 20.0)), \
         hypertexture: \"h\", method: {method})],\n)\n"
    );
    scene::parse(&text, Path::new("test.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const LIGHT: &str = "(-0.5, 0.6, -0.7)";

/// A semi-transparent, perturbed, two-noise cloud (as in tests/gpu/hypertexture.rs).
const CLOUD: &str = "(object: Sphere(radius: 1.0), field: Perturbed(field: Swirl(twist: 0.6), amount: 0.3, \
    frequency: 2.0, magnitude: 0.5), noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.4, 1.2), (1.0, 1.0, 0.0)]), \
    amplitude: 0.4, frequency: 1.5, shift: 0.3), (shape: Table([0.0, 1.0, 0.3]), amplitude: 0.15, frequency: 4.0, \
    operator: Blend, seed: 3)], color: Ramp([(0.0, (1.0, 0.9, 0.8, 0.0)), (0.3, (0.9, 0.8, 0.7, 0.2)), \
    (1.0, (0.5, 0.6, 0.9, 0.9))]), opacity_length: 0.3)";

/// An opaque iso-surface with deep holes (Figure 4's look): its bumps cast shadows on it.
const HOLES: &str =
    "(object: Sphere(radius: 1.0), field: ClosestSurface, noises: [(shape: Curve([(0.0, 0.0, 0.0), \
    (0.2, 1.0, 0.0), (0.8, 1.0, 0.0), (1.0, 0.0, 0.0)]), amplitude: 0.3, frequency: 2.5, shift: 0.5)], \
    color: Step(threshold: 0.3, color: (0.8, 0.72, 0.62)), opacity_length: 0.01)";

/// A rendered frame: the kernel's premultiplied layer, its plan, the light volume's words, size.
struct Run {
    layer: Vec<[f64; 4]>,
    plan: RayMarchPlan,
    words: Vec<u32>,
    frame: voltex::types::FrameParams,
    size: (u32, u32),
}

fn run(scene: &scene::Scene, size: u32) -> Run {
    let bp = Blueprint::new(scene, &sized(size, size)).unwrap();
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    assert_eq!(voltex::metrics::count_nonfinite(&frame.image), 0);
    let instance = r.blueprint.find_instance("RayMarch").unwrap();
    let state = r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap();
    let words =
        bytemuck::pod_collect_to_vec(&r.read_instance_buffer(&ctx, instance, "light_volume").unwrap());
    drop(ctx);
    let plan = r.blueprint.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).unwrap().clone();
    let layer = common::lit_march_state(&r.blueprint.frame, &state);
    Run { layer, plan, words, frame: r.blueprint.frame, size: r.blueprint.size }
}

fn model<'a>(plan: &'a RayMarchPlan, tables: &'a [f64]) -> Model<'a> {
    Model { params: &plan.params, noises: &plan.packed.noises, tables, grid: None }
}

/// Largest and mean difference over every channel.
fn difference(a: &[[f64; 4]], b: &[[f64; 4]]) -> (f64, f64) {
    let d: Vec<f64> = a.iter().zip(b).flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs())).collect();
    (d.iter().copied().fold(0.0, f64::max), d.iter().sum::<f64>() / d.len() as f64)
}

/// Relative RMSE of the colour of `a` against `b`.
fn rel_rmse(a: &[[f64; 4]], b: &[[f64; 4]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (p, q) in a.iter().zip(b) {
        for k in 0..3 {
            num += (p[k] - q[k]).powi(2);
            den += q[k].powi(2);
        }
    }
    (num / den.max(1e-30)).sqrt()
}

/// The bake kernel and its twin agree at every vertex, on a semi-transparent cloud (soft
/// shadows) and on an opaque iso-surface (columns that go dark); the marcher reading the volume
/// agrees with the twin march reading the twin's volume.
#[test]
fn light_volume_kernel_and_images_match_twin() {
    for (what, h, method) in [
        ("cloud", CLOUD, "RayMarch(step: 0.02, shading: PhongShadows, shadows: LightVolume(resolution: 20))"),
        ("holes", HOLES, "RayMarch(step: 0.02, shading: PhongShadows, shadows: LightVolume(resolution: 24))"),
    ] {
        let r = run(&one(h, method, LIGHT), 32);
        let grid = r.plan.light.expect("a light volume");
        let tables = bake_transfer(&r.plan.packed.functions, &r.plan.packed.points);
        let twin = bake_light_volume(&model(&r.plan, &tables), &grid);
        let gpu = unpack(&r.words);
        assert_eq!(gpu.len(), twin.len(), "{what}: one word per vertex");
        let (mut worst, mut dark, mut lit) = ([0.0f64; 2], 0, 0);
        for (g, c) in gpu.iter().zip(&twin) {
            for k in 0..2 {
                worst[k] = worst[k].max((g[k] - c[k]).abs());
            }
            dark += (c[0] < 0.5) as usize;
            lit += (c[0] > 0.99) as usize;
        }
        eprintln!(
            "{what}: {:?} vertices, {} sub-steps per layer: kernel vs twin max {:.1e} (transmittance), {:.1e} \
             (openness); {dark} dark, {lit} lit",
            &grid.counts[..3],
            grid.counts[3],
            worst[0],
            worst[1]
        );
        assert!(worst[0] < 2e-3 && worst[1] < 2e-3, "{what}: {worst:?}");
        assert!(dark > 50 && lit > 50, "{what}: the volume holds both shadow and light");

        let view = MarchView::of_frame(&r.frame, r.size);
        let cpu = ray_march_lit(&view, model(&r.plan, &tables), r.plan.shade, Some((&grid, &twin)));
        let (max, mean) = difference(&r.layer, &cpu);
        let off =
            r.layer.iter().zip(&cpu).filter(|(a, b)| (0..4).any(|k| (a[k] - b[k]).abs() > 0.02)).count();
        eprintln!("{what}: image kernel vs twin max {max:.2e}, mean {mean:.2e}, {off} pixels off by > 0.02");
        // An iso-surface: a sample on the other side of the threshold in f32 than in f64 changes
        // a pixel, so only the share of such pixels is bounded there.
        assert!(mean < 1e-4, "{what}: mean {mean}");
        assert!(off * 100 < cpu.len(), "{what}: {off} pixels off");
    }
}

/// A constant-density slab lit from straight above: the transmittance at depth `d` below its top
/// is `exp(-sigma d)` with `sigma = -ln(1 - a) / opacity_length`, at the volume's vertices (kernel
/// and twin, within one sub-step of depth) and through the lookup between them.
#[test]
fn light_volume_of_a_slab_is_analytic() {
    // Density > 0 inside the box, opacity 0.5 per opacity length from density 1/1000 on.
    let slab = "(object: Box(size: (1.0, 1.0, 0.5)), noises: [(shape: Table([0.0, 0.0]), amplitude: 0.0, \
        frequency: 1.0)], color: Step(threshold: 0.001, color: (1.0, 1.0, 1.0), opacity: 0.5), opacity_length: 0.1)";
    let method = "RayMarch(step: 0.01, shading: PhongShadows, shadow_step: 0.004, shadows: LightVolume(resolution: 32))";
    let text = format!(
        "Scene(output: (width: 16, height: 16), camera: (eye: (0.0, -4.0, 1.0), target: (0.0, 0.0, 0.0), fov_y: \
         30.0), lights: [Directional(direction: (0.0, 0.0, -1.0))], hypertextures: {{ \"slab\": {slab} }}, nodes: \
         [(name: \"slab\", hypertexture: \"slab\", method: {method})])"
    );
    let scene = scene::parse(&text, Path::new("slab.ron")).unwrap();
    let r = run(&scene, 16);
    let grid = r.plan.light.unwrap();
    let sigma = -(0.5f64).ln() / 0.1;
    let sub = grid.origin[3] as f64;
    let tables = bake_transfer(&r.plan.packed.functions, &r.plan.packed.points);
    let twin = bake_light_volume(&model(&r.plan, &tables), &grid);
    let gpu = unpack(&r.words);
    let [nx, ny, nz, _] = grid.counts;
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let (origin, u, v, w) = (v3(grid.origin), v3(grid.u), v3(grid.v), v3(grid.w));
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let p = origin + u * i as f64 + v * j as f64 + w * k as f64;
                // Columns through the slab's top, away from its sides.
                if p.x.abs() > 0.4 || p.y.abs() > 0.4 || p.z < -0.24 {
                    continue;
                }
                let depth = (0.25 - p.z).max(0.0);
                let index = ((k * ny + j) * nx + i) as usize;
                for (who, t) in [("kernel", gpu[index][0]), ("twin", twin[index][0])] {
                    // Within one sub-step of the analytic depth (midpoint sampling), and the
                    // unorm16 rounding.
                    let (lo, hi) = ((-sigma * (depth + sub)).exp(), (-sigma * (depth - sub).max(0.0)).exp());
                    assert!(
                        t >= lo - 2e-5 && t <= hi + 2e-5,
                        "{who} at depth {depth:.4}: {t} not in [{lo}, {hi}]"
                    );
                    worst = worst.max((t.ln() + sigma * depth).abs());
                }
                checked += 1;
            }
        }
    }
    eprintln!(
        "slab: {checked} vertices, |ln T + sigma d| at most {worst:.3} (one sub-step: {:.3})",
        sigma * sub
    );
    assert!(checked > 100);
    // The lookup at points between the vertices (linear in transmittance between layers).
    let mut worst: f64 = 0.0;
    for i in 0..40 {
        let depth = 0.05 + 0.4 * i as f64 / 40.0;
        let x = DVec3::new(0.1, -0.05, 0.25 - depth);
        let t = light_transmittance(&twin, &grid, x);
        worst = worst.max((t / (-sigma * depth).exp()).ln().abs());
    }
    eprintln!("slab lookup: |ln(T / exp(-sigma d))| at most {worst:.3}");
    assert!(worst < 0.05, "{worst}");
}

/// As the grid grows, light-volume shadows converge to shadow rays (the same march otherwise):
/// the error falls and ends below a bound, on an opaque iso-surface with holes and on a
/// semi-transparent cloud; without shadows the error is far larger.
#[test]
fn light_volume_converges_to_shadow_rays() {
    for (what, h, step, bound) in [("holes", HOLES, 0.01, 0.06), ("cloud", CLOUD, 0.02, 0.02)] {
        let resolutions = if what == "holes" { [16, 32, 64, 128] } else { [4, 8, 16, 32] };
        let method = |shadows: &str| format!("RayMarch(step: {step}, shading: {shadows})");
        let rays = run(&one(h, &method("PhongShadows"), LIGHT), 48).layer;
        let phong = rel_rmse(&run(&one(h, &method("Phong"), LIGHT), 48).layer, &rays);
        let errors: Vec<f64> = resolutions
            .iter()
            .map(|r| {
                let m = method(&format!("PhongShadows, shadows: LightVolume(resolution: {r})"));
                rel_rmse(&run(&one(h, &m, LIGHT), 48).layer, &rays)
            })
            .collect();
        eprintln!("{what}: relative RMSE against shadow rays at resolution {resolutions:?}: {errors:.4?}; Phong: {phong:.4}");
        assert!(errors.windows(2).all(|e| e[1] <= e[0] * 1.05), "{what}: {errors:?}");
        assert!(
            errors[3] < bound && errors[3] < 0.6 * errors[0] && errors[3] < 0.3 * phong,
            "{what}: {errors:?}"
        );
    }
}

/// `shadows: LightVolume` needs `shading: PhongShadows`; a resolution out of range is an error at
/// its position.
#[test]
fn bad_light_volumes_are_reported_at_their_position() {
    let text = |method: &str| {
        format!(
            "Scene(\n  output: (width: 8, height: 8),\n  camera: (eye: (0.0, -4.5, 1.2), target: (0.0, 0.0, 0.0)),\n  \
             hypertextures: {{ \"h\": {HOLES} }},\n  nodes: [(name: \"n\", hypertexture: \"h\",\n    method: \
             {method})],\n)\n"
        )
    };
    for (method, word) in [
        ("RayMarch(shading: Phong, shadows: LightVolume(resolution: 64))", "PhongShadows"),
        ("RayMarch(shading: PhongShadows, shadows: LightVolume(resolution: 2))", "light volume resolution"),
        (
            "RayMarch(shading: PhongShadows, shadows: LightVolume(resolution: 100000))",
            "light volume resolution",
        ),
        ("RayMarch(shading: PhongShadows, shadows: Volume)", "LightVolume"),
    ] {
        let e = scene::parse(&text(method), Path::new("bad.ron")).unwrap_err().to_string();
        assert!(e.contains("bad.ron:6:") && e.contains(word), "{method}: {e}");
    }
}
