//! `voltex pareto SCENE`: speed against error. Sweeps each method's quality knobs over the
//! scene's textured objects, measures every setting's GPU time per frame (`measure`) and its
//! error against a truth image (mean FLIP, relative RMSE), and writes `pareto.csv` and
//! `pareto.svg` (`svg`) with the Pareto fronts (`front`) per method and overall.
//!
//! A setting is a method label, a description of its knobs and the [`RenderOptions`] that apply
//! them; a new method adds a function like `view_slices` and one line in `sweep`.

pub(crate) mod front;
pub(crate) mod measure;
pub(crate) mod peers;
mod report;
pub(crate) mod svg;

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::io::{atomic, Image};
use crate::methods::options::shadows_name;
use crate::methods::reference::ReferencePlan;
use crate::methods::volume::VolumePlan;
use crate::progress::{Progress, Verbosity};
use crate::render::{Blueprint, MethodKind, RenderOptions};
use crate::scene::{Scene, Segments, Shadows, MAX_PLANES};
use report::Row;

/// Default plane counts of the `ViewSlices` sweep.
pub const SWEEP_PLANES: [u32; 8] = [16, 32, 64, 128, 256, 512, 1024, 2048];
/// Default ray steps of the `Reference` sweep, as multiples of its default step.
/// (2x, half the truth's cost, would double the sweep's time; pass it with `--steps` if wanted.)
pub const DEFAULT_STEP_FACTORS: [f64; 4] = [4.0, 8.0, 16.0, 32.0];
/// Default `AxisSlices` criteria swept: `d = p` = each value (smaller: more slices).
pub const DEFAULT_CRITERIA: [f64; 6] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0];
/// Default `RayMarch` steps swept (world units): the paper's HQ (0.002) and IE (0.015) among them.
pub const DEFAULT_RAY_STEPS: [f64; 5] = [0.002, 0.004, 0.008, 0.015, 0.03];

/// A method whose knobs the sweep varies: the three texel methods switch every textured object
/// to themselves; `RayMarch` varies the step of every hypertexture object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sweep {
    /// One of the texel methods (`ViewSlices`, `AxisSlices`, `Reference`).
    Method(MethodKind),
    /// The RayMarch step of every hypertexture object.
    RayMarch,
}

/// What errors are measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TruthSource {
    /// Every textured object ray cast by `Reference` with its default step.
    Reference,
    /// Every textured object sliced by `ViewSlices` with this many planes (a converged slicing).
    ViewSlices(u32),
    /// Every hypertexture ray-marched (and every textured object ray cast by `Reference`) with
    /// this step in world units: a converged march; with `Some(shadows)` every hypertexture
    /// shaded with them (`ray-march:STEP:rays`: shadow rays).
    RayMarch(f64, Option<Option<Shadows>>),
}

impl FromStr for TruthSource {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        const EXPECTED: &str =
            "expected `reference`, `view-slices:PLANES` or `ray-march:STEP[:SHADOWS]`, e.g. \
             view-slices:4096, ray-march:0.0005 or ray-march:0.0005:rays";
        if s == "reference" {
            return Ok(TruthSource::Reference);
        }
        if let Some(rest) = s.strip_prefix("ray-march:") {
            let (step, shadows) = match rest.split_once(':') {
                Some((step, shadows)) => (step, Some(crate::methods::options::parse_shadows(shadows)?)),
                None => (rest, None),
            };
            return match step.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(TruthSource::RayMarch(v, shadows)),
                _ => Err(format!("`{step}`: expected a positive step in world units")),
            };
        }
        let n = s.strip_prefix("view-slices:").ok_or(EXPECTED)?;
        match n.parse::<u32>() {
            Ok(n) if (1..=MAX_PLANES).contains(&n) => Ok(TruthSource::ViewSlices(n)),
            _ => Err(format!("`{n}`: expected a plane count in 1..={MAX_PLANES}")),
        }
    }
}

impl fmt::Display for TruthSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TruthSource::Reference => write!(f, "Reference, default step"),
            TruthSource::ViewSlices(n) => write!(f, "ViewSlices, {n} planes"),
            TruthSource::RayMarch(step, None) => write!(f, "RayMarch, step {step}"),
            TruthSource::RayMarch(step, Some(s)) => {
                write!(f, "RayMarch, step {step}, shadows {}", shadows_name(*s))
            }
        }
    }
}

impl TruthSource {
    fn options(self, size: (u32, u32)) -> RenderOptions {
        let size = Some(size);
        match self {
            TruthSource::Reference => {
                RenderOptions { size, method: Some(MethodKind::Reference), ..Default::default() }
            }
            TruthSource::ViewSlices(n) => RenderOptions {
                size,
                method: Some(MethodKind::ViewSlices),
                planes: Some(n),
                trivial_reject: Some(true),
                lod: Some(crate::scene::Lod::Off),
                ..Default::default()
            },
            TruthSource::RayMarch(step, shadows) => RenderOptions {
                size,
                method: Some(MethodKind::Reference),
                step: Some(step),
                shadows,
                ..Default::default()
            },
        }
    }
}

/// The command's arguments.
#[derive(Debug, Clone)]
pub struct Args {
    /// The scene file to sweep.
    pub scene: PathBuf,
    /// Render size in pixels (width, height).
    pub size: (u32, u32),
    /// Timed frames per setting (after warm-up); medians are reported.
    pub frames: usize,
    /// Output folder (default `out/pareto/<scene stem>`), created if missing.
    pub out: Option<PathBuf>,
    /// What the error is measured against.
    pub truth: TruthSource,
    /// Methods to sweep.
    pub methods: Vec<Sweep>,
    /// `ViewSlices` plane counts (each with the trivial reject on and off).
    pub planes: Vec<u32>,
    /// `ViewSlices` with `lod: Auto` too, each plane count its most planes (trivial reject on).
    pub lod: bool,
    /// `Reference` steps as multiples of the default step.
    pub steps: Vec<f64>,
    /// `AxisSlices` criteria, `d = p` (voxels and pixels).
    pub criteria: Vec<f64>,
    /// `RayMarch` steps (world units).
    pub ray_steps: Vec<f64>,
    /// `RayMarch` segment strategies, each swept over every step.
    pub ray_segments: Vec<Segments>,
    /// `RayMarch` with an adaptive stride: `(step, max_step)` pairs (world units).
    pub ray_adaptive: Vec<(f64, f64)>,
    /// `RayMarch` shadows, each swept over every step (`None`: Phong without shadows); empty:
    /// each object's own.
    pub ray_shadows: Vec<Option<Shadows>>,
    /// CSV files of other renderers' rows (`peers`), shown beside voltex's.
    pub peers: Vec<PathBuf>,
}

/// One point of the sweep.
#[derive(Debug, Clone)]
pub(crate) struct Setting {
    pub(crate) method: &'static str,
    /// The knobs, e.g. `planes=64 reject=on` (no commas: it is a CSV field).
    pub(crate) knobs: String,
    /// A short name for the chart, e.g. `64` (`64 no-reject` with the trivial reject off).
    pub(crate) tag: String,
    pub(crate) options: RenderOptions,
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
        if let Some(&s) = self.ray_steps.iter().find(|&&s| !(s.is_finite() && s > 0.0)) {
            return Err(Error::Invalid(format!("--ray-steps {s}: expected positive steps in world units")));
        }
        if let Some(&(s, m)) =
            self.ray_adaptive.iter().find(|&&(s, m)| !(s.is_finite() && s > 0.0 && m.is_finite() && m >= s))
        {
            return Err(Error::Invalid(format!(
                "--ray-adaptive {s}:{m}: expected STEP:MAX_STEP, positive world units with MAX_STEP >= STEP"
            )));
        }
        if let Some(&c) = self.criteria.iter().find(|&&c| !(c > 0.0 && c <= 1024.0)) {
            return Err(Error::Invalid(format!("--criteria {c}: expected values in (0, 1024]")));
        }
        if self.frames == 0 {
            return Err(Error::Invalid("--frames 0: expected at least one timed frame".into()));
        }
        Ok(())
    }

    pub(crate) fn out_dir(&self) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/pareto").join(self.scene.file_stem().unwrap_or_default()))
    }
}

/// `ViewSlices`: each plane count with the trivial reject on and off (a speed knob only), at
/// full detail; with `lod`, also `lod: Auto` under each count.
pub(crate) fn view_slices(args: &Args) -> Vec<Setting> {
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
                    lod: Some(crate::scene::Lod::Off),
                    ..Default::default()
                },
            });
        }
        if args.lod {
            v.push(Setting {
                method: "ViewSlices",
                knobs: format!("planes={planes} reject=on lod=auto"),
                tag: format!("{planes} lod"),
                options: RenderOptions {
                    size: Some(args.size),
                    method: Some(MethodKind::ViewSlices),
                    planes: Some(planes),
                    trivial_reject: Some(true),
                    lod: Some(crate::scene::Lod::Auto),
                    ..Default::default()
                },
            });
        }
    }
    v
}

/// `AxisSlices`: both criteria `d` (voxels) and `p` (pixels) set to each value; each object keeps
/// its other knobs (directions, blend, culling), or the defaults when it used another method.
pub(crate) fn axis_slices(args: &Args) -> Vec<Setting> {
    let mut criteria = args.criteria.clone();
    criteria.sort_by(f64::total_cmp);
    criteria.dedup();
    criteria
        .into_iter()
        .map(|c| Setting {
            method: "AxisSlices",
            knobs: format!("d=p={c}"),
            tag: format!("{c}"),
            options: RenderOptions {
                size: Some(args.size),
                method: Some(MethodKind::AxisSlices),
                axis_criteria: Some((c, c)),
                ..Default::default()
            },
        })
        .collect()
}

/// `Reference`: the ray step as multiples of `default_step` (one step for all objects).
pub(crate) fn reference(args: &Args, default_step: f64) -> Vec<Setting> {
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

/// `RayMarch`: every hypertexture object marched with each segment strategy and each shadow
/// option, at each fixed step and then with each adaptive stride (textured objects keep their
/// methods).
pub(crate) fn ray_march(args: &Args) -> Vec<Setting> {
    let mut steps = unique(args.ray_steps.iter().copied());
    steps.sort_by(f64::total_cmp);
    let mut pairs = args.ray_adaptive.clone();
    pairs.dedup();
    // No shadow options: each object's own shading.
    let shadows: Vec<Option<Option<Shadows>>> = if args.ray_shadows.is_empty() {
        vec![None]
    } else {
        unique(args.ray_shadows.iter().copied()).into_iter().map(Some).collect()
    };
    let mut v = Vec::new();
    for (segments, shadows) in unique(args.ray_segments.iter().copied())
        .into_iter()
        .flat_map(|g| shadows.iter().map(move |s| (g, *s)))
    {
        let (name, short) = match segments {
            Segments::Bounds => ("Bounds".to_string(), ""),
            Segments::DepthPeeling { passes, .. } => (format!("DepthPeeling({passes})"), " peel"),
            Segments::Splatting { slabs, .. } => (format!("Splatting({slabs})"), " splat"),
        };
        let fixed = steps.iter().map(|&step| (step, None));
        let adaptive = pairs.iter().map(|&(step, max_step)| (step, Some(max_step)));
        for (step, max_step) in fixed.chain(adaptive) {
            let (knob, tag) = match max_step {
                None => (String::new(), String::new()),
                Some(m) => (format!(" max_step={m}"), format!("<{m}")),
            };
            let (shadow_knob, shadow_tag) = match shadows {
                None => (String::new(), String::new()),
                Some(s) => (format!(" shadows={}", shadows_name(s)), format!(" {}", shadows_name(s))),
            };
            v.push(Setting {
                method: "RayMarch",
                knobs: format!("step={step}{knob} segments={name}{shadow_knob}"),
                tag: format!("{step}{tag}{short}{shadow_tag}"),
                options: RenderOptions {
                    size: Some(args.size),
                    step: Some(step),
                    max_step: Some(max_step),
                    segments: Some(segments),
                    shadows,
                    ..Default::default()
                },
            });
        }
    }
    v
}

/// Every setting of the methods asked for, with notes on what cannot be swept.
pub(crate) fn sweep(scene: &Scene, args: &Args) -> Result<(Vec<Setting>, Vec<String>)> {
    let mut settings = Vec::new();
    let mut notes = Vec::new();
    for &m in &args.methods {
        match m {
            Sweep::Method(MethodKind::ViewSlices) => settings.extend(view_slices(args)),
            Sweep::Method(MethodKind::Reference) => match reference_default_step(scene, args.size) {
                Ok(Some(step)) => settings.extend(reference(args, step)),
                Ok(None) => notes.push("Reference: not measured: no textured object".into()),
                Err(e) => notes.push(format!("Reference: not measured: {e}")),
            },
            Sweep::Method(MethodKind::AxisSlices) => settings.extend(axis_slices(args)),
            Sweep::RayMarch if scene.hypertextures.is_empty() && scene.volumes.is_empty() => {
                notes.push("RayMarch: not measured: no hypertexture and no volume".into())
            }
            Sweep::RayMarch => settings.extend(ray_march(args)),
        }
    }
    Ok((settings, notes))
}

/// The `Reference` method's default step for the scene: the smallest of its textured objects'
/// default steps (half the smallest voxel extent, see `methods::reference::default_step`) and
/// its volume objects' (a quarter voxel; the exact cells need no step, their shadow rays do).
pub(crate) fn reference_default_step(scene: &Scene, size: (u32, u32)) -> Result<Option<f64>> {
    let opts = RenderOptions { size: Some(size), method: Some(MethodKind::Reference), ..Default::default() };
    let bp = Blueprint::new(scene, &opts)?;
    let textured = bp.objects.iter().filter_map(|o| Some(o.method::<ReferencePlan>()?.step));
    let volumes =
        bp.objects.iter().filter_map(|o| o.method::<VolumePlan>().filter(|p| p.exact).map(|p| p.step));
    Ok(textured.chain(volumes).min_by(f64::total_cmp))
}

/// Runs `voltex pareto`: renders each setting of the swept methods, times it, measures its
/// error against the truth, and writes `pareto.csv` and `pareto.svg` with the Pareto fronts.
pub fn run(args: &Args) -> Result<()> {
    args.check()?;
    let scene = crate::scene::load(&args.scene)?;
    let peer_rows = args.peers.iter().map(|p| peers::read(p)).collect::<Result<Vec<_>>>()?.concat();
    let Planned { settings, blueprints, mut notes } = plan(&scene, args)?;
    // Fail on the output folder before any GPU work.
    let out = args.out_dir();
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::file(&out, format!("cannot create the output folder: {e}")))?;
    atomic::check_writable_dir(&out)?;

    let n = settings.len();
    let load = report::load_average();
    let ctx = GpuContext::new()?;
    eprintln!("truth: {}", args.truth);
    let truth = measure::image(&ctx, Blueprint::new(&scene, &args.truth.options(args.size))?)?;
    let mut rows = Vec::new();
    let mut progress = Progress::new(n, Verbosity::Normal);
    for (s, bp) in settings.into_iter().zip(blueprints) {
        let label = format!("{} {}", s.method, s.knobs);
        progress.started(&label);
        match measure_setting(&scene, args, &s, bp, &truth) {
            Ok(row) => {
                progress.finished(&label, &format!("{label}: {}", row.summary()), true, false);
                rows.push(row);
            }
            Err(e) => {
                progress.finished(&label, &format!("{label}: not measured"), true, true);
                if let Some(line) = note(&mut notes, &s, &e) {
                    progress.note(&line);
                }
            }
        }
    }
    progress.end();
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
    atomic::write_bytes(
        &svg_path,
        report::chart(&rows, &peer_rows, &title, ctx.has_timestamps()).as_bytes(),
    )?;
    crate::io::png::write_tonemapped(&out.join("truth.png"), &truth)?;
    report::print_report(args, &ctx, &rows, &peer_rows, &notes, load);
    println!("wrote {}, {} and truth.png", csv_path.display(), svg_path.display());
    Ok(())
}

/// Times one setting and measures its error. On a fresh device, so that no render pass has run
/// on it when its compute passes are timed alone (phase 1); then whole frames (phase 2), right
/// after, so both phases see the same machine load.
fn measure_setting(scene: &Scene, args: &Args, s: &Setting, bp: Blueprint, truth: &Image) -> Result<Row> {
    let ctx = GpuContext::new()?;
    let compute = measure::compute_passes(&ctx, bp, args.frames)?;
    let frames = measure::full_frames(&ctx, Blueprint::new(scene, &s.options)?, args.frames)?;
    Row::new(s.clone(), compute, frames, truth)
}

/// The settings to measure, each with its blueprint (CPU only: planning fails early), and notes
/// on what cannot be measured. The truth must plan; a setting that does not is skipped.
fn plan(scene: &Scene, args: &Args) -> Result<Planned> {
    Blueprint::new(scene, &args.truth.options(args.size)).map_err(|e| {
        let hint = if args.truth == TruthSource::Reference { "; try --truth view-slices:4096" } else { "" };
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
            Err(e) => {
                if let Some(line) = note(&mut notes, &s, &e) {
                    eprintln!("{line}");
                }
            }
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

/// Records why a setting was skipped, once per method and message; returns the line to show
/// when it is new.
fn note(notes: &mut Vec<String>, s: &Setting, e: &Error) -> Option<String> {
    let line = format!("{}: not measured: {e}", s.method);
    if notes.contains(&line) {
        return None;
    }
    notes.push(line.clone());
    Some(format!("{line} ({})", s.knobs))
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
