//! `voltex pareto SCENE`: speed against error. Sweeps each method's quality knobs over the
//! scene's textured objects, measures every setting's GPU time per frame ([`measure`]) and its
//! error against a truth image (mean FLIP, relative RMSE), and writes `pareto.csv` and
//! `pareto.svg` ([`svg`]) with the Pareto fronts ([`front`]) per method and overall.
//!
//! A setting is a method label, a description of its knobs and the [`RenderOptions`] that apply
//! them; a new method adds a function like [`view_slices`] and one line in [`sweep`].

pub mod front;
pub mod measure;
mod report;
pub mod svg;

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::io::atomic;
use crate::render::{Blueprint, MethodKind, RenderOptions};
use crate::scene::{Scene, MAX_PLANES};
use report::Row;

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
    for planes in unique(args.planes.iter().copied()) {
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
    unique(args.steps.iter().copied())
        .into_iter()
        .map(|f| Setting {
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
    let Planned { settings, blueprints, mut notes } = plan(&scene, args)?;
    // Fail on the output folder before any GPU work.
    let out = args.out_dir();
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::file(&out, format!("cannot create the output folder: {e}")))?;
    atomic::check_writable_dir(&out)?;

    let n = settings.len();
    // Phase 1: compute passes alone, each setting on a fresh device where no render pass has run.
    let mut compute: Vec<Option<measure::ComputeOnly>> = Vec::new();
    for (i, (s, bp)) in settings.iter().zip(blueprints).enumerate() {
        eprintln!("[{}/{n}] {} {}: compute passes", i + 1, s.method, s.knobs);
        let timed = GpuContext::new().and_then(|ctx| measure::compute_passes(&ctx, bp, args.frames));
        compute.push(timed.map_err(|e| note(&mut notes, s, &e)).ok());
    }
    // Phase 2: the truth, then whole frames for images and raster passes.
    let ctx = GpuContext::new()?;
    eprintln!("truth: {}", args.truth);
    let truth = measure::image(&ctx, Blueprint::new(&scene, &args.truth.options(args.size))?)?;
    let mut rows = Vec::new();
    for (i, (s, compute)) in settings.into_iter().zip(compute).enumerate() {
        let Some(compute) = compute else { continue };
        eprintln!("[{}/{n}] {} {}: frames", i + 1, s.method, s.knobs);
        let measured = Blueprint::new(&scene, &s.options)
            .and_then(|bp| measure::full_frames(&ctx, bp, args.frames))
            .and_then(|f| Row::new(s.clone(), compute, f, &truth));
        match measured {
            Ok(row) => rows.push(row),
            Err(e) => note(&mut notes, &s, &e),
        }
    }
    if rows.is_empty() {
        return Err(Error::Invalid(format!("nothing was measured: {}", notes.join("; "))));
    }
    report::mark_fronts(&mut rows);

    let csv_path = out.join("pareto.csv");
    let svg_path = out.join("pareto.svg");
    atomic::write_bytes(&csv_path, report::csv(&rows).as_bytes())?;
    let title = format!(
        "{}: time against error ({}x{}, truth: {})",
        args.scene.file_stem().unwrap_or_default().to_string_lossy(),
        args.size.0,
        args.size.1,
        args.truth
    );
    atomic::write_bytes(&svg_path, report::chart(&rows, &title, ctx.has_timestamps()).as_bytes())?;
    crate::io::png::write_tonemapped(&out.join("truth.png"), &truth)?;
    report::print_report(args, &ctx, &rows, &notes);
    println!("wrote {}, {} and truth.png", csv_path.display(), svg_path.display());
    Ok(())
}

/// The settings to measure, each with its blueprint (CPU only: planning fails early), and notes
/// on what cannot be measured. The truth must plan; a setting that does not is skipped.
fn plan(scene: &Scene, args: &Args) -> Result<Planned> {
    Blueprint::new(scene, &args.truth.options(args.size)).map_err(|e| {
        let hint = if args.truth == Truth::Reference { "; try --truth view-slices:4096" } else { "" };
        Error::Invalid(format!("the truth ({}) cannot be rendered: {e}{hint}", args.truth))
    })?;
    let (all, mut notes) = sweep(scene, args)?;
    let (mut settings, mut blueprints) = (Vec::new(), Vec::new());
    for s in all {
        match Blueprint::new(scene, &s.options) {
            Ok(bp) => {
                settings.push(s);
                blueprints.push(bp);
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
    Ok(Planned { settings, blueprints, notes })
}

struct Planned {
    settings: Vec<Setting>,
    blueprints: Vec<Blueprint>,
    notes: Vec<String>,
}

/// Records why a setting was skipped, once per method and message.
fn note(notes: &mut Vec<String>, s: &Setting, e: &Error) {
    let line = format!("{}: not measured: {e}", s.method);
    if !notes.contains(&line) {
        eprintln!("{line} ({})", s.knobs);
        notes.push(line);
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
