//! GPU time and image of one setting, in two phases that keep lavapipe's timestamps honest.
//!
//! On lavapipe, once a device has run a render pass, later compute-pass timestamps can come back
//! near zero (see `src/bench.rs`: the slicing kernels do, from the second frame on); raster-pass
//! timestamps stay right. So, on a fresh device per setting:
//! 1. [`compute_passes`]: the setting's frame with its raster passes removed (the compute passes
//!    alone: slicing, ray casting), before any render pass has run on the device;
//! 2. [`full_frames`]: whole frames, for the image and the raster passes' times.
//!
//! Each phase renders warm-up frames (lavapipe compiles shader variants on first use; the image
//! frame of phase 2 is one) and then `frames` timed ones; a pass's time is its median. A frame's
//! GPU time is the sum of its passes'.

use std::time::Instant;

use crate::error::Result;
use crate::gpu::cache::GpuCache;
use crate::gpu::GpuContext;
use crate::graph::PassDecl;
use crate::io::Image;
use crate::methods::options::RenderOptions;
use crate::render::{Blueprint, Renderer};
use crate::scene::Scene;

/// Frames rendered and thrown away before the timed ones...
pub(crate) const WARM_UP_FRAMES: usize = 2;
/// ...or only one when it took longer than this (ms): first-use costs are then lost in the noise.
pub(crate) const LONG_FRAME_MS: f64 = 1000.0;

/// One pass's median GPU time.
#[derive(Debug, Clone)]
pub(crate) struct PassTime {
    pub(crate) name: String,
    pub(crate) compute: bool,
    pub(crate) ms: f64,
}

/// What phase 2 gives for a setting.
pub(crate) struct Frames {
    pub(crate) image: Image,
    /// Median GPU ms of each raster pass.
    pub(crate) raster: Vec<(String, f64)>,
    /// Median wall-clock ms of a whole frame: record, submit, wait until the GPU is idle, read the
    /// timestamps back.
    pub(crate) wall_ms: f64,
    /// Density evaluations of RayMarch objects in one frame (0 without any).
    pub(crate) evaluations: f64,
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// What phase 1 gives for a setting.
pub(crate) struct ComputeOnly {
    /// Median GPU ms of each compute pass.
    pub(crate) passes: Vec<(String, f64)>,
    /// Median wall-clock ms of a compute-only frame (0 when there is no compute pass).
    pub(crate) wall_ms: f64,
}

/// Phase 1: median GPU ms of each compute pass of `bp`'s frame, run without its raster passes.
/// Call it on a device where no render pass has run yet (a fresh one).
pub(crate) fn compute_passes(ctx: &GpuContext, mut bp: Blueprint, frames: usize) -> Result<ComputeOnly> {
    bp.plan.passes.retain(|p| matches!(p.decl, PassDecl::Compute { .. }));
    if bp.plan.passes.is_empty() {
        return Ok(ComputeOnly { passes: Vec::new(), wall_ms: 0.0 });
    }
    let mut r = Renderer::new(ctx, bp)?;
    let (passes, wall_ms) = timed(ctx, &mut r, frames, None)?;
    Ok(ComputeOnly { passes, wall_ms })
}

/// Phase 2: the image of `bp`'s frame, the median GPU ms of its raster passes and of its wall time.
pub(crate) fn full_frames(ctx: &GpuContext, bp: Blueprint, frames: usize) -> Result<Frames> {
    let raster: Vec<String> = bp
        .plan
        .passes
        .iter()
        .filter(|p| matches!(p.decl, PassDecl::Raster { .. }))
        .map(|p| p.decl.name().to_string())
        .collect();
    let mut r = Renderer::new(ctx, bp)?;
    let t = Instant::now();
    let image = r.render(ctx)?.image;
    let evaluations = evaluations(ctx, &r)?;
    let (times, wall_ms) = timed(ctx, &mut r, frames, Some(t.elapsed().as_secs_f64() * 1e3))?;
    let raster = times.into_iter().filter(|(n, _)| raster.contains(n)).collect();
    Ok(Frames { image, raster, wall_ms, evaluations })
}

/// Density evaluations of the frame just rendered, over every object whose method counts them
/// (`MethodPlan::evaluations`): what an adaptive stride saves, independent of the machine's load.
fn evaluations(ctx: &GpuContext, r: &Renderer) -> Result<f64> {
    let mut sum = 0.0;
    for (i, instance) in r.blueprint.instances.iter().enumerate() {
        let mut read = |name: &str| r.read_instance_buffer(ctx, i, name);
        sum += r.blueprint.plan_of(instance).evaluations(&mut read)?.unwrap_or(0.0);
    }
    Ok(sum)
}

/// Degrees the camera turns between the frames of an orbit (the preview's measured orbit).
pub(crate) const ORBIT_DEGREES: f64 = 2.0;

/// Orbit time: the median wall ms of `frames` frames (after warm-up) whose camera turned since
/// the last, each planned again, its GPU inputs made again with the bakes kept (as the preview
/// does while the camera is dragged), rendered and waited for: what a preview orbit costs,
/// CPU planning and uploads included.
pub(crate) fn orbit_ms(
    ctx: &GpuContext,
    scene: &Scene,
    options: &RenderOptions,
    frames: usize,
) -> Result<f64> {
    let mut cache = GpuCache::default();
    let camera = options.camera.unwrap_or(*scene.camera);
    let mut times = Vec::new();
    for i in 0..WARM_UP_FRAMES + frames.max(1) {
        let t = Instant::now();
        let opts =
            RenderOptions { camera: Some(camera.orbited(ORBIT_DEGREES * i as f64)), ..options.clone() };
        cache.begin();
        let mut r = Renderer::with_cache(ctx, Blueprint::new(scene, &opts)?, &mut cache)?;
        cache.retain_used();
        r.render_timed(ctx)?;
        if i >= WARM_UP_FRAMES {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(median(times))
}

/// The truth's image, its frame's progress shown as `talk` asks ([`Renderer::render_showing`]).
pub(crate) fn truth_image(
    ctx: &GpuContext,
    bp: Blueprint,
    talk: crate::progress::Verbosity,
) -> Result<Image> {
    Ok(Renderer::new(ctx, bp)?.render_showing(ctx, talk, "truth")?.image)
}

/// Warm-up frames (`warmed`: the wall ms of one already rendered), then `frames` timed ones:
/// median GPU ms per pass (submission order) and median wall ms per frame.
pub(crate) fn timed(
    ctx: &GpuContext,
    r: &mut Renderer,
    frames: usize,
    warmed: Option<f64>,
) -> Result<(Vec<(String, f64)>, f64)> {
    let mut done = warmed.into_iter().collect::<Vec<f64>>();
    while done.len() < WARM_UP_FRAMES && done.last().is_none_or(|&ms| ms < LONG_FRAME_MS) {
        let t = Instant::now();
        r.render_timed(ctx)?;
        done.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let mut per_pass: Vec<(String, Vec<f64>)> = Vec::new();
    let mut wall = Vec::new();
    for _ in 0..frames.max(1) {
        let t = Instant::now();
        let times = r.render_timed(ctx)?;
        wall.push(t.elapsed().as_secs_f64() * 1e3);
        for (name, ms) in times {
            match per_pass.iter_mut().find(|p| p.0 == name) {
                Some(p) => p.1.push(ms),
                None => per_pass.push((name, vec![ms])),
            }
        }
    }
    Ok((per_pass.into_iter().map(|(n, v)| (n, median(v))).collect(), median(wall)))
}
