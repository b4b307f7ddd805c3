//! `voltex bench-hyper`: the set-up of the paper's Figure 11 on the current adapter: one
//! hypertexture (three noises) on six objects (three soft primitives, the cube, teapot and bunny
//! stand-in meshes of the Figure 11 scenes, whose grid bakes it also times, as the cumulus's
//! point grid) covering most of the window, HQ and IE steps, no shading, Phong, and Phong with
//! shadow rays, each with both segment strategies (the enlarged bounds and depth peeling). Per
//! setting: the median wall time of a frame after warm-up, the density evaluations the frame made
//! and those that ran the noises (counted by the kernel: points farther than the largest shift
//! from the object skip them), and the share of the frame that those noise evaluations alone
//! would take at the rate `bench_simplex.wgsl` measures
//! ("rate"), and the share measured directly ("A/B"): the same frame with the noises compiled out
//! (override `noise_off`), timed in alternation, compared per density evaluation.
//!
//! Frames are timed by wall clock after `device.poll`: lavapipe's compute timestamps come back
//! wrong once a render pass has run in the process, and every frame ends with raster passes.
//! A second table compares the segment strategies (section 5): the whole enlarged bounds against
//! depth peeling over the object's surface splats and EWA-style splatting of its interior
//! splats, per object at the IE step with Phong: frame
//! time, density evaluations (Phong's included), samples along the rays (the evaluations of the
//! same frame unshaded) and FLIP against a converged render (the bounds march with a step of
//! 0.001).

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::json::{Report, Row};
use crate::error::Result;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::methods::ray_march::RayMarchPlan;
use crate::render::{Blueprint, RenderOptions, Renderer};
use crate::types::MarchState;

/// The paper's objects: soft primitives, and the cube, teapot and bunny (a stand-in of our own)
/// meshes of the Figure 11 example scenes (`{meshes}`: their folder) : (name, object, node transform),
/// each covering about 3/4 of the window.
const OBJECTS: &[(&str, &str, &str)] = &[
    ("sphere", "Sphere(radius: 1.0)", "(rotate: (0.0, 0.0, 0.0))"),
    ("torus", "Torus(major: 0.72, minor: 0.4)", "(rotate: (60.0, 0.0, 0.0))"),
    ("box", "Box(size: (1.3, 1.3, 1.3))", "(rotate: (20.0, 0.0, 35.0))"),
    ("cube mesh", "Mesh(path: \"{meshes}/cube.obj\")", "(rotate: (20.0, 0.0, 35.0), scale: (0.8, 0.8, 0.8))"),
    (
        "teapot mesh",
        "Mesh(path: \"{meshes}/teapot.obj\")",
        "(translate: (-0.03, 0.0, -0.4), rotate: (0.0, 0.0, -20.0), scale: (0.42, 0.42, 0.42))",
    ),
    (
        "bunny mesh",
        "Mesh(path: \"{meshes}/bunny.obj\")",
        "(translate: (0.04, 0.0, -0.8), rotate: (0.0, 0.0, -30.0), scale: (0.84, 0.84, 0.84))",
    ),
];
const QUALITIES: &[&str] = &["HQ", "IE"];
const SHADINGS: &[&str] = &["None", "Phong", "PhongShadows"];
/// The hypertexture of every row: holes plus a two-octave turbulence.
const NOISES: &str = "[(shape: Curve([(0.0, 0.0, 0.0), (0.2, 1.0, 0.0), (0.8, 1.0, 0.0), (1.0, 0.0, 0.0)]), \
    amplitude: 0.15, frequency: 2.5, shift: 0.5), (shape: Table([1.0, 0.0, 1.0]), amplitude: 0.05, frequency: 6.0, \
    shift: 0.5, seed: 1), (shape: Table([1.0, 0.0, 1.0]), amplitude: 0.025, frequency: 12.0, shift: 0.5, seed: 2)]";
const NOISE_COUNT: f64 = 3.0;

fn scene_text(object: &str, transform: &str, quality: &str, shading: &str, segments: &str) -> String {
    let method = format!("RayMarch(quality: {quality}, shading: {shading}, segments: {segments})");
    method_scene(object, transform, &method)
}

/// The benchmark scene with `method` on its object.
fn method_scene(object: &str, transform: &str, method: &str) -> String {
    let meshes = crate::project_root().join("scenes/hypertextures/meshes");
    let object = object.replace("{meshes}", &meshes.display().to_string());
    format!(
        "Scene(output: (width: 512, height: 512), camera: (eye: (0.0, -2.5, 0.9), target: (0.0, 0.0, 0.0), \
         fov_y: 40.0), ambient: 0.2, lights: [Directional(direction: (-0.5, 0.6, -0.7))], hypertextures: {{ \"h\": \
         (object: {object}, noises: {NOISES}, color: Step(threshold: 0.35, color: (0.8, 0.72, 0.62)), \
         opacity_length: 0.01) }}, nodes: [(name: \"object\", transform: {transform}, hypertexture: \"h\", \
         method: {method})])"
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Simplex evaluations per second of `bench_simplex.wgsl` (wall clock, median of 5, after warm-up).
pub(crate) fn noise_rate(ctx: &GpuContext) -> Result<f64> {
    const PER_THREAD: u32 = 1024;
    let threads = [4096u32, 16, 1];
    let mut kernel = ComputeKernel::load(ctx, &Sources::project()?, "ray_march/bench_simplex.wgsl")?;
    let mut inputs = Inputs::default();
    let out = vec![0u8; (threads[0] * threads[1] * 4) as usize];
    inputs.buffers.insert("bench_out".into(), crate::gpu::buffers::storage(ctx, "bench_out", &out));
    inputs.constants.push(("evaluations".into(), PER_THREAD as f64));
    let mut times = Vec::new();
    for i in 0..6 {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        kernel.dispatch(ctx, &mut encoder, &inputs, threads)?;
        let t = Instant::now();
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        if i > 0 {
            times.push(t.elapsed().as_secs_f64());
        }
    }
    ctx.take_errors()?;
    Ok((threads[0] * threads[1] * PER_THREAD) as f64 / median(times))
}

/// Median frame time (ms, wall clock) and the density evaluations of the last frame (all, and
/// those that ran the noises), for renderers timed in alternation (so load changes hit both).
struct Timed {
    renderer: Renderer,
    times: Vec<f64>,
    /// GPU ms of each timed frame (the sum over its passes), where the adapter has timestamps.
    gpu: Vec<f64>,
}

impl Timed {
    fn new(renderer: Renderer) -> Self {
        Timed { renderer, times: Vec::new(), gpu: Vec::new() }
    }

    /// Renders a timed frame.
    fn frame(&mut self, ctx: &GpuContext) -> Result<()> {
        let t = Instant::now();
        let passes = self.renderer.render_timed(ctx)?;
        self.times.push(t.elapsed().as_secs_f64() * 1e3);
        if !passes.is_empty() {
            self.gpu.push(passes.iter().map(|p| p.1).sum());
        }
        Ok(())
    }

    fn gpu_ms(&self) -> Option<f64> {
        (!self.gpu.is_empty()).then(|| median(self.gpu.clone()))
    }

    fn counts(&self, ctx: &GpuContext) -> Result<(f64, f64, f64)> {
        let r = &self.renderer;
        let instance = r.blueprint.find_instance("RayMarch").unwrap_or(0);
        let states: Vec<MarchState> =
            bytemuck::pod_collect_to_vec(&r.read_instance_buffer(ctx, instance, "ray_march_state")?);
        let evals: f64 = states.iter().map(|s| s.resume[1] as f64).sum();
        let noised: f64 = states.iter().map(|s| s.resume[3] as f64).sum();
        let covered = states.iter().filter(|s| s.color[3] > 0.5).count() as f64 / states.len().max(1) as f64;
        Ok((evals, noised, covered))
    }
}

/// Segment strategies compared by `segments_table`.
const SEGMENTS: &[(&str, &str)] = &[
    ("Bounds", "Bounds"),
    ("DepthPeeling(4)", "DepthPeeling(passes: 4)"),
    ("Splatting(16)", "Splatting(slabs: 16)"),
];

/// The segment strategies on every object (IE, Phong): frame time, density evaluations and FLIP
/// against a converged render.
pub(crate) fn segments_table(ctx: &GpuContext, args: &Args, report: &mut Report) -> Result<()> {
    let (size, frames, quick) = (args.size, args.frames, args.quick);
    println!(
        "\n| object | segments | dispatches | frame ms (wall) | M density evals | M noise evals | M samples | FLIP vs \
         converged |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let opts = RenderOptions { size: Some(size), ..Default::default() };
    let objects = if quick { &OBJECTS[..1] } else { OBJECTS };
    for (name, object, transform) in objects {
        let parse = |method: &str| {
            crate::scene::parse(&method_scene(object, transform, method), Path::new("bench-hyper.ron"))
        };
        let truth_method = format!("RayMarch(step: {}, shading: Phong)", args.truth_step);
        let truth = Renderer::new(ctx, Blueprint::new(&parse(&truth_method)?, &opts)?)?.render(ctx)?.image;
        for (label, segments) in SEGMENTS {
            let scene = parse(&format!("RayMarch(quality: IE, shading: Phong, segments: {segments})"))?;
            let mut run = Timed::new(Renderer::new(ctx, Blueprint::new(&scene, &opts)?)?);
            run.renderer.render_timed(ctx)?;
            for _ in 0..frames {
                run.frame(ctx)?;
            }
            let (evals, noised, _) = run.counts(ctx)?;
            let image = run.renderer.render(ctx)?.image;
            let flip = crate::metrics::flip(&image, &truth)?.mean;
            let rel_rmse = crate::metrics::relative_rmse(&image, &truth)?;
            // Unshaded, every density evaluation is a sample along a ray.
            let unshaded = parse(&format!("RayMarch(quality: IE, shading: None, segments: {segments})"))?;
            let mut unshaded = Renderer::new(ctx, Blueprint::new(&unshaded, &opts)?)?;
            unshaded.render_timed(ctx)?;
            let (samples, _, _) = Timed::new(unshaded).counts(ctx)?;
            let plan =
                run.renderer.blueprint.objects.iter().find_map(|o| o.method::<RayMarchPlan>().cloned());
            // Splatting runs no marcher: its two passes are dispatched once each.
            let dispatches = plan.map_or("-".into(), |p| match p.splatting {
                Some(_) => "1 + 1".to_string(),
                None => p.dispatches.to_string(),
            });
            let ms = median(run.times.clone());
            println!(
                "| {name} | {label} | {dispatches} | {ms:.1} | {:.2} | {:.2} | {:.3} | {flip:.4} |",
                evals / 1e6,
                noised / 1e6,
                samples / 1e6
            );
            let extra = [("noise_evaluations", noised), ("samples", samples)];
            report.rows.push(Row {
                object: Some(name.to_string()),
                quality: Some("IE".into()),
                step: Some(0.015),
                shading: Some("Phong".into()),
                segments: Some(label.to_string()),
                flip: Some(flip),
                rel_rmse: Some(rel_rmse),
                truth: Some(format!("RayMarch, step {}, Phong, Bounds", args.truth_step)),
                work: Some(evals),
                work_unit: Some("density evaluations".into()),
                extra: extra.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
                ..Row::new("segments", "RayMarch", ms)
            });
            report.trace(format!("{name} IE Phong {label}"), &run.renderer);
        }
    }
    Ok(())
}

/// `voltex bench-hyper`'s arguments.
pub struct Args {
    /// Frame size in pixels (width, height).
    pub size: (u32, u32),
    /// Timed frames per row, after warm-up.
    pub frames: usize,
    /// Only the first object (the sphere; the teapot for the shadows table).
    pub quick: bool,
    /// Only the table of segment strategies.
    pub segments: bool,
    /// Only the table of shadows (Phong, shadow rays, light volumes on the Figure 11 scenes).
    pub shadows: bool,
    /// Step of the converged renders that errors are measured against.
    pub truth_step: f64,
    /// Write the rows as JSON here.
    pub json: Option<PathBuf>,
    /// Write the timed frames' passes as a Chrome/Perfetto trace here.
    pub trace: Option<PathBuf>,
}

/// Runs `voltex bench-hyper`: the tables of the RayMarch paper's figures, printed and written as
/// asked.
pub fn run(args: &Args) -> Result<()> {
    super::json::check_output(args.json.as_deref())?;
    super::json::check_output(args.trace.as_deref())?;
    let ctx = GpuContext::new()?;
    let mut report = Report::new("bench-hyper", ctx.adapter_line(), args.size, args.frames);
    let result = tables(&ctx, args, &mut report);
    report.cost_models = super::cost::fit(&report.rows);
    for f in &report.cost_models {
        println!("{}", f.describe());
    }
    report.finish(args.json.as_deref(), args.trace.as_deref())?;
    result
}

/// The grid bake of `plan`'s mesh or point-set object, wall time with a readback in ms: the
/// median of 3, after a first that compiles the kernels (also returned).
fn grid_bake_ms(ctx: &GpuContext, plan: &RayMarchPlan) -> Result<(f64, f64)> {
    let mut times = Vec::new();
    for _ in 0..4 {
        let t = Instant::now();
        let grid = plan.bake_mesh_grid(ctx)?.expect("a mesh or point-set object");
        crate::hypertexture::mesh::read(ctx, &grid)?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok((median(times[1..].to_vec()), times[0]))
}

/// Times the point-set bake of `points_cumulus.ron` (its kernels through a BVH, then the
/// jump flooding), as the mesh grid bakes are timed.
fn point_grid_bake(ctx: &GpuContext, size: (u32, u32)) -> Result<()> {
    let scene = crate::scene::load(&crate::project_root().join("scenes/hypertextures/points_cumulus.ron"))?;
    let bp = Blueprint::new(&scene, &RenderOptions { size: Some(size), ..Default::default() })?;
    let plan = bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).expect("a RayMarch object");
    let points = plan.packed.point_set.as_ref().expect("a point-set object");
    let (ms, first) = grid_bake_ms(ctx, plan)?;
    println!(
        "point grid bake, cumulus: {} kernels, {:?} samples: {ms:.1} ms (wall, with readback; median of 3 after one \
         that compiles the kernels: {first:.1} ms)",
        points.set.centres.len(),
        points.spec.n,
    );
    Ok(())
}

fn tables(ctx: &GpuContext, args: &Args, report: &mut Report) -> Result<()> {
    let (size, frames, quick) = (args.size, args.frames, args.quick);
    if args.segments || args.shadows {
        println!(
            "bench-hyper on {}: {size:?}, median of {frames} frame(s) after one warm-up",
            ctx.adapter_line()
        );
        if args.segments {
            segments_table(ctx, args, report)?;
        }
        if args.shadows {
            shadows_table(ctx, args, report)?;
        }
        return Ok(());
    }
    let rate = noise_rate(ctx)?;
    println!(
        "bench-hyper on {}: {size:?}, median of {frames} frame(s) after one warm-up; simplex noise alone: {:.0} M \
         evaluations/s",
        ctx.adapter_line(),
        rate / 1e6
    );
    for (name, object, transform) in OBJECTS.iter().filter(|o| o.1.starts_with("Mesh")) {
        let scene = crate::scene::parse(
            &scene_text(object, transform, "IE", "None", "Bounds"),
            Path::new("bench-hyper.ron"),
        )?;
        let bp = Blueprint::new(&scene, &RenderOptions { size: Some(size), ..Default::default() })?;
        let plan = bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).expect("a RayMarch object");
        let (shape, spec) = plan.packed.mesh.as_ref().expect("a mesh object");
        let (ms, first) = grid_bake_ms(ctx, plan)?;
        println!(
            "mesh grid bake, {name}: {} triangles in {} part(s), {:?} samples: {ms:.1} ms (wall, with readback; median \
             of 3 after one that compiles the kernel: {first:.1} ms)",
            shape.triangles.len(),
            shape.parts.len(),
            spec.n,
        );
    }
    point_grid_bake(ctx, size)?;
    println!(
        "\n| object | quality | step | shading | segments | dispatches | coverage | frame ms (wall) | fps | M density \
         evals | M noise evals | noise alone ms | noise share (rate) | noise share (A/B) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let objects = if quick { &OBJECTS[..1] } else { OBJECTS };
    let opts = RenderOptions { size: Some(size), ..Default::default() };
    for (name, object, transform) in objects {
        // Converged renders per shading (shadow rays for PhongShadows), the bounds marched.
        let mut truths = std::collections::HashMap::new();
        for shading in SHADINGS {
            let text = scene_text(object, transform, "HQ", shading, "Bounds")
                .replace("RayMarch(quality: HQ,", &format!("RayMarch(step: {},", args.truth_step));
            let scene = crate::scene::parse(&text, Path::new("bench-hyper.ron"))?;
            truths.insert(*shading, Renderer::new(ctx, Blueprint::new(&scene, &opts)?)?.render(ctx)?.image);
        }
        for quality in QUALITIES {
            for (shading, (label, segments)) in
                SHADINGS.iter().flat_map(|s| SEGMENTS.iter().map(move |g| (s, g)))
            {
                let text = scene_text(object, transform, quality, shading, segments);
                let scene = crate::scene::parse(&text, Path::new("bench-hyper.ron"))?;
                let opts = RenderOptions { size: Some(size), ..Default::default() };
                let mut runs = Vec::new();
                for noise in [true, false] {
                    let mut bp = Blueprint::new(&scene, &opts)?;
                    bp.objects
                        .iter_mut()
                        .filter_map(|o| o.method_mut::<RayMarchPlan>())
                        .for_each(|m| m.noise = noise);
                    let mut renderer = Renderer::new(ctx, bp)?;
                    renderer.render_timed(ctx)?;
                    runs.push(Timed::new(renderer));
                }
                for _ in 0..frames {
                    for run in runs.iter_mut() {
                        run.frame(ctx)?;
                    }
                }
                let plan = runs[0]
                    .renderer
                    .blueprint
                    .objects
                    .iter()
                    .find_map(|o| o.method::<RayMarchPlan>().cloned());
                let plan = plan.expect("a RayMarch object");
                let ms = median(runs[0].times.clone());
                let ms_off = median(runs[1].times.clone());
                let (evals, noised, covered) = runs[0].counts(ctx)?;
                let (evals_off, _, _) = runs[1].counts(ctx)?;
                let noise_ms = noised * NOISE_COUNT / rate * 1e3;
                // Time per density evaluation with and without the noises.
                let ab = 1.0 - (ms_off / evals_off) / (ms / evals);
                let image = runs[0].renderer.render(ctx)?.image;
                let truth = &truths[shading];
                let extra = [
                    ("dispatches", plan.dispatches as f64),
                    ("coverage", covered),
                    ("noise_evaluations", noised * NOISE_COUNT),
                    ("noise_share_rate", noise_ms / ms),
                    ("noise_share_ab", ab),
                ];
                report.rows.push(Row {
                    object: Some(name.to_string()),
                    quality: Some(quality.to_string()),
                    step: Some(plan.step),
                    shading: Some(shading.to_string()),
                    shadows: (*shading == "PhongShadows").then(|| "rays".into()),
                    segments: Some(label.to_string()),
                    gpu_ms: runs[0].gpu_ms(),
                    flip: Some(crate::metrics::flip(&image, truth)?.mean),
                    rel_rmse: Some(crate::metrics::relative_rmse(&image, truth)?),
                    truth: Some(format!("RayMarch, step {}, same shading, Bounds", args.truth_step)),
                    work: Some(evals),
                    work_unit: Some("density evaluations".into()),
                    extra: extra.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
                    ..Row::new("figure11", "RayMarch", ms)
                });
                report.trace(format!("{name} {quality} {shading} {label}"), &runs[0].renderer);
                println!(
                    "| {name} | {quality} | {} | {shading} | {label} | {} | {:.0}% | {ms:.1} | {:.2} | {:.1} | {:.1} | \
                     {noise_ms:.1} | {:.0}% | {:.0}% |",
                    plan.step,
                    plan.dispatches,
                    covered * 100.0,
                    1e3 / ms,
                    evals / 1e6,
                    noised * NOISE_COUNT / 1e6,
                    100.0 * noise_ms / ms,
                    100.0 * ab
                );
            }
        }
    }
    segments_table(ctx, args, report)?;
    shadows_table(ctx, args, report)
}

/// The Figure 11 scenes (scenes/hypertextures/) of the shadows table.
const FIGURE11: &[&str] = &["teapot", "bunny", "cube"];
/// Shadow settings of the shadows table (`--shadows` values), Phong without shadows first.
const SHADOWS: &[&str] = &["none", "rays", "volume:32", "volume:64", "volume:128"];

/// Shadows on the Figure 11 scenes at HQ: Phong without shadows, shadow rays and light volumes,
/// timed in alternation (so load changes hit all), with the light volume's bake timed apart (it
/// is cached: a frame pays it only when the light or the density changes), and the error against
/// shadow rays at the truth step and against shadow rays at the same step.
pub(crate) fn shadows_table(ctx: &GpuContext, args: &Args, report: &mut Report) -> Result<()> {
    use crate::methods::ray_march::light_volume;
    use crate::scene::parse_shadows;
    println!(
        "\n| object | shadows | frame ms (wall) | x Phong | light volume bake ms | M density evals | FLIP vs truth | \
         FLIP vs rays |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let scenes = if args.quick { &FIGURE11[..1] } else { FIGURE11 };
    for name in scenes {
        let path = crate::project_root().join(format!("scenes/hypertextures/fig11_{name}.ron"));
        let scene = crate::scene::load(&path)?;
        let options = |step: f64, shadows: &str| -> Result<RenderOptions> {
            Ok(RenderOptions {
                size: Some(args.size),
                step: Some(step),
                shadows: Some(parse_shadows(shadows).map_err(crate::Error::Invalid)?),
                ..Default::default()
            })
        };
        let render = |opts: &RenderOptions| -> Result<crate::io::Image> {
            Ok(Renderer::new(ctx, Blueprint::new(&scene, opts)?)?.render(ctx)?.image)
        };
        let truth = render(&options(args.truth_step, "rays")?)?;
        let mut runs = Vec::new();
        for shadows in SHADOWS {
            let mut r = Renderer::new(ctx, Blueprint::new(&scene, &options(0.002, shadows)?)?)?;
            r.render_timed(ctx)?;
            runs.push(Timed::new(r));
        }
        for _ in 0..args.frames {
            for run in runs.iter_mut() {
                run.frame(ctx)?;
            }
        }
        let phong_ms = median(runs[0].times.clone());
        let rays = runs[1].renderer.render(ctx)?.image;
        for (shadows, run) in SHADOWS.iter().zip(&mut runs) {
            let ms = median(run.times.clone());
            let image = run.renderer.render(ctx)?.image;
            let (evals, _, _) = run.counts(ctx)?;
            let plan =
                run.renderer.blueprint.objects.iter().find_map(|o| o.method::<RayMarchPlan>().cloned());
            let plan = plan.expect("a RayMarch object");
            // The bake alone (the first compiles the kernels), with a readback to wait for it.
            let bake_ms = match &plan.light {
                Some(grid) => {
                    let grid_bake = plan.bake_mesh_grid(ctx)?;
                    let mut times = Vec::new();
                    for _ in 0..3 {
                        let t = Instant::now();
                        let volume = light_volume::bake(ctx, &plan, grid, grid_bake.as_ref())?;
                        ctx.read_buffer(&volume, 0, 4)?;
                        times.push(t.elapsed().as_secs_f64() * 1e3);
                    }
                    Some(median(times[1..].to_vec()))
                }
                None => None,
            };
            let flip = crate::metrics::flip(&image, &truth)?.mean;
            let flip_rays = crate::metrics::flip(&image, &rays)?.mean;
            println!(
                "| fig11_{name} | {shadows} | {ms:.1} | {:.2} | {} | {:.2} | {flip:.4} | {flip_rays:.4} |",
                ms / phong_ms,
                bake_ms.map_or("-".into(), |b| format!("{b:.1}")),
                evals / 1e6
            );
            let mut extra = std::collections::BTreeMap::new();
            extra.insert("phong_ratio".to_string(), ms / phong_ms);
            extra.insert("flip_vs_rays_same_step".to_string(), flip_rays);
            if let Some(b) = bake_ms {
                extra.insert("light_volume_bake_ms".to_string(), b);
            }
            report.rows.push(Row {
                object: Some(format!("fig11_{name}")),
                quality: Some("HQ".into()),
                step: Some(plan.step),
                shading: Some(if *shadows == "none" { "Phong" } else { "PhongShadows" }.into()),
                shadows: Some(shadows.to_string()),
                segments: Some("Bounds".into()),
                gpu_ms: run.gpu_ms(),
                flip: Some(flip),
                rel_rmse: Some(crate::metrics::relative_rmse(&image, &truth)?),
                truth: Some(format!("RayMarch, step {}, PhongShadows with shadow rays", args.truth_step)),
                work: Some(evals),
                work_unit: Some("density evaluations".into()),
                extra,
                ..Row::new("shadows", "RayMarch", ms)
            });
            report.trace(format!("fig11_{name} HQ shadows={shadows}"), &run.renderer);
        }
    }
    println!(
        "x Phong: frame time over Phong without shadows' (timed in alternation); the light volume's bake is cached \
         (a frame pays it when the light or the density changes)"
    );
    Ok(())
}
