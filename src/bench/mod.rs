//! `voltex bench`: the 2002 paper's Table 1 set-up on the current adapter. For each scene, plane
//! count and trivial-reject setting: median GPU time per pass from timestamps after warm-up, wall
//! time per frame, the CPU twin doing the same classification and intersection, and the error
//! against a converged render (many planes) of the same scene.
//!
//! Lavapipe returns near-zero compute timestamps once a render pass has run in the process, so
//! the slicing kernels are timed first, alone (graph `slices_only.ron`), before any full frame.
//!
//! `--json FILE` writes the rows ([`json`]) with the cost model ([`cost`]: frame time against
//! slice triangles, planes x visible prisms); `--limits` measures the adapter's own blend, texture
//! and noise rates first (`limits`) and prints each setting's share of the blend limit.

pub mod cost;
pub mod hyper;
pub mod json;
pub(crate) mod limits;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::io::Image;
use crate::pareto::measure::{orbit_ms, timed};
use crate::render::{Blueprint, RenderOptions, Renderer};
use crate::scene::{Compositor, Scene};

pub(crate) fn default_scenes() -> Vec<PathBuf> {
    let root = crate::project_root().join("scenes/view_slices");
    vec![root.join("torus_egg.ron"), root.join("terrain.ron")]
}

/// One setting of the table.
struct Setting {
    scene: usize,
    planes: u32,
    reject: bool,
    compositor: Compositor,
}

#[derive(Default)]
struct Row {
    /// Median GPU ms of the slicing kernels, timed alone.
    slicing: Vec<(String, f64)>,
    /// Median GPU ms of the raster passes of a full frame.
    raster: Vec<(String, f64)>,
    wall_ms: f64,
    /// Median wall ms of a frame while the camera orbits (planning and uploads included).
    orbit_ms: f64,
    cpu_ms: f64,
    /// Fragments the slices cover: their projected area in pixels, summed.
    fragments: f64,
    /// Slice triangles the CPU twin emits (planes x visible prisms, fanned).
    triangles: f64,
    rel_rmse: f64,
    flip: f64,
}

/// `voltex bench`'s arguments.
pub struct Args {
    /// Scene files to measure.
    pub scenes: Vec<PathBuf>,
    /// ViewSlices plane counts to measure each scene at.
    pub planes: Vec<u32>,
    /// Frame size in pixels (width, height).
    pub size: (u32, u32),
    /// Timed frames per row, after warm-up.
    pub frames: usize,
    /// Planes of the ViewSlices render the error is measured against.
    pub reference_planes: u32,
    /// Write the rows as JSON here.
    pub json: Option<PathBuf>,
    /// Measure the adapter's blend, texture and noise rates first.
    pub limits: bool,
    /// Write the timed frames' passes as a Chrome/Perfetto trace here.
    pub trace: Option<PathBuf>,
    /// The compositors to measure (each setting with each).
    pub compositors: Vec<Compositor>,
    /// What it says on stderr while it measures (the tables go to stdout).
    pub verbosity: crate::progress::Verbosity,
}

/// The passes that bring a ViewSlices sweep's slices into the frame, by compositor: the `draw`
/// column sums them.
fn draw_passes(c: Compositor) -> &'static [&'static str] {
    match c {
        Compositor::Raster => &["draw_slices"],
        Compositor::Tiles => &["bin_slices", "scan_tiles", "fill_tiles", "composite_tiles", "blend_tiles"],
    }
}

/// Runs `voltex bench`: each scene at each plane count, timed and compared, printed as a table
/// and written as asked.
pub fn run(args: &Args) -> Result<()> {
    let Args { scenes, planes, size, frames, reference_planes, .. } = args;
    let (size, frames, reference_planes) = (*size, *frames, *reference_planes);
    json::check_output(args.json.as_deref())?;
    json::check_output(args.trace.as_deref())?;
    let paths = if scenes.is_empty() { default_scenes() } else { scenes.to_vec() };
    let scenes: Vec<Scene> = paths.iter().map(|p| crate::scene::load(p)).collect::<Result<_>>()?;
    let mut settings = Vec::new();
    for scene in 0..scenes.len() {
        for &n in planes.iter() {
            for &compositor in &args.compositors {
                for reject in [true, false] {
                    settings.push(Setting { scene, planes: n, reject, compositor });
                }
            }
        }
    }
    let ctx = GpuContext::new()?;
    let mut report = json::Report::new("bench", ctx.adapter_line(), size, frames);
    // Before any render pass: lavapipe's compute timestamps are only right until then.
    if args.limits {
        report.limits = Some(limits::measure(&ctx)?);
    }
    let options = |s: &Setting, graph: Option<PathBuf>| RenderOptions {
        size: Some(size),
        planes: Some(s.planes),
        trivial_reject: Some(s.reject),
        compositor: Some(s.compositor),
        graph,
        ..Default::default()
    };

    // Phase 1: the slicing kernels alone, before any render pass runs in this process.
    let slices_only = crate::project_root().join("graphs/slices_only.ron");
    let mut rows: Vec<Row> = Vec::new();
    // Each setting twice: its slicing alone, then its full frame.
    let mut progress = crate::progress::Progress::new(2 * settings.len(), args.verbosity);
    let label = |s: &Setting, what: &str| {
        let stem = paths[s.scene].file_stem().unwrap_or_default().to_string_lossy();
        format!("{stem} planes={} reject={} {:?} {what}", s.planes, s.reject, s.compositor)
    };
    let keep = args.verbosity == crate::progress::Verbosity::Verbose;
    for s in &settings {
        progress.started(&label(s, "slicing alone"));
        let bp = Blueprint::new(&scenes[s.scene], &options(s, Some(slices_only.clone())))?;
        let mut r = Renderer::new(&ctx, bp)?;
        let (slicing, _) = timed(&ctx, &mut r, frames, None)?;
        let stem = paths[s.scene].file_stem().unwrap_or_default().to_string_lossy();
        report.trace(
            format!("{stem} planes={} reject={} {:?} slicing alone", s.planes, s.reject, s.compositor),
            &r,
        );
        let mut cpu = Vec::new();
        let (mut fragments, mut triangles) = (0.0, 0.0);
        for o in &r.blueprint.objects {
            let Some(vs) = o.method::<crate::methods::view_slices::ViewSlicesPlan>() else { continue };
            let t = Instant::now();
            let out = crate::methods::view_slices::slice_prisms::emit_slices(
                &o.shell,
                &vs.sweep,
                vs.trivial_reject,
            );
            cpu.push(t.elapsed().as_secs_f64() * 1e3);
            fragments += covered_pixels(&r.blueprint, &out);
            triangles += out.iter().map(|p| p.len() / 3).sum::<usize>() as f64;
        }
        let ms: f64 = slicing.iter().map(|p| p.1).sum();
        let line = format!("{}: {ms:.2} ms", label(s, "slicing alone"));
        progress.finished(&label(s, "slicing alone"), &line, true, keep);
        rows.push(Row { slicing, cpu_ms: cpu.iter().sum(), fragments, triangles, ..Default::default() });
    }

    // Phase 2: full frames, their raster passes and wall time, and the error of each setting.
    let mut references: Vec<Option<Image>> = vec![None; scenes.len()];
    for (s, row) in settings.iter().zip(&mut rows) {
        progress.started(&label(s, "frame"));
        if references[s.scene].is_none() {
            let opts =
                RenderOptions { size: Some(size), planes: Some(reference_planes), ..Default::default() };
            references[s.scene] =
                Some(Renderer::new(&ctx, Blueprint::new(&scenes[s.scene], &opts)?)?.render(&ctx)?.image);
        }
        let reference = references[s.scene].as_ref().unwrap();
        let mut r = Renderer::new(&ctx, Blueprint::new(&scenes[s.scene], &options(s, None))?)?;
        let image = r.render(&ctx)?.image;
        row.rel_rmse = crate::metrics::relative_rmse(&image, reference)?;
        row.flip = crate::metrics::flip(&image, reference)?.mean;
        let (passes, wall) = timed(&ctx, &mut r, frames, None)?;
        let stem = paths[s.scene].file_stem().unwrap_or_default().to_string_lossy();
        report.trace(format!("{stem} planes={} reject={} {:?} frame", s.planes, s.reject, s.compositor), &r);
        let draw = draw_passes(s.compositor);
        row.raster =
            passes.into_iter().filter(|p| draw.contains(&p.0.as_str()) || p.0 == "composite").collect();
        row.wall_ms = wall;
        row.orbit_ms = orbit_ms(&ctx, &scenes[s.scene], &options(s, None), frames)?;
        let line = format!("{}: {:.1} ms, FLIP {:.4}", label(s, "frame"), row.wall_ms, row.flip);
        progress.finished(&label(s, "frame"), &line, true, keep);
    }
    progress.end();

    println!("adapter: {}", ctx.adapter_line());
    println!("{}x{}, median of {frames} frames after warm-up; times in ms", size.0, size.1);
    println!(
        "error: relative RMSE and mean FLIP against the same scene sliced with {reference_planes} planes"
    );
    println!(
        "| scene | planes | reject | compositor | count | scan | emit | slicing | draw | Mfrag | Mfrag/s | composite | frame (wall) | fps | orbit | CPU twin | rel RMSE | FLIP |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (s, row) in settings.iter().zip(&rows) {
        let get = |v: &[(String, f64)], p: &str| v.iter().find(|x| x.0 == p).map(|x| x.1).unwrap_or(f64::NAN);
        let slicing: f64 = row.slicing.iter().map(|p| p.1).sum();
        let name = Path::new(&paths[s.scene]).file_stem().unwrap_or_default().to_string_lossy().to_string();
        let draw = draw_ms(row, s.compositor);
        println!(
            "| {name} | {} | {} | {:?} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1} | {:.0} | {:.3} | {:.1} | {:.2} | {:.1} | {:.1} | {:.4} | {:.4} |",
            s.planes,
            if s.reject { "on" } else { "off" },
            s.compositor,
            get(&row.slicing, "count_slices"),
            get(&row.slicing, "scan_plane_offsets"),
            get(&row.slicing, "emit_slices"),
            slicing,
            draw,
            row.fragments * 1e-6,
            row.fragments * 1e-3 / draw,
            get(&row.raster, "composite"),
            row.wall_ms,
            1000.0 / row.wall_ms,
            row.orbit_ms,
            row.cpu_ms,
            row.rel_rmse,
            row.flip,
        );
    }
    println!("slicing = count + scan + emit (classification and intersection, GPU timestamps, timed alone);");
    println!(
        "Mfrag = millions of fragments the slice polygons cover (projected area); Mfrag/s = Mfrag / draw;"
    );
    println!(
        "draw = draw_slices (Raster) or bin + scan + fill + composite + blend of the tiles (Tiles; on lavapipe \
         compute timestamps go wrong once a render pass has run: compare frame (wall))"
    );
    println!(
        "frame (wall) = submit to idle of a whole frame; orbit = the median wall time of a frame whose camera \
         turned (planned, uploaded, rendered, waited for); CPU twin = the same slicing on one CPU core"
    );
    let truth = format!("ViewSlices, {reference_planes} planes");
    for (s, row) in settings.iter().zip(&rows) {
        let name = Path::new(&paths[s.scene]).file_stem().unwrap_or_default().to_string_lossy().to_string();
        let slicing: f64 = row.slicing.iter().map(|p| p.1).sum();
        let raster: f64 = row.raster.iter().map(|p| p.1).sum();
        let mut extra = std::collections::BTreeMap::new();
        for (k, v) in row.slicing.iter().chain(&row.raster) {
            extra.insert(format!("{k}_ms"), *v);
        }
        extra.insert("fragments".into(), row.fragments);
        extra.insert("cpu_twin_ms".into(), row.cpu_ms);
        extra.insert("orbit_ms".into(), row.orbit_ms);
        let draw = draw_ms(row, s.compositor);
        extra.insert("draw_ms".into(), draw);
        if let Some(l) = &report.limits {
            extra.insert("blend_limit_share".into(), row.fragments / (draw * 1e-3) / l.blend_fragments_per_s);
            // The frame against the time the adapter needs to blend its fragments (goal: <= 1.5).
            extra.insert(
                "frame_over_blend_limit".into(),
                row.wall_ms * 1e-3 / (row.fragments / l.blend_fragments_per_s),
            );
            // The same with the cost of its triangles as the adapter draws small ones.
            let bound = limits::bound_seconds(l, row.triangles, row.fragments);
            extra.insert("frame_over_adapter_bound".into(), row.wall_ms * 1e-3 / bound);
        }
        report.rows.push(json::Row {
            scene: Some(name),
            planes: Some(s.planes),
            trivial_reject: Some(s.reject),
            compositor: Some(format!("{:?}", s.compositor)),
            gpu_ms: (!row.slicing.is_empty()).then_some(slicing + raster),
            flip: Some(row.flip),
            rel_rmse: Some(row.rel_rmse),
            truth: Some(truth.clone()),
            work: Some(row.triangles),
            work_unit: Some("slice triangles".into()),
            extra,
            ..json::Row::new("table1", "ViewSlices", row.wall_ms)
        });
    }
    if let Some(l) = &report.limits {
        println!("\n{}", limits::describe(l));
        println!(
            "| scene | planes | reject | compositor | Mfrag/s in draw | share of the blend limit | frame / (Mfrag / blend rate) | frame / (triangles / triangle rate + Mfrag / blend rate) |"
        );
        println!("|---|---|---|---|---|---|---|---|");
        for r in &report.rows {
            let share = r.extra.get("blend_limit_share").copied().unwrap_or(f64::NAN);
            println!(
                "| {} | {} | {} | {} | {:.0} | {:.0}% | {:.2} | {:.2} |",
                r.scene.as_deref().unwrap_or(""),
                r.planes.unwrap_or(0),
                if r.trivial_reject == Some(true) { "on" } else { "off" },
                r.compositor.as_deref().unwrap_or(""),
                share * l.blend_fragments_per_s / 1e6,
                share * 100.0,
                r.extra.get("frame_over_blend_limit").copied().unwrap_or(f64::NAN),
                r.extra.get("frame_over_adapter_bound").copied().unwrap_or(f64::NAN),
            );
        }
    }
    report.cost_models = cost::fit(&report.rows);
    for f in &report.cost_models {
        println!("{}", f.describe());
    }
    report.finish(args.json.as_deref(), args.trace.as_deref())
}

/// GPU ms of the passes that bring the slices into the frame (see [`draw_passes`]).
fn draw_ms(row: &Row, c: Compositor) -> f64 {
    let passes = draw_passes(c);
    let found: Vec<f64> = row.raster.iter().filter(|p| passes.contains(&p.0.as_str())).map(|p| p.1).collect();
    if found.is_empty() {
        f64::NAN
    } else {
        found.iter().sum()
    }
}

fn covered_pixels(bp: &Blueprint, planes: &[Vec<crate::types::SliceVertex>]) -> f64 {
    let vp = glam::Mat4::from_cols_array_2d(&bp.frame.view_proj);
    let (w, h) = (bp.size.0 as f32, bp.size.1 as f32);
    let mut total = 0.0f64;
    for tri in planes.iter().flat_map(|p| p.chunks_exact(3)) {
        let q: [glam::Vec2; 3] = std::array::from_fn(|i| {
            let v = &tri[i];
            let c = vp * glam::Vec4::new(v.position[0], v.position[1], v.position[2], 1.0);
            glam::Vec2::new((c.x / c.w * 0.5 + 0.5) * w, (c.y / c.w * 0.5 + 0.5) * h)
        });
        let outside = q.iter().all(|p| p.x < 0.0)
            || q.iter().all(|p| p.x > w)
            || q.iter().all(|p| p.y < 0.0)
            || q.iter().all(|p| p.y > h);
        if !outside {
            total += 0.5 * ((q[1] - q[0]).perp_dot(q[2] - q[0])).abs() as f64;
        }
    }
    total
}
