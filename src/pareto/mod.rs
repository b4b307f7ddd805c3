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
use crate::methods::sweep::{unique, SweepScene, SweepValues};
use crate::progress::{Progress, Verbosity};
use crate::render::{Blueprint, MethodKind, RenderOptions};
use crate::scene::Scene;
use report::Row;

/// What errors are measured against: a method that can be a truth, with its argument
/// (`reference`, `view-slices:4096`, `ray-march:0.0005:rays`; each method's plug-in says).
#[derive(Debug, Clone, PartialEq)]
pub struct TruthSource {
    kind: MethodKind,
    arg: Option<String>,
    label: String,
}

impl FromStr for TruthSource {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let forms: Vec<&str> = MethodKind::all().filter_map(|k| k.defaults().plugin().truth_form()).collect();
        let (name, arg) = match s.split_once(':') {
            Some((n, a)) => (n, Some(a)),
            None => (s, None),
        };
        let kind = MethodKind::from_cli(name)
            .ok()
            .filter(|k| k.defaults().plugin().truth_form().is_some())
            .ok_or_else(|| format!("`{s}`: expected {}", forms.join(", ")))?;
        let (_, label) = kind.defaults().plugin().truth(arg, (1, 1))?;
        Ok(TruthSource { kind, arg: arg.map(str::to_string), label })
    }
}

impl fmt::Display for TruthSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label)
    }
}

impl TruthSource {
    /// The truth's default: the ground-truth method at its defaults.
    pub(crate) fn ground_truth() -> TruthSource {
        let kind = MethodKind::truth();
        let (_, label) = kind.defaults().plugin().truth(None, (1, 1)).expect("the truth takes no argument");
        TruthSource { kind, arg: None, label }
    }

    fn options(&self, size: (u32, u32)) -> RenderOptions {
        let plugin = self.kind.defaults();
        plugin.plugin().truth(self.arg.as_deref(), size).expect("checked when parsed").0
    }
}

/// Most samples per pixel side of `--supersample` and `--supersample-methods`.
pub(crate) const MAX_SUPERSAMPLE: u32 = 8;

/// The command's arguments.
#[derive(Debug, Clone)]
pub struct Args {
    /// The scene file to sweep.
    pub scene: PathBuf,
    /// Timed frames per setting (after warm-up); medians are reported.
    pub frames: usize,
    /// Output folder (default `out/pareto/<scene stem>`), created if missing.
    pub out: Option<PathBuf>,
    /// What the error is measured against.
    pub truth: TruthSource,
    /// Methods to sweep.
    pub methods: Vec<MethodKind>,
    /// The values swept (the render size among them).
    pub sweep: SweepValues,
    /// CSV files of other renderers' rows (`peers`), shown beside voltex's.
    pub peers: Vec<PathBuf>,
    /// Samples per pixel side of the truth (`--supersample`): each pixel the mean over its area,
    /// the truth of methods that filter by the pixel's footprint.
    pub supersample: u32,
    /// Samples per pixel side of every swept setting (`--supersample-methods`).
    pub supersample_methods: u32,
    /// What it says on stderr while it runs (`--quiet`, `--verbose`); the report goes to stdout.
    pub verbosity: Verbosity,
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
        let v = &self.sweep;
        let max_planes = crate::scene::MAX_PLANES;
        if let Some(&p) = v.planes.iter().find(|&&p| p == 0 || p > max_planes) {
            return Err(Error::Invalid(format!("--planes {p}: expected plane counts in 1..={max_planes}")));
        }
        if let Some(&f) = v.steps.iter().find(|&&f| !(f.is_finite() && f > 0.0)) {
            return Err(Error::Invalid(format!(
                "--steps {f}: expected positive multiples of the default step"
            )));
        }
        if let Some(&s) = v.ray_steps.iter().find(|&&s| !(s.is_finite() && s > 0.0)) {
            return Err(Error::Invalid(format!("--ray-steps {s}: expected positive steps in world units")));
        }
        if let Some(&(s, m)) =
            v.ray_adaptive.iter().find(|&&(s, m)| !(s.is_finite() && s > 0.0 && m.is_finite() && m >= s))
        {
            return Err(Error::Invalid(format!(
                "--ray-adaptive {s}:{m}: expected STEP:MAX_STEP, positive world units with MAX_STEP >= STEP"
            )));
        }
        if let Some(&c) = v.criteria.iter().find(|&&c| !(c > 0.0 && c <= 1024.0)) {
            return Err(Error::Invalid(format!("--criteria {c}: expected values in (0, 1024]")));
        }
        if self.frames == 0 {
            return Err(Error::Invalid("--frames 0: expected at least one timed frame".into()));
        }
        for (flag, n) in
            [("--supersample", self.supersample), ("--supersample-methods", self.supersample_methods)]
        {
            if !(1..=MAX_SUPERSAMPLE).contains(&n) {
                return Err(Error::Invalid(format!(
                    "{flag} {n}: expected 1 to {MAX_SUPERSAMPLE} samples per pixel side"
                )));
            }
        }
        Ok(())
    }

    /// The truth as reports name it: `reference`, `reference, 4x4 samples per pixel`.
    pub(crate) fn truth_label(&self) -> String {
        match self.supersample {
            1 => self.truth.to_string(),
            n => format!("{}, {n}x{n} samples per pixel", self.truth),
        }
    }

    /// The truth's options: its method's, supersampled as asked.
    fn truth_options(&self) -> RenderOptions {
        let n = (self.supersample > 1).then_some(self.supersample);
        RenderOptions { supersample: n, ..self.truth.options(self.sweep.size) }
    }

    pub(crate) fn out_dir(&self) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/pareto").join(self.scene.file_stem().unwrap_or_default()))
    }
}

/// Every setting of the methods asked for (each method's plug-in sweeps its knobs), with notes
/// on what cannot be swept.
pub(crate) fn sweep(scene: &Scene, args: &Args) -> Result<(Vec<Setting>, Vec<String>)> {
    let facts = SweepScene {
        has_hypertextures: !(scene.hypertextures.is_empty() && scene.volumes.is_empty()),
        truth_step: truth_step(scene, args.sweep.size).map_err(|e| e.to_string()),
    };
    let mut settings = Vec::new();
    let mut notes = Vec::new();
    for kind in unique(args.methods.iter().copied()) {
        match kind.defaults().plugin().sweep(&args.sweep, &facts) {
            Ok(points) => settings.extend(points.into_iter().map(|p| Setting {
                method: kind.name(),
                knobs: p.knobs,
                tag: p.tag,
                options: RenderOptions {
                    supersample: (args.supersample_methods > 1).then_some(args.supersample_methods),
                    ..p.options
                },
            })),
            Err(why) => notes.push(format!("{kind}: not measured: {why}")),
        }
    }
    Ok((settings, notes))
}

/// The ground truth's default ray step for the scene: the smallest of its objects' (see
/// `MethodPlan::ray_step`; `None` when no object has one).
pub(crate) fn truth_step(scene: &Scene, size: (u32, u32)) -> Result<Option<f64>> {
    let opts = RenderOptions { size: Some(size), method: Some(MethodKind::truth()), ..Default::default() };
    let bp = Blueprint::new(scene, &opts)?;
    Ok(bp.objects.iter().flat_map(|o| o.methods.iter().filter_map(|m| m.ray_step())).min_by(f64::total_cmp))
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
    if args.verbosity != Verbosity::Quiet {
        eprintln!("truth: {}", args.truth_label());
    }
    let truth = measure::truth_image(&ctx, Blueprint::new(&scene, &args.truth_options())?, args.verbosity)?;
    let mut rows = Vec::new();
    let mut progress = Progress::new(n, args.verbosity);
    // Measured in an order that spreads cheap and costly settings (the ETA is the mean time of
    // those done so far), reported in the sweep's order.
    let order = spread(&settings.iter().map(|s| s.method).collect::<Vec<_>>());
    let mut planned: Vec<Option<(Setting, Blueprint)>> =
        settings.into_iter().zip(blueprints).map(Some).collect();
    for i in order {
        let (s, bp) = planned[i].take().expect("each setting once");
        let label = format!("{} {}", s.method, s.knobs);
        progress.started(&label);
        match measure_setting(&scene, args, &s, bp, &truth) {
            Ok(row) => {
                let keep = args.verbosity == Verbosity::Verbose;
                progress.finished(&label, &format!("{label}: {}", row.summary()), true, keep);
                rows.push((i, row));
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
    rows.sort_by_key(|(i, _)| *i);
    let mut rows: Vec<Row> = rows.into_iter().map(|(_, r)| r).collect();
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
        args.sweep.size.0,
        args.sweep.size.1,
        args.truth_label()
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

/// The order to measure settings in, given each one's method (settings of one method are in
/// the sweep's order, cheapest first): the methods in turn, and within each method its sweep's
/// ends alternately (first, last, second, second last, ...), so that the settings measured first
/// are a fair sample of the costs and an ETA from their mean is not fooled by the cheap ones.
fn spread(methods: &[&str]) -> Vec<usize> {
    let mut groups: Vec<(&str, Vec<usize>)> = Vec::new();
    for (i, m) in methods.iter().enumerate() {
        match groups.iter_mut().find(|(g, _)| g == m) {
            Some((_, v)) => v.push(i),
            None => groups.push((m, vec![i])),
        }
    }
    let zigzag: Vec<Vec<usize>> = groups
        .iter()
        .map(|(_, v)| {
            let (mut lo, mut hi, mut out) = (0, v.len(), Vec::new());
            while lo < hi {
                out.push(v[lo]);
                lo += 1;
                if lo < hi {
                    hi -= 1;
                    out.push(v[hi]);
                }
            }
            out
        })
        .collect();
    let longest = zigzag.iter().map(Vec::len).max().unwrap_or(0);
    (0..longest).flat_map(|k| zigzag.iter().filter_map(move |z| z.get(k).copied())).collect()
}

/// Times one setting and measures its error. On a fresh device, so that no render pass has run
/// on it when its compute passes are timed alone (phase 1); then whole frames (phase 2), right
/// after, so both phases see the same machine load.
fn measure_setting(scene: &Scene, args: &Args, s: &Setting, bp: Blueprint, truth: &Image) -> Result<Row> {
    let ctx = GpuContext::new()?;
    let compute = measure::compute_passes(&ctx, bp, args.frames)?;
    let frames = measure::full_frames(&ctx, Blueprint::new(scene, &s.options)?, args.frames)?;
    let orbit = measure::orbit_ms(&ctx, scene, &s.options, args.frames)?;
    Row::new(s.clone(), compute, frames, orbit, truth)
}

/// The settings to measure, each with its blueprint (CPU only: planning fails early), and notes
/// on what cannot be measured. The truth must plan; a setting that does not is skipped.
fn plan(scene: &Scene, args: &Args) -> Result<Planned> {
    Blueprint::new(scene, &args.truth_options()).map_err(|e| {
        let hint = if args.truth == TruthSource::ground_truth() {
            "; try a converged method as the truth (--truth)"
        } else {
            ""
        };
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
                if let Some(line) = note(&mut notes, &s, &e).filter(|_| args.verbosity != Verbosity::Quiet) {
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

#[cfg(test)]
mod tests {
    #[test]
    fn settings_are_spread_over_methods_and_costs_each_once() {
        let methods = ["view", "view", "view", "view", "axis", "axis", "shell"];
        let order = super::spread(&methods);
        assert_eq!(order, vec![0, 4, 6, 3, 5, 1, 2]);
        let mut sorted = order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..methods.len()).collect::<Vec<_>>());
        assert!(super::spread(&[]).is_empty());
    }
}
