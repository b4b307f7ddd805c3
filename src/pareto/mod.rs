//! `voltex pareto SCENE`: speed against error. Sweeps each method's quality knobs over the
//! scene's textured objects, measures every setting's GPU time per frame ([`measure`]) and its
//! error against a truth image (mean FLIP, relative RMSE), and writes `pareto.csv` and
//! `pareto.svg` ([`svg`]) with the Pareto fronts ([`front`]) per method and overall.
//!
//! A setting is a method label, a description of its knobs and the [`RenderOptions`] that apply
//! them; a new method adds a function like [`view_slices`] and one line in [`sweep`].

pub mod front;
pub mod measure;
pub mod svg;

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::io::atomic;
use crate::render::{Blueprint, MethodKind, RenderOptions};
use crate::scene::{Scene, MAX_PLANES};

/// Default plane counts of the `ViewSlices` sweep.
pub const DEFAULT_PLANES: [u32; 8] = [16, 32, 64, 128, 256, 512, 1024, 2048];
/// Default ray steps of the `Reference` sweep, as multiples of its default step.
pub const DEFAULT_STEP_FACTORS: [f64; 5] = [2.0, 4.0, 8.0, 16.0, 32.0];

/// What errors are measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Truth {
    /// Every textured object ray cast by `Reference` with its default step.
    Reference,
    /// Every textured object sliced by `ViewSlices` with this many planes (a converged slicing).
    ViewSlices(u32),
}

impl FromStr for Truth {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        const EXPECTED: &str = "expected `reference` or `view-slices:PLANES`, e.g. view-slices:4096";
        if s == "reference" {
            return Ok(Truth::Reference);
        }
        let n = s.strip_prefix("view-slices:").ok_or(EXPECTED)?;
        match n.parse::<u32>() {
            Ok(n) if (1..=MAX_PLANES).contains(&n) => Ok(Truth::ViewSlices(n)),
            _ => Err(format!("`{n}`: expected a plane count in 1..={MAX_PLANES}")),
        }
    }
}

impl fmt::Display for Truth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Truth::Reference => write!(f, "Reference, default step"),
            Truth::ViewSlices(n) => write!(f, "ViewSlices, {n} planes"),
        }
    }
}

impl Truth {
    fn options(self, size: (u32, u32)) -> RenderOptions {
        let size = Some(size);
        match self {
            Truth::Reference => {
                RenderOptions { size, method: Some(MethodKind::Reference), ..Default::default() }
            }
            Truth::ViewSlices(n) => RenderOptions {
                size,
                method: Some(MethodKind::ViewSlices),
                planes: Some(n),
                trivial_reject: Some(true),
                ..Default::default()
            },
        }
    }
}

/// The command's arguments.
#[derive(Debug, Clone)]
pub struct Args {
    pub scene: PathBuf,
    pub size: (u32, u32),
    /// Timed frames per setting (after warm-up); medians are reported.
    pub frames: usize,
    /// Output folder (default `out/pareto/<scene stem>`), created if missing.
    pub out: Option<PathBuf>,
    pub truth: Truth,
    /// Methods to sweep.
    pub methods: Vec<MethodKind>,
    /// `ViewSlices` plane counts (each with the trivial reject on and off).
    pub planes: Vec<u32>,
    /// `Reference` steps as multiples of the default step.
    pub steps: Vec<f64>,
}

/// One point of the sweep.
#[derive(Debug, Clone)]
pub struct Setting {
    pub method: &'static str,
    /// The knobs, e.g. `planes=64 reject=on` (no commas: it is a CSV field).
    pub knobs: String,
    /// A short name for the chart, e.g. `64` (`64 no-reject` with the trivial reject off).
    pub tag: String,
    pub options: RenderOptions,
}

/// A measured setting.
struct Row {
    setting: Setting,
    passes: Vec<measure::PassTime>,
    wall_ms: f64,
    /// Wall ms of the compute-only frame (phase 1), to check its timestamps against.
    compute_wall_ms: f64,
    flip: f64,
    rel_rmse: f64,
    method_front: bool,
    overall_front: bool,
}

impl Row {
    /// GPU ms of a frame: the sum of its passes' medians (NaN without timestamps).
    fn gpu_ms(&self) -> f64 {
        if self.passes.is_empty() {
            return f64::NAN;
        }
        self.passes.iter().map(|p| p.ms).sum()
    }
    /// The time plotted: GPU time, or wall time on adapters without timestamps.
    fn time(&self) -> f64 {
        let gpu = self.gpu_ms();
        if gpu.is_finite() {
            gpu
        } else {
            self.wall_ms
        }
    }
}

impl Args {
    fn check(&self) -> Result<()> {
        if let Some(&p) = self.planes.iter().find(|&&p| p == 0 || p > MAX_PLANES) {
            return Err(Error::Invalid(format!("--planes {p}: expected plane counts in 1..={MAX_PLANES}")));
        }
        if let Some(&f) = self.steps.iter().find(|&&f| !(f.is_finite() && f > 0.0)) {
            return Err(Error::Invalid(format!(
                "--steps {f}: expected positive multiples of the default step"
            )));
        }
        if self.frames == 0 {
            return Err(Error::Invalid("--frames 0: expected at least one timed frame".into()));
        }
        Ok(())
    }

    pub fn out_dir(&self) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/pareto").join(self.scene.file_stem().unwrap_or_default()))
    }
}

/// `ViewSlices`: each plane count with the trivial reject on and off (a speed knob only).
pub fn view_slices(args: &Args) -> Vec<Setting> {
    let mut v = Vec::new();
    for &planes in &args.planes {
        for reject in [true, false] {
            v.push(Setting {
                method: "ViewSlices",
                knobs: format!("planes={planes} reject={}", if reject { "on" } else { "off" }),
                tag: if reject { planes.to_string() } else { format!("{planes} no-reject") },
                options: RenderOptions {
                    size: Some(args.size),
                    method: Some(MethodKind::ViewSlices),
                    planes: Some(planes),
                    trivial_reject: Some(reject),
                    ..Default::default()
                },
            });
        }
    }
    v
}

/// `Reference`: the ray step as multiples of `default_step` (one step for all objects).
pub fn reference(args: &Args, default_step: f64) -> Vec<Setting> {
    args.steps
        .iter()
        .map(|&f| Setting {
            method: "Reference",
            knobs: format!("step={f}x"),
            tag: format!("{f}x"),
            options: RenderOptions {
                size: Some(args.size),
                method: Some(MethodKind::Reference),
                step: Some(f * default_step),
                ..Default::default()
            },
        })
        .collect()
}

/// Every setting of the methods asked for, with notes on what cannot be swept.
pub fn sweep(scene: &Scene, args: &Args) -> Result<(Vec<Setting>, Vec<String>)> {
    let mut settings = Vec::new();
    let mut notes = Vec::new();
    for &m in &args.methods {
        match m {
            MethodKind::ViewSlices => settings.extend(view_slices(args)),
            MethodKind::Reference => match reference_default_step(scene)? {
                Some(step) => settings.extend(reference(args, step)),
                None => notes.push("Reference: no textured object to step through".into()),
            },
        }
    }
    Ok((settings, notes))
}

/// The `Reference` method's default step for the scene: half the smallest voxel extent (world
/// units, along `s`, `t` or `w`) over its textured objects. With several objects, the sweep
/// scales this one step for all of them.
pub fn reference_default_step(scene: &Scene) -> Result<Option<f64>> {
    let mut best = f64::INFINITY;
    for o in scene.objects()? {
        let texel = o.texel.as_ref().and_then(|t| scene.texels.get(t));
        let (Some(_), Some(texel)) = (&o.method, texel) else { continue };
        let [rs, rt, rw] = texel.resolution.map(f64::from);
        for h in &o.surface.heights {
            if h.length() > 0.0 {
                best = best.min(h.length() / rw);
            }
        }
        for (tri, uv) in o.surface.triangles.iter().zip(&o.surface.corner_uvs) {
            let p = tri.map(|i| o.surface.positions[i as usize]);
            let (e1, e2, d1, d2) = (p[1] - p[0], p[2] - p[0], uv[1] - uv[0], uv[2] - uv[0]);
            let det = d1.x * d2.y - d2.x * d1.y;
            if det.abs() > 1e-12 {
                // World length per unit of s and of t over this triangle.
                let ds = (e1 * d2.y - e2 * d1.y) / det;
                let dt = (e2 * d1.x - e1 * d2.x) / det;
                best = best.min(ds.length() / rs).min(dt.length() / rt);
            }
        }
    }
    Ok((best.is_finite() && best > 0.0).then_some(0.5 * best))
}

pub fn run(args: &Args) -> Result<()> {
    args.check()?;
    let scene = crate::scene::load(&args.scene)?;
    let out = args.out_dir();
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::file(&out, format!("cannot create the output folder: {e}")))?;
    atomic::check_writable_dir(&out)?;
    let truth_bp = Blueprint::new(&scene, &args.truth.options(args.size)).map_err(|e| {
        Error::Invalid(format!(
            "the truth ({}) cannot be rendered: {e}; try --truth view-slices:4096",
            args.truth
        ))
    })?;
    drop(truth_bp);
    let (all, mut notes) = sweep(&scene, args)?;
    // Settings that cannot be planned are reported, once per method and error, and skipped.
    let mut settings = Vec::new();
    let mut blueprints = Vec::new();
    for s in all {
        match Blueprint::new(&scene, &s.options) {
            Ok(bp) => {
                blueprints.push(bp);
                settings.push(s);
            }
            Err(e) => note(&mut notes, &s, &e),
        }
    }
    if settings.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: nothing to measure: {}",
            args.scene.display(),
            notes.join("; ")
        )));
    }

    let ctx = GpuContext::new()?;
    let n = settings.len();
    // Phase 1: compute passes alone, before any render pass runs on this device.
    let mut compute: Vec<Option<measure::ComputeOnly>> = Vec::new();
    for (i, (s, bp)) in settings.iter().zip(blueprints).enumerate() {
        eprintln!("[{}/{n}] {} {}: compute passes", i + 1, s.method, s.knobs);
        compute
            .push(measure::compute_passes(&ctx, bp, args.frames).map_err(|e| note(&mut notes, s, &e)).ok());
    }
    // Phase 2: the truth, then whole frames for images and raster passes.
    eprintln!("truth: {}", args.truth);
    let truth = measure::image(&ctx, Blueprint::new(&scene, &args.truth.options(args.size))?)?;
    let mut rows = Vec::new();
    for (i, (s, compute)) in settings.into_iter().zip(compute).enumerate() {
        let Some(compute) = compute else { continue };
        eprintln!("[{}/{n}] {} {}: frames", i + 1, s.method, s.knobs);
        let frames = match Blueprint::new(&scene, &s.options)
            .and_then(|bp| measure::full_frames(&ctx, bp, args.frames))
        {
            Ok(f) => f,
            Err(e) => {
                note(&mut notes, &s, &e);
                continue;
            }
        };
        let passes = compute
            .passes
            .into_iter()
            .map(|(name, ms)| measure::PassTime { name, compute: true, ms })
            .chain(frames.raster.into_iter().map(|(name, ms)| measure::PassTime { name, compute: false, ms }))
            .collect();
        rows.push(Row {
            passes,
            wall_ms: frames.wall_ms,
            compute_wall_ms: compute.wall_ms,
            flip: crate::metrics::flip(&frames.image, &truth)?.mean,
            rel_rmse: crate::metrics::relative_rmse(&frames.image, &truth)?,
            setting: s,
            method_front: false,
            overall_front: false,
        });
    }
    mark_fronts(&mut rows);

    let csv_path = out.join("pareto.csv");
    let svg_path = out.join("pareto.svg");
    atomic::write_bytes(&csv_path, csv(&rows).as_bytes())?;
    let title = format!(
        "{}: time against error ({}x{}, truth: {})",
        args.scene.file_stem().unwrap_or_default().to_string_lossy(),
        args.size.0,
        args.size.1,
        args.truth
    );
    atomic::write_bytes(&svg_path, chart(&rows, &title, ctx.has_timestamps()).as_bytes())?;
    crate::io::png::write_tonemapped(&out.join("truth.png"), &truth)?;
    print_report(args, &ctx, &rows, &notes);
    println!("wrote {}, {} and truth.png", csv_path.display(), svg_path.display());
    Ok(())
}

/// Records why a setting was skipped, once per method and message.
fn note(notes: &mut Vec<String>, s: &Setting, e: &Error) {
    let line = format!("{}: not measured: {e}", s.method);
    if !notes.contains(&line) {
        eprintln!("{line} ({})", s.knobs);
        notes.push(line);
    }
}

fn mark_fronts(rows: &mut [Row]) {
    let xy: Vec<(f64, f64)> = rows.iter().map(|r| (r.time(), r.flip)).collect();
    for (r, on) in rows.iter_mut().zip(front::front(&xy)) {
        r.overall_front = on;
    }
    let methods: Vec<&'static str> = unique(rows.iter().map(|r| r.setting.method));
    for m in methods {
        let ids: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].setting.method == m).collect();
        let pts: Vec<(f64, f64)> = ids.iter().map(|&i| xy[i]).collect();
        for (&i, on) in ids.iter().zip(front::front(&pts)) {
            rows[i].method_front = on;
        }
    }
}

fn unique<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut v = Vec::new();
    for x in items {
        if !v.contains(&x) {
            v.push(x);
        }
    }
    v
}

fn num(v: Option<f64>) -> String {
    v.filter(|v| v.is_finite()).map(|v| format!("{v:.6}")).unwrap_or_default()
}

/// One row per measured setting; `passes` lists `name=ms` of every pass (compute passes first).
fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "method,knobs,planes,trivial_reject,step,gpu_ms,compute_ms,raster_ms,wall_ms,flip,rel_rmse,\
         method_front,overall_front,passes\n",
    );
    for r in rows {
        let o = &r.setting.options;
        let sum = |compute: bool| r.passes.iter().filter(|p| p.compute == compute).map(|p| p.ms).sum::<f64>();
        let passes: Vec<String> = r.passes.iter().map(|p| format!("{}={:.4}", p.name, p.ms)).collect();
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.setting.method,
            r.setting.knobs,
            o.planes.map(|p| p.to_string()).unwrap_or_default(),
            o.trivial_reject.map(|t| t.to_string()).unwrap_or_default(),
            num(o.step),
            num(Some(r.gpu_ms())),
            num(Some(sum(true))),
            num(Some(sum(false))),
            num(Some(r.wall_ms)),
            num(Some(r.flip)),
            num(Some(r.rel_rmse)),
            r.method_front,
            r.overall_front,
            passes.join(";"),
        ));
    }
    s
}

fn chart(rows: &[Row], title: &str, timestamps: bool) -> String {
    let series: Vec<svg::Series> = unique(rows.iter().map(|r| r.setting.method))
        .into_iter()
        .map(|m| svg::Series {
            label: m.to_string(),
            points: rows
                .iter()
                .filter(|r| r.setting.method == m)
                .map(|r| svg::Point {
                    x: r.time(),
                    y: r.flip,
                    label: format!("{} {}", m, r.setting.knobs),
                    tag: r.setting.tag.clone(),
                })
                .collect(),
        })
        .collect();
    let x_label = if timestamps {
        "GPU time per frame (ms, log): sum of pass medians"
    } else {
        "wall time per frame (ms, log)"
    };
    svg::render(&svg::Chart { title, x_label, y_label: "error: mean FLIP (log)", series: &series })
}

/// Timestamps against wall clock, summed over all settings: compute-only frames (their
/// timestamps should account for nearly all their wall time) and whole frames (compute plus
/// raster time against the frame's wall time). A ratio far below 1 means lost timestamps.
fn timing_check(rows: &[Row]) -> String {
    let sum = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).filter(|v| v.is_finite()).sum::<f64>();
    let compute = sum(&|r| r.passes.iter().filter(|p| p.compute).map(|p| p.ms).sum());
    let (compute_wall, gpu, wall) = (sum(&|r| r.compute_wall_ms), sum(&|r| r.gpu_ms()), sum(&|r| r.wall_ms));
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    let (c, f) = (ratio(compute, compute_wall), ratio(gpu, wall));
    let mut line = format!(
        "timing check (timestamps / wall clock, all settings): compute-only frames {c:.2}, whole frames {f:.2}"
    );
    if [c, f].iter().any(|r| r.is_finite() && !(0.5..=1.5).contains(r)) {
        line.push_str(
            "\nwarning: timestamps and wall clock disagree by more than 1.5x: GPU times may be wrong",
        );
    }
    line
}

fn print_report(args: &Args, ctx: &GpuContext, rows: &[Row], notes: &[String]) {
    println!("pareto: {} at {}x{}, truth: {}", args.scene.display(), args.size.0, args.size.1, args.truth);
    println!("adapter: {}", ctx.adapter_line());
    if ctx.has_timestamps() {
        println!(
            "GPU ms: per frame, the sum of each pass's median over {} frames after {} warm-up frames \
             (compute passes timed alone, see README); wall ms: submit to idle",
            args.frames,
            measure::WARM_UP_FRAMES
        );
        println!("{}", timing_check(rows));
    } else {
        println!("no GPU timestamps on this adapter: times are wall clock (submit to idle)");
    }
    for n in notes {
        println!("{n}");
    }
    let table = |title: &str, ids: Vec<usize>| {
        let mut ids = ids;
        ids.sort_by(|&a, &b| rows[a].time().total_cmp(&rows[b].time()));
        println!("\n{title}");
        println!("| method | knobs | GPU ms | wall ms | FLIP | rel RMSE |");
        println!("|---|---|---|---|---|---|");
        for i in ids {
            let r = &rows[i];
            println!(
                "| {} | {} | {:.2} | {:.2} | {:.4} | {:.4} |",
                r.setting.method,
                r.setting.knobs,
                r.gpu_ms(),
                r.wall_ms,
                r.flip,
                r.rel_rmse
            );
        }
    };
    for m in unique(rows.iter().map(|r| r.setting.method)) {
        let ids = (0..rows.len()).filter(|&i| rows[i].setting.method == m && rows[i].method_front).collect();
        table(&format!("{m} front:"), ids);
    }
    table("overall front:", (0..rows.len()).filter(|&i| rows[i].overall_front).collect());
}
