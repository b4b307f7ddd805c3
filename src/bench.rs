//! `voltex bench`: the 2002 paper's Table 1 set-up on the current adapter. For each scene, plane
//! count and trivial-reject setting: median GPU time per pass from timestamps after warm-up, wall
//! time per frame, and the CPU twin doing the same classification and intersection.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::render::{Blueprint, RenderOptions, Renderer};

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub fn default_scenes() -> Vec<PathBuf> {
    let root = crate::project_root().join("scenes/view_slices");
    vec![root.join("torus_egg.ron"), root.join("terrain.ron")]
}

/// `reference_planes`: plane count of the converged image each row's error is measured against
/// (a stand-in for the exact reference renderer, which does not exist yet).
pub fn run(
    scenes: &[PathBuf],
    planes: &[u32],
    size: (u32, u32),
    frames: usize,
    reference_planes: u32,
) -> Result<()> {
    let scenes = if scenes.is_empty() { default_scenes() } else { scenes.to_vec() };
    let ctx = GpuContext::new()?;
    println!("adapter: {}", ctx.adapter_line());
    println!("{}x{}, median of {frames} frames after 2 warm-up frames; times in ms", size.0, size.1);
    println!(
        "{:<12} {:>6} {:>7} | {:>8} {:>8} {:>8} {:>8} {:>9} | {:>9} {:>9} | {:>9}",
        "scene",
        "planes",
        "reject",
        "count",
        "emit",
        "slices",
        "draw",
        "gpu total",
        "wall",
        "fps(wall)",
        "cpu twin"
    );
    for scene_path in &scenes {
        let scene = crate::scene::load(scene_path)?;
        let reference = {
            let opts =
                RenderOptions { size: Some(size), planes: Some(reference_planes), ..Default::default() };
            Renderer::new(&ctx, Blueprint::new(&scene, &opts)?)?.render(&ctx)?.image
        };
        for &n in planes {
            for reject in [true, false] {
                let opts = RenderOptions {
                    size: Some(size),
                    planes: Some(n),
                    trivial_reject: Some(reject),
                    ..Default::default()
                };
                let row = measure(&ctx, &scene, &opts, frames, &reference)?;
                let name =
                    Path::new(scene_path).file_stem().unwrap_or_default().to_string_lossy().to_string();
                let pass = |p: &str| row.passes.iter().find(|x| x.0 == p).map(|x| x.1).unwrap_or(f64::NAN);
                println!(
                    "{:<12} {:>6} {:>7} | {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>9.3} | {:>9.2} {:>9.1} | {:>9.2} | {:>8.4} {:>7.4}",
                    name,
                    n,
                    reject,
                    pass("count_slices"),
                    pass("emit_slices"),
                    pass("count_slices") + pass("scan_plane_offsets") + pass("emit_slices"),
                    pass("draw_slices"),
                    row.passes.iter().map(|p| p.1).sum::<f64>(),
                    row.wall_ms,
                    1000.0 / row.wall_ms,
                    row.cpu_ms,
                    row.rel_rmse,
                    row.flip,
                );
            }
        }
    }
    println!("slices = count + scan + emit (classification and intersection); cpu twin = the same work on one CPU core");
    Ok(())
}

struct Row {
    passes: Vec<(String, f64)>,
    wall_ms: f64,
    cpu_ms: f64,
    rel_rmse: f64,
    flip: f64,
}

fn measure(
    ctx: &GpuContext,
    scene: &crate::scene::Scene,
    opts: &RenderOptions,
    frames: usize,
    reference: &crate::io::Image,
) -> Result<Row> {
    let bp = Blueprint::new(scene, opts)?;
    let mut r = Renderer::new(ctx, bp)?;
    let image = r.render(ctx)?.image;
    let rel_rmse = crate::metrics::relative_rmse(&image, reference)?;
    let flip = crate::metrics::flip(&image, reference)?.mean;
    r.render_timed(ctx)?; // second warm-up frame (the first rendered the image above)
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
    let mut cpu = Vec::new();
    for o in r.blueprint.objects.iter().filter(|o| o.slicing.is_some()) {
        let (params, _) = o.slicing.unwrap();
        let t = Instant::now();
        let out = crate::cpu::slice_prisms::slice_all(
            &o.shell.vertices,
            &o.shell.prisms,
            &params,
            o.trivial_reject,
        );
        cpu.push(t.elapsed().as_secs_f64() * 1e3);
        std::hint::black_box(out);
    }
    Ok(Row {
        passes: per_pass.into_iter().map(|(n, v)| (n, median(v))).collect(),
        wall_ms: median(wall),
        cpu_ms: cpu.iter().sum(),
        rel_rmse,
        flip,
    })
}
