//! Hypertextures (Gilet & Dischler 2009): the kernels against their f64 CPU twins (simplex noise,
//! transfer tables, soft objects, vector fields, density, colour, whole images), the analytic
//! checks of the paper's model, and bad input reported at its position.
use crate::common::adapter::{gpu, Expectations};
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::{Path, PathBuf};

use glam::DVec3;
use voltex::cpu::bake::pcg_hash;
use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::cpu::noise_simplex::{simplex3, simplex3_tiled, simplex4};
use voltex::methods::ray_march::march::{ray_march, MarchView};
use voltex::methods::ray_march::{probe, RayMarchPlan};
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene;
use voltex::types::MarchState;

fn example(name: &str) -> PathBuf {
    voltex::project_root().join("scenes/hypertextures").join(name)
}

const EXAMPLES: &[&str] = &[
    "fig4_identity.ron",
    "fig4_holes.ron",
    "fig4_craters.ron",
    "fig4_isolines.ron",
    "fig5_multiple_noises.ron",
    "fig6_clouds.ron",
    "fig8_vector_fields.ron",
    "fig10_amplitude_frequency.ron",
    "fig7_2d_transfer.ron",
    "periodic_noise.ron",
    "fig13_wool.ron",
    "fig13_lawn.ron",
    "fig13_hedge.ron",
    "fig13_sponge.ron",
    "fig13_clods.ron",
    "fig13_cave.ron",
];

/// Figure 13's scenes use the tools the paper names for each (section 6): "The wool, lawn and
/// hedge have been obtained with a 1D shape transfer function. The sponge and clods were obtained
/// with three noises. Finally, for the cave [...] a 2D transfer function", whose rows differ
/// (equal rows are a 1D function); each keeps a small regression size.
#[test]
fn figure13_scenes_use_the_tools_the_paper_names() {
    for (name, tool) in [
        ("wool", "1D"),
        ("lawn", "1D"),
        ("hedge", "1D"),
        ("sponge", "three noises"),
        ("clods", "three noises"),
        ("cave", "2D"),
    ] {
        let scene = scene::load(&example(&format!("fig13_{name}.ron"))).unwrap();
        assert_eq!(scene.regress.size, Some([64, 64]), "{name}: regression size");
        assert_eq!(scene.hypertextures.len(), 1, "{name}: one hypertexture");
        let noises = &scene.hypertextures.values().next().unwrap().noises.value;
        let rows: Vec<_> = noises.iter().map(|n| n.shape.rows()).collect();
        match tool {
            "1D" => assert!(rows.iter().all(|r| r.is_none()), "{name}: only 1D shape transfer functions"),
            "three noises" => assert_eq!(noises.len(), 3, "{name}: three noises"),
            _ => assert!(
                rows.iter().flatten().any(|r| r.iter().any(|row| row != &r[0])),
                "{name}: a 2D shape transfer function whose rows differ"
            ),
        }
    }
}

fn blueprint(scene: &scene::Scene, opts: &RenderOptions) -> Blueprint {
    Blueprint::new(scene, opts).unwrap()
}

fn plans(bp: &Blueprint) -> Vec<&RayMarchPlan> {
    bp.objects.iter().filter_map(|o| o.method::<RayMarchPlan>()).collect()
}

/// A scene with one hypertexture `h` (given as RON) on a node drawn with `method`.
fn one(hypertexture: &str, method: &str) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 32, height: 32),\n    camera: (eye: (0.0, -4.5, 1.2), \
         target: (0.0, 0.0, 0.0), fov_y: 35.0),\n    lights: [Directional(direction: (-0.5, 0.6, -0.7))],\n    \
         hypertextures: {{ \"h\": {hypertexture} }},\n    nodes: [(name: \"n\", transform: (rotate: (10.0, 0.0, 20.0)), \
         hypertexture: \"h\", method: {method})],\n)\n"
    );
    scene::parse(&text, Path::new("test.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// A small pseudo-random generator in [0, 1).
struct Rng(u32);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = pcg_hash(self.0);
        self.0 as f64 / 4294967296.0
    }
    fn in_box(&mut self, lo: DVec3, hi: DVec3) -> DVec3 {
        lo + (hi - lo) * DVec3::new(self.next(), self.next(), self.next())
    }
}

fn point(p: DVec3, seed: u32) -> [f32; 4] {
    [p.x as f32, p.y as f32, p.z as f32, f32::from_bits(seed)]
}

/// The twin's model of a plan, with the tables the CPU twin of `bake_transfer` fills.
fn twin_tables(plan: &RayMarchPlan) -> Vec<f64> {
    bake_transfer(&plan.packed.functions, &plan.packed.points)
}

fn model<'a>(plan: &'a RayMarchPlan, tables: &'a [f64]) -> Model<'a> {
    Model { params: &plan.params, noises: &plan.packed.noises, tables, grid: None }
}

/// 3D simplex noise: the kernel and the f64 twin agree on points up to 40 units from the origin
/// and on any seed.
#[test]
fn simplex_noise_kernel_matches_twin() {
    let scene = scene::load(&example("fig4_holes.ron")).unwrap();
    let bp = blueprint(&scene, &sized(8, 8));
    let plan = plans(&bp)[0];
    let mut rng = Rng(7);
    let points: Vec<[f32; 4]> = (0..4096)
        .map(|i| point(rng.in_box(DVec3::splat(-40.0), DVec3::splat(40.0)), pcg_hash(i) % 1000))
        .collect();
    let gpu = probe(&crate::common::adapter::device(&ADAPTER), plan, &points).unwrap();
    let (mut max, mut sum, mut lo, mut hi): (f64, f64, f64, f64) = (0.0, 0.0, 1.0, -1.0);
    let mut max4: f64 = 0.0;
    for (i, p) in points.iter().enumerate() {
        let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let cpu = simplex3(x, p[3].to_bits());
        let d = (gpu.values[4 * i][0] as f64 - cpu).abs();
        max = max.max(d);
        sum += d;
        lo = lo.min(cpu);
        hi = hi.max(cpu);
        let w = (0.37f32 * p[0] + 1.3) as f64;
        let cpu4 = simplex4(x.extend(w), p[3].to_bits());
        max4 = max4.max((gpu.values[4 * i][3] as f64 - cpu4).abs());
    }
    eprintln!(
        "simplex3 GPU vs f64 twin: max {max:.2e}, mean {:.2e}; range [{lo:.3}, {hi:.3}]; simplex4: max {max4:.2e}",
        sum / 4096.0
    );
    assert!(max < 1e-4 && max4 < 1e-4, "max difference {max}, 4D {max4}");
    assert!(lo < -0.7 && hi > 0.7);
}

/// Periodic noise: the kernel's `simplex3_tiled` against its twin, and both repeat after each
/// period (3a, 3b, 3c cells) while the plain noise does not.
#[test]
fn periodic_noise_repeats() {
    let scene = scene::load(&example("periodic_noise.ron")).unwrap();
    let bp = blueprint(&scene, &sized(8, 8));
    let plan = plans(&bp)[0];
    let noise = plan.packed.noises[0];
    // frequency 2.5 x period 1.2 = 3 cells: one tile of 3 cells per axis, the frequency unchanged
    // (scale.w is Blend's unit: the one noise's amplitude).
    assert_eq!((noise.tile, noise.scale), ([1, 1, 1, 0], [1.0, 1.0, 1.0, noise.amplitude]));
    let tile = [2, 3, 5];
    let mut rng = Rng(11);
    let base: Vec<DVec3> = (0..1024).map(|_| rng.in_box(DVec3::splat(-20.0), DVec3::splat(20.0))).collect();
    let shifts = [DVec3::new(6.0, 0.0, 0.0), DVec3::new(0.0, 9.0, 0.0), DVec3::new(0.0, 0.0, 15.0)];
    let mut points: Vec<[f32; 4]> = base.iter().map(|&p| point(p, 3)).collect();
    for s in shifts {
        points.extend(base.iter().map(|&p| point(p + s, 3)));
    }
    let mut packed = plan.clone();
    packed.packed.noises[0].tile = [tile[0] as u32, tile[1] as u32, tile[2] as u32, 0];
    let gpu = probe(&crate::common::adapter::device(&ADAPTER), &packed, &points).unwrap();
    let value = |i: usize| gpu.values[4 * i + 2][1] as f64;
    let n = base.len();
    let (mut twin, mut repeat, mut twin_repeat, mut plain): (f64, f64, f64, f64) = (0.0, 0.0, 0.0, 0.0);
    for (i, &p) in base.iter().enumerate() {
        let cpu = simplex3_tiled(
            DVec3::new(points[i][0] as f64, points[i][1] as f64, points[i][2] as f64),
            3,
            tile,
        );
        twin = twin.max((value(i) - cpu).abs());
        for (k, s) in shifts.iter().enumerate() {
            repeat = repeat.max((value(i) - value((k + 1) * n + i)).abs());
            twin_repeat =
                twin_repeat.max((simplex3_tiled(p, 3, tile) - simplex3_tiled(p + *s, 3, tile)).abs());
            plain = plain.max((simplex3(p, 3) - simplex3(p + *s, 3)).abs());
        }
    }
    eprintln!("periodic simplex: GPU vs twin {twin:.1e}; after a period: GPU {repeat:.1e}, twin {twin_repeat:.1e}; plain noise {plain:.2}");
    assert!(twin < 1e-4 && repeat < 1e-4 && twin_repeat < 1e-9, "{twin} {repeat} {twin_repeat}");
    assert!(plain > 0.5, "the plain noise does not repeat there");
}

/// Transfer tables (Hermite curves, sampled tables, ramps, steps) of every example hypertexture:
/// `bake_transfer.wgsl` against its twin.
#[test]
fn transfer_tables_match_twin() {
    let ctx = gpu!(ADAPTER);
    let mut worst: f64 = 0.0;
    let mut functions = 0;
    for name in EXAMPLES {
        let scene = scene::load(&example(name)).unwrap();
        let bp = blueprint(&scene, &sized(8, 8));
        for plan in plans(&bp) {
            let gpu = probe(&ctx, plan, &[[0.0; 4]]).unwrap();
            let cpu = twin_tables(plan);
            assert_eq!(gpu.tables.len(), cpu.len());
            for (g, c) in gpu.tables.iter().zip(&cpu) {
                worst = worst.max((*g as f64 - c).abs());
            }
            functions += plan.packed.functions.len();
        }
    }
    eprintln!("transfer tables: {functions} functions, GPU vs f64 twin max {worst:.2e}");
    assert!(worst < 1e-5, "{worst}");
}

/// Soft objects, vector fields (all six of Figure 8), the density of eq. 3 to 5 and the colour
/// transfer: the kernel against the twin at random points in the enlarged bounds of every example.
#[test]
fn fields_density_and_colour_match_twin() {
    let ctx = gpu!(ADAPTER);
    let mut rng = Rng(99);
    for name in EXAMPLES {
        let scene = scene::load(&example(name)).unwrap();
        let bp = blueprint(&scene, &sized(8, 8));
        let mut worst = [0.0f64; 4];
        let mut count = 0;
        for plan in plans(&bp) {
            let (lo, hi) = plan.packed.bounds;
            let points: Vec<[f32; 4]> = (0..1024).map(|_| point(rng.in_box(lo, hi), 0)).collect();
            let gpu = probe(&ctx, plan, &points).unwrap();
            let tables = twin_tables(plan);
            let m = model(plan, &tables);
            for (i, p) in points.iter().enumerate() {
                let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                let g = &gpu.values[4 * i..4 * i + 4];
                let v = m.vector_field(x);
                let field_err = (DVec3::new(g[1][0] as f64, g[1][1] as f64, g[1][2] as f64) - v).length()
                    / v.length().max(1.0);
                let density = m.hyper_density(x);
                let colour = m.hyper_color(density);
                let colour_err = (0..4).map(|c| (g[3][c] as f64 - colour[c]).abs()).fold(0.0, f64::max);
                let errs = [
                    (g[0][1] as f64 - m.object_density(x)).abs(),
                    field_err,
                    (g[2][0] as f64 - density).abs(),
                    colour_err,
                ];
                for k in 0..4 {
                    worst[k] = worst[k].max(errs[k]);
                }
                count += (density > 0.0) as usize;
            }
        }
        eprintln!(
            "{name}: GPU vs f64 twin max: object {:.1e}, field {:.1e} (relative), density {:.1e}, colour {:.1e}; \
             {count} points inside",
            worst[0], worst[1], worst[2], worst[3]
        );
        assert!(
            worst[0] < 1e-6 && worst[1] < 1e-5 && worst[2] < 1e-4 && worst[3] < 2e-3,
            "{name}: {worst:?}"
        );
        assert!(count > 100, "{name}: enough points where the density is positive");
    }
}

/// The kernel's premultiplied layer of the first RayMarch object, as `composite_ray_march`
/// blends it (colour times the light colour, coverage), and the twin's.
fn layer_and_twin(scene: &scene::Scene, opts: &RenderOptions) -> (Vec<[f64; 4]>, Vec<[f64; 4]>, u32) {
    let bp = blueprint(scene, opts);
    let ctx = gpu!(ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    assert_eq!(voltex::metrics::count_nonfinite(&frame.image), 0);
    let instance = r.blueprint.find_instance("RayMarch").unwrap();
    let bytes = r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap();
    drop(ctx);
    let f = &r.blueprint.frame;
    let gpu = common::lit_march_state(f, &bytes);
    let o = r.blueprint.objects.iter().find(|o| o.method::<RayMarchPlan>().is_some()).unwrap();
    let plan = o.method::<RayMarchPlan>().unwrap();
    let tables = twin_tables(plan);
    let view = MarchView::of_frame(f, r.blueprint.size);
    let cpu = ray_march(&view, model(plan, &tables), plan.shade);
    (gpu, cpu, plan.dispatches)
}

/// Largest difference of any channel, mean difference, and the share of pixels off by more
/// than 0.02 in some channel.
fn compare(gpu: &[[f64; 4]], cpu: &[[f64; 4]]) -> (f64, f64, f64) {
    let (mut max, mut sum, mut off) = (0.0f64, 0.0, 0);
    for (g, c) in gpu.iter().zip(cpu) {
        let d = (0..4).map(|k| (g[k] - c[k]).abs()).fold(0.0, f64::max);
        max = max.max(d);
        sum += (0..4).map(|k| (g[k] - c[k]).abs()).sum::<f64>() / 4.0;
        off += (d > 0.02) as usize;
    }
    (max, sum / gpu.len() as f64, off as f64 / gpu.len() as f64)
}

const CLOUD: &str = "(object: Sphere(radius: 1.0), field: Perturbed(field: Swirl(twist: 0.6), amount: 0.3, \
    frequency: 2.0, magnitude: 0.5), noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.4, 1.2), (1.0, 1.0, 0.0)]), \
    amplitude: 0.4, frequency: 1.5, shift: 0.3), (shape: Table([0.0, 1.0, 0.3]), amplitude: 0.15, frequency: 4.0, \
    operator: Blend, seed: 3)], color: Ramp([(0.0, (1.0, 0.9, 0.8, 0.0)), (0.3, (0.9, 0.8, 0.7, 0.2)), \
    (1.0, (0.5, 0.6, 0.9, 0.9))]), opacity_length: 0.3)";

/// Whole images: the kernel (resuming across dispatches) and the twin agree on a semi-transparent
/// hypertexture unshaded, with Phong, and with Phong and shadow rays; and on the Figure 6 clouds.
#[test]
fn images_match_twin() {
    let cases = [
        ("cloud, no shading", one(CLOUD, "RayMarch(step: 0.02)")),
        ("cloud, Phong", one(CLOUD, "RayMarch(step: 0.02, shading: Phong)")),
        (
            "cloud, Phong + shadows",
            one(CLOUD, "RayMarch(step: 0.01, shading: PhongShadows, shadow_step: 0.04)"),
        ),
        (
            "cloud, Henyey-Greenstein g 0.6",
            one(CLOUD, "RayMarch(step: 0.02, shading: HenyeyGreenstein(g: 0.6))"),
        ),
        (
            "cloud, Henyey-Greenstein g -0.4 + shadows",
            one(
                CLOUD,
                "RayMarch(step: 0.02, shading: HenyeyGreenstein(g: -0.4, shadows: true), shadow_step: 0.04)",
            ),
        ),
    ];
    let mut resumed = false;
    for (what, scene) in &cases {
        let (gpu, cpu, dispatches) = layer_and_twin(scene, &sized(32, 32));
        let (max, mean, off) = compare(&gpu, &cpu);
        eprintln!(
            "{what}: {dispatches} dispatch(es), max {max:.2e}, mean {mean:.2e}, {:.2}% pixels off by > 0.02",
            off * 100.0
        );
        assert!(mean < 1e-5 && max < 1e-3, "{what}: max {max}, mean {mean}, off {off}");
        let covered = cpu.iter().filter(|p| p[3] > 0.05).count();
        assert!(covered > 100, "{what}: the object covers {covered} pixels");
        resumed |= dispatches > 2;
    }
    assert!(resumed, "some case needs several dispatches per frame");
    let scene = scene::load(&example("fig6_clouds.ron")).unwrap();
    let (gpu, cpu, _) = layer_and_twin(&scene, &sized(48, 20));
    let (max, mean, off) = compare(&gpu, &cpu);
    eprintln!("fig6_clouds (first object): max {max:.2e}, mean {mean:.2e}, {:.2}% pixels off", off * 100.0);
    assert!(mean < 1e-5 && max < 1e-3);
    // An iso-surface (a step opacity): a sample on the other side of the threshold in f32 than in
    // f64 changes a pixel, so only the share of such pixels is bounded.
    let scene = scene::load(&example("fig4_holes.ron")).unwrap();
    let (gpu, cpu, _) = layer_and_twin(&scene, &sized(96, 32));
    let (max, mean, off) = compare(&gpu, &cpu);
    eprintln!(
        "fig4_holes (first object, Phong): max {max:.2e}, mean {mean:.2e}, {:.2}% pixels off",
        off * 100.0
    );
    assert!(mean < 1e-4 && off < 0.01);
}

/// The adaptive stride: kernel and twin take the same samples, the kernel resuming its stride
/// across dispatches (a budget of 97 evaluations per dispatch makes the longest rays resume
/// four times and more); with strides of up to 8 steps in empty space the image stays close to the fixed
/// step's at clearly fewer density evaluations; a stride of 1 is the fixed march, bit for bit.
#[test]
fn adaptive_stride_matches_twin() {
    // The kernel's layer, its per-pixel states, and the twin's layer, with a small budget.
    let run = |scene: &scene::Scene| {
        let mut bp = blueprint(scene, &sized(32, 32));
        let plan = bp.objects.iter_mut().find_map(|o| o.method_mut::<RayMarchPlan>()).unwrap();
        let budget = plan.params.budget[0];
        plan.params.budget[0] = 97;
        plan.dispatches *= budget / 97 + 1;
        let plan = plan.clone();
        let ctx = gpu!(ADAPTER);
        let mut r = Renderer::new(&ctx, bp).unwrap();
        r.render(&ctx).unwrap();
        let instance = r.blueprint.find_instance("RayMarch").unwrap();
        let bytes = r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap();
        drop(ctx);
        let states = bytemuck::pod_collect_to_vec::<u8, MarchState>(&bytes);
        let f = &r.blueprint.frame;
        let light = [0, 1, 2].map(|c| f.light_color[c] as f64);
        let gpu: Vec<[f64; 4]> = states
            .iter()
            .map(|s| std::array::from_fn(|c| s.color[c] as f64 * if c < 3 { light[c] } else { 1.0 }))
            .collect();
        let tables = twin_tables(&plan);
        let view = MarchView::of_frame(f, r.blueprint.size);
        let cpu = ray_march(&view, model(&plan, &tables), plan.shade);
        (gpu, states, cpu)
    };
    let (fixed_gpu, fixed_states, fixed_cpu) = run(&one(CLOUD, "RayMarch(step: 0.005, shading: Phong)"));
    let fixed_evals: f64 = fixed_states.iter().map(|s| s.resume[1] as f64).sum();
    for method in [
        "RayMarch(step: 0.005, shading: Phong, adaptive: (max_step: 0.04))",
        "RayMarch(step: 0.005, adaptive: (max_step: 0.04))",
    ] {
        let (gpu, states, cpu) = run(&one(CLOUD, method));
        let (max, mean, off) = compare(&gpu, &cpu);
        let evals: f64 = states.iter().map(|s| s.resume[1] as f64).sum();
        let most = states.iter().map(|s| s.resume[1]).fold(0.0, f32::max);
        eprintln!(
            "{method}: kernel vs twin max {max:.2e}, mean {mean:.2e}, {:.2}% off; {evals} density evaluations \
             (fixed step, Phong: {fixed_evals}), at most {most} per ray",
            off * 100.0
        );
        assert!(most > 4.0 * 97.0, "{method}: rays resume across dispatches");
        assert!(states.iter().all(|s| s.resume[2] == 1.0), "{method}: every ray finished");
        assert!(mean < 1e-5 && max < 1e-3, "{method}: max {max}, mean {mean}, off {off}");
        if method.contains("Phong") {
            let (_, mean_fixed, _) = compare(&gpu, &fixed_gpu);
            let (_, mean_twins, _) = compare(&cpu, &fixed_cpu);
            eprintln!(
                "  mean difference to the fixed step {mean_fixed:.2e} (kernel), {mean_twins:.2e} (twins)"
            );
            assert!(evals < 0.7 * fixed_evals, "{evals} vs {fixed_evals}");
            assert!(mean_fixed < 2e-3 && mean_twins < 2e-3, "{mean_fixed} {mean_twins}");
        }
    }
    // max_step below two steps: stride 1, the fixed march.
    let (gpu, _, _) = run(&one(CLOUD, "RayMarch(step: 0.005, shading: Phong, adaptive: (max_step: 0.009))"));
    assert!(gpu == fixed_gpu, "a stride of at most 1 step changes the image");
}

/// With every amplitude 0 the density is the soft object's, exactly, whatever the noises and the
/// field; drawn as an iso-surface it is a sphere whose silhouette is known per pixel.
#[test]
fn zero_amplitude_gives_the_undistorted_object() {
    let h = "(object: Sphere(radius: 1.0), field: Perturbed(field: ClosestSurface, frequency: 3.0), \
        noises: [(shape: Table([0.0, 1.0]), amplitude: 0.0, frequency: 3.0, shift: 0.5), \
        (shape: Table([1.0, 0.0, 1.0]), amplitude: 0.0, frequency: 7.0, operator: Blend)], \
        color: Step(threshold: 0.4, color: (1.0, 1.0, 1.0)), opacity_length: 0.001)";
    let scene = one(h, "RayMarch(step: 0.01)");
    let bp = blueprint(&scene, &sized(40, 40));
    let plan = plans(&bp)[0];
    let mut rng = Rng(5);
    let points: Vec<[f32; 4]> =
        (0..2048).map(|_| point(rng.in_box(DVec3::splat(-1.1), DVec3::splat(1.1)), 0)).collect();
    let gpu = probe(&crate::common::adapter::device(&ADAPTER), plan, &points).unwrap();
    let tables = twin_tables(plan);
    let m = model(plan, &tables);
    for (i, p) in points.iter().enumerate() {
        let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        assert_eq!(gpu.values[4 * i + 2][0], gpu.values[4 * i][1], "kernel at {x}");
        assert_eq!(m.hyper_density(x), m.object_density(x), "twin at {x}");
    }
    // The iso-surface at density 0.4 is the sphere of radius 0.6 around the node's origin.
    let (gpu, _, _) = layer_and_twin(&scene, &sized(40, 40));
    let f = &bp.frame;
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let (forward, right, up) = (v3(f.forward), v3(plan.params.right), v3(plan.params.up));
    let eye = scene.camera.eye;
    let (mut inside, mut outside) = (0, 0);
    for y in 0..40 {
        for x in 0..40 {
            let sx = 2.0 * (x as f64 + 0.5) / 40.0 - 1.0;
            let sy = 1.0 - 2.0 * (y as f64 + 0.5) / 40.0;
            let d = (forward + right * sx + up * sy).normalize();
            let closest = (eye - d * eye.dot(d)).length();
            let chord = 2.0 * (0.36 - closest * closest).max(0.0).sqrt();
            let coverage = gpu[y * 40 + x][3];
            if chord > 0.05 {
                assert!(coverage > 0.999, "pixel ({x}, {y}) crosses the sphere: coverage {coverage}");
                inside += 1;
            } else if closest > 0.6 + 0.006 {
                assert_eq!(coverage, 0.0, "pixel ({x}, {y}) misses the sphere");
                outside += 1;
            }
        }
    }
    eprintln!("a = 0: density equals the soft object's at 2048 points; {inside} pixels covered, {outside} empty as the sphere says");
    assert!(inside > 200 && outside > 200);
}

/// Eq. 5's operators against the paper's formulas, with constant shape transfer functions (so
/// `t_i` is known everywhere): Sum `k + a t`; Blend the paper's `v1 (1 - v2) + v2` with `v1` the
/// k so far and `v2 = a t`, both over the largest amplitude A; Mix `k (1 - t) + a t`. Inside a
/// soft unit sphere with the closest-surface field the density is `1 - (|x| - k)`, so kernel and
/// twin give k at every point.
#[test]
fn operators_follow_the_papers_formulas() {
    let (a, t) = ([0.2, 0.4, 0.1], [0.5, 0.75, 0.4]);
    let big = 0.4;
    let sum = a[0] * t[0];
    let paper = |v1: f64, v2: f64| v1 * (1.0 - v2) + v2;
    let blend = big * paper(sum / big, a[1] * t[1] / big);
    let mix = blend * (1.0 - t[2]) + a[2] * t[2];
    assert!((blend - 0.325).abs() < 1e-12 && (mix - 0.235).abs() < 1e-12, "{blend} {mix}");
    for (operators, k) in
        [(["Sum", "Sum", "Sum"], sum + a[1] * t[1] + a[2] * t[2]), (["Sum", "Blend", "Mix"], mix)]
    {
        let noise = |i: usize| {
            format!(
                "(shape: Table([{t}, {t}]), amplitude: {a}, frequency: 3.0, seed: {i}, operator: {op})",
                t = t[i],
                a = a[i],
                op = operators[i]
            )
        };
        let h = format!(
            "(object: Sphere(radius: 1.0), noises: [{}, {}, {}], color: Step(threshold: 0.4, color: (1.0, 1.0, 1.0)), \
             opacity_length: 0.01)",
            noise(0),
            noise(1),
            noise(2)
        );
        let scene = one(&h, "RayMarch(step: 0.01)");
        let bp = blueprint(&scene, &sized(16, 16));
        let plan = plans(&bp)[0];
        let mut rng = Rng(29);
        let points: Vec<[f32; 4]> = (0..512)
            .map(|_| {
                let dir = rng.in_box(DVec3::splat(-1.0), DVec3::splat(1.0)).normalize();
                point(dir * (0.5 + 0.45 * rng.next()), 0)
            })
            .collect();
        let gpu = probe(&crate::common::adapter::device(&ADAPTER), plan, &points).unwrap();
        let tables = twin_tables(plan);
        let m = model(plan, &tables);
        let mut worst: f64 = 0.0;
        for (i, p) in points.iter().enumerate() {
            let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            let expected = 1.0 - (x.length() - k);
            assert!((m.hyper_density(x) - expected).abs() < 1e-6, "{operators:?}: twin at {x}");
            worst = worst.max((gpu.values[4 * i + 2][0] as f64 - expected).abs());
        }
        eprintln!("{operators:?}: k = {k}, kernel within {worst:.1e}");
        assert!(worst < 1e-5, "{operators:?}: kernel off by {worst}");
    }
}

/// The Henyey-Greenstein phase function: isotropic at g = 0, a density over the sphere of
/// directions for every g (it integrates to 1), and its peak value; with g = 0 the phase shading
/// keeps the albedo: the image equals the unshaded one.
#[test]
fn henyey_greenstein_phase_function() {
    use std::f64::consts::PI;
    use voltex::methods::ray_march::march::henyey_greenstein as hg;
    for cos in [-1.0, -0.3, 0.0, 0.7, 1.0] {
        assert!((hg(0.0, cos) - 1.0 / (4.0 * PI)).abs() < 1e-15, "isotropic at cos {cos}");
    }
    for g in [-0.9, -0.5, 0.0, 0.3, 0.8, 0.9] {
        // 2 pi times the integral over cos in [-1, 1], by Simpson's rule on 20000 intervals.
        let n = 20000;
        let h = 2.0 / n as f64;
        let f = |i: usize| hg(g, -1.0 + i as f64 * h);
        let s: f64 = (0..=n)
            .map(|i| {
                f(i) * if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                }
            })
            .sum();
        let total = 2.0 * PI * s * h / 3.0;
        assert!((total - 1.0).abs() < 1e-6, "g {g}: integrates to {total}");
        // Mean cosine is g (the anisotropy's definition).
        let m: f64 = (0..=n)
            .map(|i| {
                f(i) * (-1.0 + i as f64 * h)
                    * if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    }
            })
            .sum();
        assert!((2.0 * PI * m * h / 3.0 - g).abs() < 1e-5, "g {g}: mean cosine");
    }
    // Forward peak: (1 - g^2) / (4 pi (1 - g)^3) = (1 + g) / (4 pi (1 - g)^2); g = 1/2: 1.5 / pi.
    assert!((hg(0.5, 1.0) - 1.5 / PI).abs() < 1e-15);
    assert!((hg(0.5, -1.0) - 0.75 / (4.0 * PI * 1.5f64.powi(3))).abs() < 1e-15);
    // Images: g = 0 equals the unshaded render.
    let (unshaded, _, _) = layer_and_twin(&one(CLOUD, "RayMarch(step: 0.02)"), &sized(32, 32));
    let (isotropic, _, _) = layer_and_twin(
        &one(CLOUD, "RayMarch(step: 0.02, shading: HenyeyGreenstein(g: 0.0))"),
        &sized(32, 32),
    );
    let (max, _, _) = compare(&unshaded, &isotropic);
    assert!(max < 1e-6, "g = 0 differs from unshaded by {max}");
}

/// Perlin's bias and gain (the density modulation functions of section 3): known values of the
/// twin, and the kernel against the twin on a soft sphere whose density they reshape.
#[test]
fn bias_and_gain_modulate_the_density() {
    use voltex::cpu::hypertexture::{perlin_bias, perlin_gain};
    for b in [0.1, 0.3, 0.5, 0.8, 0.95] {
        assert!((perlin_bias(b, 0.5) - b).abs() < 1e-15, "bias({b}, 0.5) = {b}");
        assert_eq!((perlin_bias(b, 0.0), perlin_bias(b, 1.0)), (0.0, 1.0));
        assert!((perlin_gain(b, 0.5) - 0.5).abs() < 1e-15, "gain({b}, 0.5) = 0.5");
        // gain(g, 1/4) = bias(1 - g, 1/2) / 2 = (1 - g) / 2, and it is odd about (1/2, 1/2).
        assert!((perlin_gain(b, 0.25) - (1.0 - b) / 2.0).abs() < 1e-15);
        assert!((perlin_gain(b, 0.75) - (1.0 - (1.0 - b) / 2.0)).abs() < 1e-15);
    }
    // bias(b, t) = t^(ln b / ln 1/2): bias(1/4, t) = t^2, bias(1/8, t) = t^3.
    assert!((perlin_bias(0.25, 0.3) - 0.09).abs() < 1e-15);
    assert!((perlin_bias(0.125, 0.6) - 0.216).abs() < 1e-14);
    assert!((perlin_gain(0.75, 0.1) - 0.5 * 0.2f64.powi(2)).abs() < 1e-15, "gain(3/4, t) = 2 t^2 below 1/2");
    let h = "(object: Sphere(radius: 1.0), noises: [(shape: Table([0.0, 1.0]), amplitude: 0.0, frequency: 3.0)], \
        color: Step(threshold: 0.4, color: (1.0, 1.0, 1.0)), opacity_length: 0.01, bias: 0.3, gain: 0.8)";
    let scene = one(h, "RayMarch(step: 0.01)");
    let bp = blueprint(&scene, &sized(16, 16));
    let plan = plans(&bp)[0];
    let mut rng = Rng(17);
    let points: Vec<[f32; 4]> =
        (0..1024).map(|_| point(rng.in_box(DVec3::splat(-1.1), DVec3::splat(1.1)), 0)).collect();
    let gpu = probe(&crate::common::adapter::device(&ADAPTER), plan, &points).unwrap();
    let tables = twin_tables(plan);
    let m = model(plan, &tables);
    let mut worst: f64 = 0.0;
    for (i, p) in points.iter().enumerate() {
        let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let expected = perlin_gain(0.8, perlin_bias(0.3, (1.0 - x.length()).max(0.0)));
        assert!((m.hyper_density(x) - expected).abs() < 1e-6, "twin at {x}");
        worst = worst.max((gpu.values[4 * i + 2][0] as f64 - expected).abs());
    }
    eprintln!("bias 0.3, gain 0.8 on a soft sphere: kernel within {worst:.1e} of gain(bias(1 - |x|))");
    assert!(worst < 1e-5, "kernel off by {worst}");
}

/// r = 1 with the closest-surface field on a sphere (section 4.1): every point of a radius is
/// given the same distortion k (the noise is evaluated where the radius meets the surface), so
/// the density along a radius is the soft sphere's shifted by k: a displacement along the radius.
/// With r = 0 the distortion varies along the radius.
#[test]
fn shift_one_on_a_sphere_is_a_radial_displacement() {
    let noises = |r: &str| {
        format!(
            "(object: Sphere(radius: 1.0), field: ClosestSurface, noises: [(shape: Curve([(0.0, 0.0, 0.0), \
             (0.5, 0.3, 1.0), (1.0, 1.0, 0.0)]), amplitude: 0.2, frequency: 2.0, shift: {r}), (shape: Table([1.0, 0.0, \
             1.0]), amplitude: 0.1, frequency: 5.0, shift: {r}, seed: 4)], color: Step(threshold: 0.5, color: (1.0, \
             1.0, 1.0)))"
        )
    };
    let ctx = gpu!(ADAPTER);
    let radii = [0.35, 0.5, 0.65, 0.8, 0.95];
    let mut spreads = Vec::new();
    for r in ["1.0", "0.0"] {
        let scene = one(&noises(r), "RayMarch()");
        let bp = blueprint(&scene, &sized(8, 8));
        let plan = plans(&bp)[0];
        let tables = twin_tables(plan);
        let m = model(plan, &tables);
        let mut rng = Rng(11);
        let dirs: Vec<DVec3> =
            (0..256).map(|_| (rng.in_box(DVec3::splat(-1.0), DVec3::ONE)).normalize_or(DVec3::X)).collect();
        let points: Vec<[f32; 4]> =
            dirs.iter().flat_map(|&u| radii.iter().map(move |&rho| point(u * rho, 0))).collect();
        let gpu = probe(&ctx, plan, &points).unwrap();
        let (mut gpu_spread, mut cpu_spread, mut surface): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for (j, &u) in dirs.iter().enumerate() {
            // k implied by the density at radius rho: d = 1 - (rho - k), so k = rho - 1 + d.
            let k_gpu: Vec<f64> = (0..radii.len())
                .map(|i| radii[i] - 1.0 + gpu.values[4 * (j * radii.len() + i) + 2][0] as f64)
                .collect();
            let k_cpu: Vec<f64> = radii.iter().map(|&rho| rho - 1.0 + m.hyper_density(u * rho)).collect();
            let spread = |k: &[f64]| {
                k.iter().fold(f64::MIN, |a, &b| a.max(b)) - k.iter().fold(f64::MAX, |a, &b| a.min(b))
            };
            gpu_spread = gpu_spread.max(spread(&k_gpu));
            cpu_spread = cpu_spread.max(spread(&k_cpu));
            // ... and k is the distortion evaluated on the surface (where V = 0).
            surface = surface.max((k_cpu[0] - m.distortion(u, DVec3::ZERO)).abs());
        }
        eprintln!(
            "shift {r}: largest spread of k along a radius: kernel {gpu_spread:.2e}, twin {cpu_spread:.2e}"
        );
        spreads.push((gpu_spread, cpu_spread, surface));
    }
    let (gpu, cpu, surface) = spreads[0];
    assert!(gpu < 1e-5 && cpu < 1e-12 && surface < 1e-12, "r = 1: {:?}", spreads[0]);
    assert!(spreads[1].0 > 0.02 && spreads[1].1 > 0.02, "r = 0 varies along the radius: {:?}", spreads[1]);
}

/// Figure 10's sweep (`fig10_amplitude_frequency.ron`, shift r = 1, so each object is its sphere
/// displaced along the radius by k(u) = a T(noise(f u)) at the surface point u): read back from the
/// kernel's density, the displacement is proportional to the amplitude (0 at a = 0), and the
/// frequency is a pure zoom of the noise: k at frequency f and point u is the twin's k at
/// frequency 1 and point f u (the f = 1 object).
#[test]
fn figure10_amplitude_scales_and_frequency_zooms_the_displacement() {
    let scene = scene::load(&example("fig10_amplitude_frequency.ron")).unwrap();
    let bp = blueprint(&scene, &sized(8, 8));
    let plans = plans(&bp);
    let knobs: Vec<(f64, f64)> = plans
        .iter()
        .map(|p| (p.packed.noises[0].amplitude as f64, p.packed.noises[0].frequency as f64))
        .collect();
    assert_eq!(knobs.len(), 8, "two rows of four objects");
    let ctx = gpu!(ADAPTER);
    let mut rng = Rng(10);
    let dirs: Vec<DVec3> =
        (0..256).map(|_| rng.in_box(DVec3::splat(-1.0), DVec3::ONE).normalize_or(DVec3::X)).collect();
    // k from the kernel's density at radius 0.5 (inside the band where d = 1 - (rho - k)).
    let k: Vec<Vec<f64>> = plans
        .iter()
        .map(|plan| {
            let points: Vec<[f32; 4]> = dirs.iter().map(|&u| point(u * 0.5, 0)).collect();
            let gpu = probe(&ctx, plan, &points).unwrap();
            (0..dirs.len()).map(|j| 0.5 - 1.0 + gpu.values[4 * j + 2][0] as f64).collect()
        })
        .collect();
    drop(ctx);
    let reference = knobs.iter().position(|&(a, f)| a == 0.25 && f == 2.5).unwrap();
    let (mut worst_a, mut worst_f, mut spread) = (0.0f64, 0.0f64, 0.0f64);
    for (i, &(a, f)) in knobs.iter().enumerate() {
        if f == 2.5 {
            for (v, r) in k[i].iter().zip(&k[reference]) {
                worst_a = worst_a.max((v - a / 0.25 * r).abs());
            }
            if a == 0.0 {
                assert!(k[i].iter().all(|&v| v.abs() < 1e-6), "a = 0 leaves the sphere undistorted");
            }
        }
        if a == 0.25 {
            let one = knobs.iter().position(|&(a1, f1)| a1 == 0.25 && f1 == 1.0).unwrap();
            let tables = twin_tables(plans[one]);
            let m = model(plans[one], &tables);
            for (j, &u) in dirs.iter().enumerate() {
                worst_f = worst_f.max((k[i][j] - m.distortion(u * f, DVec3::ZERO)).abs());
            }
        }
        spread = spread
            .max(k[i].iter().fold(0.0, |m: f64, &v| m.max(v)) - k[i].iter().fold(1.0, |m: f64, &v| m.min(v)));
    }
    eprintln!("Figure 10: k against a/0.25 k(0.25): max {worst_a:.1e}; against the zoomed f = 1 twin: max {worst_f:.1e}");
    assert!(spread > 0.1, "the noise displaces the surface: {spread}");
    assert!(worst_a < 1e-6 && worst_f < 5e-6, "{worst_a} {worst_f}");
}

/// Animated hypertextures (4D noise, the paper's future work): the frame changes with time, and
/// kernel and twin agree at each time.
#[test]
fn animated_hypertextures_change_with_time() {
    let animated = CLOUD.replace("shift: 0.3)", "shift: 0.3, speed: 0.8)");
    assert_ne!(animated, CLOUD);
    let scene = one(&animated, "RayMarch(step: 0.02, shading: Phong)");
    let mut layers = Vec::new();
    for time in [0.0, 0.7] {
        let (gpu, cpu, _) = layer_and_twin(&scene, &RenderOptions { time: Some(time), ..sized(32, 32) });
        let (max, mean, _) = compare(&gpu, &cpu);
        eprintln!("animated, time {time}: kernel vs twin max {max:.2e}, mean {mean:.2e}");
        assert!(mean < 1e-5 && max < 1e-3);
        layers.push(gpu);
    }
    let (_, change, _) = compare(&layers[0], &layers[1]);
    eprintln!("animated: mean change of the layer from time 0 to 0.7: {change:.3}");
    assert!(change > 1e-3);
}

/// Halving the step changes the error, not the brightness (the shared step-corrected opacity).
#[test]
fn step_changes_error_not_brightness() {
    let mean = |step: f64| {
        let scene = one(CLOUD, &format!("RayMarch(step: {step})"));
        let (gpu, _, _) = layer_and_twin(&scene, &sized(32, 32));
        gpu.iter().map(|p| p[0] + p[1] + p[2] + p[3]).sum::<f64>() / gpu.len() as f64
    };
    let (coarse, fine) = (mean(0.04), mean(0.01));
    eprintln!("mean layer: {coarse:.5} with step 0.04, {fine:.5} with 0.01");
    assert!((coarse - fine).abs() / fine < 0.01, "{coarse} against {fine}");
}

// ---- bad input ----

const BASE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 16, height: 16),
    camera: (eye: (0.0, -4.0, 0.0), target: (0.0, 0.0, 0.0)),
    hypertextures: {
        "h": (
            object: Sphere(radius: 1.0),
            field: ClosestSurface,
            noises: [
                (shape: Curve([(0.0, 0.0, 0.0), (0.5, 1.0, 0.0), (1.0, 0.0, 0.0)]), amplitude: 0.2, frequency: 2.0),
            ],
            color: Ramp([(0.0, (1.0, 1.0, 1.0, 0.0)), (1.0, (1.0, 1.0, 1.0, 1.0))]),
        ),
    },
    nodes: [(name: "n", hypertexture: "h", method: RayMarch(quality: HQ, shading: None))],
)
"#;

/// The base scene with `line` (1-based) replaced; the error must be at `line` and the column
/// where `at` starts in the new line, and mention `word`.
#[track_caller]
fn bad(line: usize, text: &str, at: &str, word: &str) {
    let mut lines: Vec<&str> = BASE.lines().collect();
    lines[line - 1] = text;
    let source = lines.join("\n");
    let col = text.find(at).unwrap_or_else(|| panic!("{at} in {text}")) + 1;
    let e = match scene::parse(&source, Path::new("test.ron")) {
        Ok(scene) => Blueprint::new(&scene, &RenderOptions::default()).err().map(|e| e.to_string()),
        Err(e) => Some(e.to_string()),
    }
    .unwrap_or_else(|| panic!("expected an error for: {text}"));
    let want = format!("test.ron:{line}:{col}: ");
    assert!(e.starts_with(&want), "want {want}... got {e}");
    assert!(e.contains(word), "want `{word}` in {e}");
}

#[test]
fn base_hypertexture_scene_is_valid() {
    let scene = scene::parse(BASE, Path::new("test.ron")).unwrap();
    let bp = blueprint(&scene, &RenderOptions::default());
    let plan = plans(&bp)[0];
    assert_eq!((plan.step, plan.shade.phong), (0.002, false));
}

#[test]
fn bad_transfer_functions_are_reported_at_their_position() {
    let noise = |shape: &str| format!("                (shape: {shape}, amplitude: 0.2, frequency: 2.0),");
    bad(10, &noise("Curve([(0.0, 0.0, 0.0), (0.5, 1.5, 0.0), (1.0, 0.0, 0.0)])"), "1.5", "[0, 1]");
    bad(10, &noise("Curve([(0.0, 0.0, 0.0), (0.6, 1.0, 0.0), (0.4, 0.0, 0.0)])"), "(0.4", "comes before");
    bad(10, &noise("Curve([(0.0, 0.0, 0.0), (0.5, 1.0, 0.0), (0.5, 0.0, 0.0)])"), "(0.5, 0.0", "repeats");
    bad(10, &noise("Curve([(0.3, 0.0, 0.0)])"), "[(0.3", "2 to 64 control points");
    bad(10, &noise("Table([0.0, -0.1])"), "-0.1", "[0, 1]");
    bad(10, &noise("Table([1.0])"), "[1.0]", "table of 2 to 256");
    bad(10, &noise("Grid([[0.0, 1.0]])"), "[[0.0", "2 to 64 rows");
    bad(10, &noise("Grid([[0.0], [1.0]])"), "[[0.0", "rows of 2 to 256 values");
    bad(10, &noise("Grid([[0.0, 1.0], [1.0, 0.5, 0.0]])"), "[[0.0", "grid row 2 has 3 values");
    bad(10, &noise("Grid([[0.0, 1.0], [1.0, 1.5]])"), "1.5", "[0, 1]");
    let ramp = "            color: Ramp([(0.0, (1.0, 1.0, 1.0, 0.0)), (1.0, (1.0, 2.0, 1.0, 1.0))]),";
    bad(12, ramp, "2.0", "[0, 1]");
    let ramp = "            color: Ramp([(0.5, (1.0, 1.0, 1.0, 0.0)), (0.2, (1.0, 1.0, 1.0, 1.0))]),";
    bad(12, ramp, "(0.2", "sorted by x");
    bad(12, "            color: Step(threshold: 1.2, color: (1.0, 1.0, 1.0)),", "1.2", "[0, 1]");
}

/// 2D shape transfer functions (eq. 6): a grid whose rows are equal is its 1D table (kernel and
/// twin); an image gives the grid of its pixels; bad images fail at their position;
/// `Grid([[0, 0], [1, 1]])` is T = O(x) whatever the noise, so on a sphere with the
/// closest-surface field every point at |x| >= a / (1 + a) moves inwards by a (1 - |x|): the
/// density is (1 + a)(1 - |x|) exactly.
#[test]
fn grid_shape_transfer_functions() {
    let ctx = gpu!(ADAPTER);
    let h = |shape: &str| {
        format!(
            "(object: Sphere(radius: 1.0), noises: [(shape: {shape}, amplitude: 0.3, frequency: 2.5, shift: 1.0)], \
             color: Step(threshold: 0.5, color: (1.0, 1.0, 1.0)))"
        )
    };
    let mut rng = Rng(5);
    let points: Vec<[f32; 4]> =
        (0..2048).map(|_| point(rng.in_box(DVec3::splat(-1.3), DVec3::splat(1.3)), 0)).collect();
    let density = |shape: &str| {
        let scene = one(&h(shape), "RayMarch()");
        let bp = blueprint(&scene, &sized(8, 8));
        let plan = plans(&bp)[0];
        let gpu = probe(&ctx, plan, &points).unwrap();
        let tables = twin_tables(plan);
        let m = model(plan, &tables);
        let cpu: Vec<f64> = points
            .iter()
            .map(|p| m.hyper_density(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
            .collect();
        let g: Vec<f64> = (0..points.len()).map(|i| gpu.values[4 * i + 2][0] as f64).collect();
        (g, cpu)
    };
    let (table_gpu, table_cpu) = density("Table([0.0, 0.2, 1.0])");
    let (grid_gpu, grid_cpu) = density("Grid([[0.0, 0.2, 1.0], [0.0, 0.2, 1.0], [0.0, 0.2, 1.0]])");
    let max = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    let (d_gpu, d_cpu) = (max(&table_gpu, &grid_gpu), max(&table_cpu, &grid_cpu));
    let (depth_gpu, depth_cpu) = density("Grid([[0.0, 0.0], [1.0, 1.0]])");
    // The same function from a grayscale PNG image (top row: density 0).
    let dir = std::env::temp_dir().join(format!("voltex-grid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = |name: &str, w: u32, h: u32, grey: &dyn Fn(u32, u32) -> u8| {
        let pixels: Vec<[u8; 4]> = (0..w * h).map(|i| grey(i % w, i / w)).map(|g| [g, g, g, 255]).collect();
        voltex::io::png::write_rgba8(&dir.join(name), w, h, &pixels).unwrap();
        format!("Image(path: \"{}\")", dir.join(name).display())
    };
    let image = png("depth.png", 2, 2, &|_, y| if y == 0 { 0 } else { 255 });
    let (image_gpu, image_cpu) = density(&image);
    let d_image = max(&image_gpu, &depth_gpu).max(max(&image_cpu, &depth_cpu));
    assert!(d_image == 0.0, "image against grid: {d_image}");
    let source = |shape: &str| {
        let text = BASE.lines().map(|l| {
            if l.contains("(shape:") {
                format!("                (shape: {shape}, amplitude: 0.2, frequency: 2.0),")
            } else {
                l.to_string()
            }
        });
        text.collect::<Vec<_>>().join("\n")
    };
    let one_row = png("one_row.png", 4, 1, &|_, _| 0);
    let e = scene::parse(&source(&one_row), Path::new("test.ron")).unwrap_err().to_string();
    assert!(
        e.starts_with("test.ron:10:") && e.contains("2 to 64 rows (density)") && e.contains("is 4x1"),
        "{e}"
    );
    let missing = "Image(path: \"/nonexistent/t.png\")";
    let e = scene::parse(&source(missing), Path::new("test.ron")).unwrap_err().to_string();
    assert!(e.starts_with("test.ron:10:") && e.contains("t.png does not exist"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
    let (mut analytic_gpu, mut analytic_cpu, mut checked) = (0.0f64, 0.0f64, 0);
    for (i, p) in points.iter().enumerate() {
        let r = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64).length();
        if r >= 0.3 / 1.3 + 0.01 {
            let want = (1.3 * (1.0 - r)).clamp(0.0, 1.0);
            analytic_gpu = analytic_gpu.max((depth_gpu[i] - want).abs());
            analytic_cpu = analytic_cpu.max((depth_cpu[i] - want).abs());
            checked += (r < 1.0) as usize;
        }
    }
    eprintln!(
        "2D shape transfer: equal rows vs 1D table max {d_gpu:.1e} (kernel), {d_cpu:.1e} (twin); T = O(x): density vs \
         (1 + a)(1 - |x|) max {analytic_gpu:.1e} (kernel), {analytic_cpu:.1e} (twin) over {checked} points inside"
    );
    assert!(d_gpu < 1e-5 && d_cpu < 1e-12, "{d_gpu} {d_cpu}");
    assert!(analytic_gpu < 1e-5 && analytic_cpu < 1e-6 && checked > 100, "{analytic_gpu} {analytic_cpu}");
}

#[test]
fn bad_noises_are_reported_at_their_position() {
    let mut lines: Vec<&str> = BASE.lines().collect();
    lines[9] = "";
    let e = scene::parse(&lines.join("\n"), Path::new("test.ron")).unwrap_err().to_string();
    assert!(e.starts_with("test.ron:9:21: ") && e.contains("1 to 8 noises, found 0"), "{e}");
    let noise = "                (shape: Table([0.0, 1.0]), amplitude: 0.2, frequency: 0.0),";
    bad(10, noise, "0.0)", "positive");
    let noise = "                (shape: Table([0.0, 1.0]), amplitude: -0.2, frequency: 1.0),";
    bad(10, noise, "-0.2", ">= 0");
    let noise = "                (shape: Table([0.0, 1.0]), amplitude: 0.2, frequency: 1.0, shift: 2.0),";
    bad(10, noise, "2.0)", "[0, 1]");
    let noise = "                (shape: Table([0.0, 1.0]), amplitude: 0.2, frequency: 1.0, period: (1.0, 0.0, 1.0)),";
    bad(10, noise, "(1.0, 0.0", "positive finite periods");
    let noise = "                (shape: Table([0.0, 1.0]), amplitude: 0.2, frequency: 1.0, speed: 1.0, period: (1.0, 1.0, 1.0)),";
    bad(10, noise, "(1.0, 1.0, 1.0)", "cannot be animated");
    let nine = "(shape: Table([0.0, 1.0]), amplitude: 0.1, frequency: 1.0), ".repeat(9);
    let mut lines: Vec<String> = BASE.lines().map(String::from).collect();
    lines[9] = format!("                {nine}");
    let e = scene::parse(&lines.join("\n"), Path::new("test.ron")).unwrap_err().to_string();
    assert!(e.starts_with("test.ron:9:21: ") && e.contains("1 to 8 noises, found 9"), "{e}");
}

#[test]
fn bad_objects_fields_and_methods_are_reported_at_their_position() {
    bad(7, "            object: Torus(major: 0.5, minor: 0.6),", "Torus", "below the major radius");
    bad(7, "            object: Sphere(radius: 0.0),", "0.0", "positive");
    // (Checks of a whole tuple are reported where it ends, like every direction in a scene.)
    bad(8, "            field: Constant(direction: (0.0, 0.0, 0.0)),", ")),", "non-zero direction");
    let field = "            field: Perturbed(field: Perturbed(field: ClosestSurface, frequency: 1.0), frequency: 2.0),";
    bad(8, field, "Perturbed(field: Closest", "perturbed once");
    let node = |m: &str| format!("    nodes: [(name: \"n\", hypertexture: \"h\", method: {m})],");
    bad(15, &node("RayMarch(step: 0.0)"), "0.0", "positive");
    bad(15, &node("RayMarch(step: 1e-9)"), "RayMarch", "expected a step of at least");
    bad(15, &node("RayMarch(step: 0.02, adaptive: (max_step: 0.01))"), "RayMarch", "below the step 0.02");
    bad(15, &node("RayMarch(adaptive: (max_step: inf))"), "inf)", "positive finite");
    bad(15, &node("RayMarch(adaptive: (max_step: NaN))"), "NaN)", "positive finite");
    bad(15, &node("RayMarch(adaptive: (max_step: 0.0))"), "0.0)", "positive finite");
    bad(15, &node("RayMarch(adaptive: (stride: 4))"), "stride", "max_step");
    bad(15, &node("RayMarch(shading: Gouraud)"), "Gouraud", "PhongShadows");
    bad(15, &node("ViewSlices(planes: 10)"), "ViewSlices", "expected RayMarch");
    bad(15, &node("RayMarch(segments: DepthPeeling(passes: 0))"), "0)", "depth-peeling pass count in 1..=8");
    bad(15, &node("RayMarch(segments: DepthPeeling(passes: 9))"), "9)", "depth-peeling pass count in 1..=8");
    bad(15, &node("RayMarch(segments: DepthPeeling(splat_grid: 2))"), "2)", "splat lattice size");
    bad(15, &node("RayMarch(segments: DepthPeeling(passes: -1))"), "1))", "out of bounds");
    bad(15, &node("RayMarch(segments: DepthPeeling(layers: 2))"), "layers", "passes");
    bad(15, &node("RayMarch(segments: Slabs)"), "Slabs", "DepthPeeling");
    bad(15, "    nodes: [(name: \"n\", hypertexture: \"g\")],", "\"g\"", "expected one of \"h\"");
    bad(15, "    nodes: [(name: \"n\", method: RayMarch())],", "RayMarch", "expected `hypertexture");
    let both =
        "    nodes: [(name: \"n\", surface: Sphere(radius: 1.0, segments: (8, 4)), hypertexture: \"h\")],";
    bad(15, both, "\"h\"", "not both");
}

/// The binary reports a bad hypertexture with its position and exit status 1, and writes nothing.
#[test]
fn binary_reports_bad_hypertextures() {
    let dir = std::env::temp_dir().join(format!("voltex-hyper-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.ron");
    std::fs::write(&path, BASE.replace("frequency: 2.0)", "frequency: 0.0)")).unwrap();
    let out = common::voltex(&["render", common::s(&path), "-o", common::s(&dir.join("out.exr"))]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("bad.ron:10:") && err.contains("positive"), "{err}");
    assert!(!dir.join("out.exr").exists());
    std::fs::remove_dir_all(&dir).ok();
}
