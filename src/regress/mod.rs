//! `voltex regress DIR`: renders every scene under a folder headless, compares each with the
//! reference image beside it (`<stem>.ref.exr`: mean FLIP of the tonemapped images and relative
//! RMSE of the linear HDR values, thresholds from the scene's `regress` field), and writes per
//! scene `actual.exr`, `actual.png`, `reference.png`, `diff.png` (FLIP heat map) and a
//! `result.json` record into `OUT/<scene path without .ron>/`, then `OUT/index.html` from every
//! record under `OUT` (so shards and copied folders merge into one report).
//!
//! Statuses: pass, regressed, new (no reference), broken scene (it fails to load, plan or render),
//! broken reference (unreadable, other size). Every scene is checked before the exit status says
//! whether all passed. References are written only with `--update`, and only for new, regressed
//! and other-size ones.
//!
//! `--jobs N` runs N scenes on threads sharing one [`GpuContext`]. wgpu errors raised outside an
//! error scope are collected per device, so with N > 1 such an error may be reported on the
//! scene that happened to look next; rerun the scene alone to be sure which one raised it.
//!
//! GPU faults: an out-of-memory error is the scene's problem (a broken scene) and the run goes
//! on. A lost device makes the scenes that were on it broken scenes ("GPU device lost"); a new
//! device is opened for the scenes not yet started, and if none can be opened the run stops with
//! an error after writing the records and the report of what was checked.

mod check;
mod discover;
pub(crate) mod junit;
pub(crate) mod merge;
mod progress;
pub mod record;
pub(crate) mod report;
pub mod shards;

pub use discover::{find, SceneEntry, Shard};
pub(crate) use merge::Problem;
pub use record::{Record, Status};

use std::collections::BTreeSet;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, RwLock};

use crate::gpu::GpuContext;
use crate::io::atomic::check_writable_dir;
use crate::progress::{Progress, Verbosity};
use crate::{Error, Result};

/// The `regress` command line.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Folder searched recursively for scene files (`*.ron` except render graphs), or one scene.
    #[arg(required_unless_present = "report_only")]
    pub(crate) dir: Option<PathBuf>,
    /// Output folder: a subfolder per scene and index.html.
    #[arg(short = 'o', long, visible_alias = "output", default_value = "out/regress")]
    pub out: PathBuf,
    /// Write `<stem>.ref.exr` for scenes that are new, regressed or whose reference has another
    /// size (passing ones are left untouched). Without it no reference is ever written.
    #[arg(long)]
    pub(crate) update: bool,
    /// Render size WIDTHxHEIGHT for every scene (default: the scene's regress.size, else its output).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Scenes rendered concurrently (threads sharing one GPU device).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub(crate) jobs: u32,
    /// Check only shard i of n (1-based), as planned from the scenes' costs (OUT/.voltex/plan-N.json,
    /// shared by the shards of one output folder). `auto/n` takes i from SLURM_ARRAY_TASK_ID or
    /// JOB_COMPLETION_INDEX.
    #[arg(long, default_value = "1/1")]
    pub(crate) shard: Shard,
    /// Mean FLIP a scene may reach, for every scene (default: each scene's regress.max_flip).
    #[arg(long, value_parser = parse_max_flip)]
    pub(crate) max_flip: Option<f64>,
    /// Relative RMSE a scene may reach, for every scene (default: each scene's regress.max_rel_rmse).
    #[arg(long, value_parser = parse_max_rel_rmse)]
    pub(crate) max_rel_rmse: Option<f64>,
    /// Skip the truth renders (`regress.truth`): check only "unchanged against the reference".
    /// Faster (a truth render costs a Reference or fine-step render); refused with `--update`,
    /// which must never accept a reference beyond its truth bound.
    #[arg(long, conflicts_with = "update")]
    pub(crate) no_truth: bool,
    /// Render scenes whose record is current too (same scene, assets, reference, size, graphs,
    /// WGSL and binary); without it they are kept and not rendered again.
    #[arg(long)]
    pub(crate) force: bool,
    /// Write the JUnit XML report to FILE (default: OUT/junit.xml, beside index.html).
    #[arg(long, value_name = "FILE")]
    pub(crate) junit: Option<PathBuf>,
    /// Render nothing: print how N shards would split DIR (costs from the records under --out,
    /// else estimates) and the predicted makespan.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000),
          conflicts_with_all = ["update", "jobs", "shard", "force", "junit", "json"])]
    pub(crate) plan_shards: Option<u32>,
    /// Print a JSON summary on stdout (verdict, exit status, counts, failures, merge problems,
    /// report paths) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// No progress on stderr (errors still).
    #[arg(short, long, conflicts_with = "verbose")]
    pub(crate) quiet: bool,
    /// Each scene's warnings in the progress too.
    #[arg(short, long)]
    pub(crate) verbose: bool,
    /// Render nothing: rebuild OUT/index.html from the records under OUT (after merging shards).
    #[arg(long, value_name = "OUT", conflicts_with_all = ["dir", "out", "update", "size", "jobs", "shard", "force", "max_flip", "max_rel_rmse", "no_truth"])]
    pub(crate) report_only: Option<PathBuf>,
}

/// Exit statuses of `voltex regress` and `voltex farm`, by cause (other commands exit 1 on any
/// error). The worst cause wins: broken input over regressions.
pub mod exit {
    use crate::Error;

    /// Every scene passed.
    pub const PASS: u8 = 0;
    /// A scene regressed, or is new without `--update`.
    pub(crate) const REGRESSIONS: u8 = 1;
    /// A bad command line (clap's status).
    pub const USAGE: u8 = 2;
    /// Broken input: a broken scene or reference, an unreadable record, a merge that found
    /// problems, a missing or unwritable folder.
    pub(crate) const BROKEN_INPUT: u8 = 3;
    /// The engine failed: no GPU device could be opened (or reopened after a loss), or the farm's
    /// engine is missing, refused the jobs or lost them.
    pub const ENGINE: u8 = 4;

    /// The status of a run that stopped with `e`.
    pub fn of_error(e: &Error) -> u8 {
        match e {
            Error::Gpu(_) | Error::DeviceLost(_) => ENGINE,
            _ => BROKEN_INPUT,
        }
    }
}

/// What every scene check of one run shares.
pub(crate) struct RunInfo<'a> {
    pub(crate) args: &'a Args,
    pub(crate) shard: Shard,
    pub(crate) suite: String,
    pub(crate) toolchain: String,
    pub(crate) host: String,
}

/// Parses `--max-flip`: a mean FLIP in [0, 1].
pub fn parse_max_flip(s: &str) -> std::result::Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| (0.0..=1.0).contains(v))
        .ok_or_else(|| format!("`{s}`: expected a mean FLIP in [0, 1]"))
}

/// Parses `--max-rel-rmse`: a relative RMSE >= 0.
pub fn parse_max_rel_rmse(s: &str) -> std::result::Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| format!("`{s}`: expected a relative RMSE >= 0"))
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("`{s}`: expected WIDTHxHEIGHT between 1x1 and 16384x16384, e.g. 128x128");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// What a run or `--report-only` did.
pub struct Outcome {
    /// Scenes checked by this run, in the sorted order (all records for `--report-only`).
    pub(crate) records: Vec<Record>,
    /// Records under the output folder that could not be read.
    pub(crate) unreadable: Vec<Error>,
    /// What the merged output folder must not hide (different suites, duplicates, lost shards).
    /// They fail `--report-only` (the merge); a run only reports them, since while shards run the
    /// others' results are not there yet.
    pub(crate) problems: Vec<Problem>,
    pub(crate) merged: bool,
    /// Scenes of this run whose record was current, so they were not rendered again.
    pub(crate) skipped: usize,
    pub(crate) report: PathBuf,
    pub(crate) junit: PathBuf,
}

impl Outcome {
    /// The exit status: [`exit::BROKEN_INPUT`] if a scene or reference is broken, a record
    /// unreadable or (for a merge) the merge found problems, else [`exit::REGRESSIONS`] if a scene
    /// failed, else [`exit::PASS`].
    pub(crate) fn exit_code(&self) -> u8 {
        let broken = self
            .records
            .iter()
            .any(|r| r.failed() && matches!(r.status, Status::BrokenScene | Status::BrokenReference));
        if broken || !self.unreadable.is_empty() || (self.merged && !self.problems.is_empty()) {
            exit::BROKEN_INPUT
        } else if self.failures() > 0 {
            exit::REGRESSIONS
        } else {
            exit::PASS
        }
    }

    /// Scenes that did not pass (and were not updated), plus unreadable records, and for a merge
    /// its problems.
    pub(crate) fn failures(&self) -> usize {
        self.records.iter().filter(|r| r.failed()).count()
            + self.unreadable.len()
            + if self.merged { self.problems.len() } else { 0 }
    }
}

/// Runs `voltex regress` as the command line asked: prints the summary and the report's path, and
/// returns the exit status ([`exit`]); says on stderr why it is not 0.
pub fn command(args: &Args) -> Result<u8> {
    if let Some(n) = args.plan_shards {
        print!("{}", plan_shards(args, n as usize)?);
        return Ok(exit::PASS);
    }
    let outcome = match &args.report_only {
        Some(out) => report_only(out, args.junit.as_deref())?,
        None => run(args)?,
    };
    if args.json {
        println!("{}", summary_json(&outcome));
    } else {
        print!("{}", report::summary_table(&outcome.records));
        for e in &outcome.unreadable {
            println!("unreadable record: {e}");
        }
        for p in &outcome.problems {
            println!("{}: {p}", if outcome.merged { "merge" } else { "note" });
        }
        if outcome.skipped > 0 {
            println!("{} scene(s) current, not rendered again (--force renders them)", outcome.skipped);
        }
        println!("report: {}", outcome.report.display());
    }
    match outcome.failures() {
        0 => Ok(exit::PASS),
        n => {
            let problems = if outcome.merged { outcome.problems.len() } else { 0 };
            let scenes = outcome.records.len() + outcome.unreadable.len();
            let mut text = format!(
                "{} of {scenes} scene{} did not pass",
                n - problems,
                if scenes == 1 { "" } else { "s" }
            );
            if problems > 0 {
                text += &format!(" and the merge found {problems} problem(s)");
            }
            eprintln!("error: {text} (see {})", outcome.report.display());
            Ok(outcome.exit_code())
        }
    }
}

/// The `--json` summary of a run or merge.
pub(crate) fn summary_json(o: &Outcome) -> String {
    let code = o.exit_code();
    let count = |st: Status| o.records.iter().filter(|r| r.status == st).count();
    let failed: Vec<serde_json::Value> = o
        .records
        .iter()
        .filter(|r| r.failed())
        .map(|r| serde_json::json!({"scene": r.scene, "status": r.status, "message": r.message}))
        .collect();
    serde_json::json!({
        "verdict": match code { exit::PASS => "pass", exit::REGRESSIONS => "regressions", _ => "broken input" },
        "exit_code": code,
        "scenes": o.records.len(),
        "counts": {
            "pass": count(Status::Pass),
            "regressed": count(Status::Regressed),
            "new": count(Status::New),
            "broken_scene": count(Status::BrokenScene),
            "broken_reference": count(Status::BrokenReference),
            "updated": o.records.iter().filter(|r| r.updated).count(),
            "current_not_rendered": o.skipped,
        },
        "failed": failed,
        "unreadable": o.unreadable.iter().map(|e| e.to_string()).collect::<Vec<_>>(),
        "merge_problems": o.problems,
        "merge_problems_fail": o.merged,
        "report": o.report,
        "junit": o.junit,
    })
    .to_string()
}

/// `--plan-shards N`: the plan of DIR's scenes on N shards from the costs under `--out`, as text.
pub(crate) fn plan_shards(args: &Args, n: usize) -> Result<String> {
    let dir = args.dir.as_deref().ok_or_else(|| Error::Invalid("regress: no scene folder given".into()))?;
    let all = find(dir)?;
    if all.is_empty() {
        return Err(Error::file(dir, "no scene files (*.ron) in this folder"));
    }
    let plan = shards::fresh_plan(&args.out, &all, n, args.size);
    let mut s = String::from("shard  cost ms  source    scene\n");
    let mut rows: Vec<&shards::Planned> = plan.scenes.iter().collect();
    rows.sort_by(|a, b| a.shard.cmp(&b.shard).then(b.cost.ms.total_cmp(&a.cost.ms)));
    for p in rows {
        let source = if p.cost.measured { "measured" } else { "estimate" };
        s += &format!("{:>5}  {:>7.0}  {source:<8}  {}\n", p.shard, p.cost.ms, p.scene);
    }
    Ok(s + &plan.table())
}

/// Checks the scenes of `args.dir` (this shard's share) and rewrites the report.
pub(crate) fn run(args: &Args) -> Result<Outcome> {
    let dir = args.dir.as_deref().ok_or_else(|| Error::Invalid("regress: no scene folder given".into()))?;
    let all = find(dir)?;
    if all.is_empty() {
        return Err(Error::file(dir, "no scene files (*.ron) in this folder"));
    }
    // Everything that will be written must be writable before any rendering.
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::file(&args.out, format!("cannot create the output folder: {e}")))?;
    check_writable_dir(&args.out)?;
    let shard = args.shard;
    let suite = shards::suite_id(&all);
    let scenes = match shard.count {
        1 => all,
        n => shards::plan_for(&args.out, &all, n, args.size)?.take(shard, all),
    };
    if args.update {
        let folders: BTreeSet<PathBuf> = scenes.iter().map(|s| parent(&s.reference)).collect();
        folders.iter().try_for_each(|d| check_writable_dir(d))?;
    }
    // Thresholds given on the command line change verdicts as much as the binary does.
    let toolchain = format!(
        "{}/{:?}/{:?}/{}",
        shards::toolchain_hash()?,
        args.max_flip,
        args.max_rel_rmse,
        args.no_truth
    );
    let info = RunInfo { args, shard, suite, toolchain, host: shards::host() };
    if let Some(other) = shards::running_elsewhere(&args.out, shard) {
        return Err(Error::file(
            &args.out,
            format!(
                "shard {shard} is already running into this folder ({other}); two runs of one shard would \
                 overwrite each other's results: wait for it, or stop it"
            ),
        ));
    }
    let mut manifest = shards::Manifest {
        suite: info.suite.clone(),
        shard: shard.to_string(),
        scenes: scenes.iter().map(|s| s.rel.clone()).collect(),
        host: info.host.clone(),
        pid: std::process::id(),
        started_unix: shards::unix_now(),
        finished_unix: None,
    };
    manifest.write(&args.out, shard)?;
    let junit = args.junit.clone().unwrap_or_else(|| args.out.join(junit::JUNIT_FILE));
    let (records, skipped) = if scenes.is_empty() {
        eprintln!("shard {shard}: no scenes");
        (Vec::new(), 0)
    } else {
        match run_scenes(GpuContext::new()?, &info, &scenes) {
            Ok(done) => done,
            Err(e) => {
                // The report of what was checked before the run stopped, if it can be written.
                let _ = write_reports(&args.out, &junit);
                return Err(e);
            }
        }
    };
    manifest.finished_unix = Some(shards::unix_now());
    manifest.write(&args.out, shard)?;
    let Merged { unreadable, problems, report, .. } = write_reports(&args.out, &junit)?;
    Ok(Outcome { records, unreadable, problems, merged: false, skipped, report, junit })
}

/// What [`write_reports`] found under an output folder.
struct Merged {
    found: Vec<record::Found>,
    unreadable: Vec<Error>,
    problems: Vec<Problem>,
    report: PathBuf,
}

/// The records under `out`, checked as a merge, and `index.html` and the JUnit file from them.
fn write_reports(out: &Path, junit: &Path) -> Result<Merged> {
    let (found, unreadable) = record::collect(out)?;
    let problems = merge::check(out, &found)?;
    let report = report::write_index(out, &found, &unreadable, &problems)?;
    junit::write(junit, &found, &unreadable, &problems)?;
    Ok(Merged { found, unreadable, problems, report })
}

/// Rebuilds `out/index.html` (and the JUnit file) from the records under `out`.
pub(crate) fn report_only(out: &Path, junit: Option<&Path>) -> Result<Outcome> {
    check_writable_dir(out)?;
    let junit = junit.map(Path::to_path_buf).unwrap_or_else(|| out.join(junit::JUNIT_FILE));
    let (found, unreadable) = record::collect(out)?;
    if found.is_empty() && unreadable.is_empty() {
        return Err(Error::file(out, "no regress records (result.json) in this folder"));
    }
    let Merged { found, unreadable, problems, report } = write_reports(out, &junit)?;
    let mut records: Vec<Record> = found.into_iter().map(|f| f.record).collect();
    records.sort_by(|a, b| a.scene.cmp(&b.scene));
    Ok(Outcome { records, unreadable, problems, merged: true, skipped: 0, report, junit })
}

fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

enum Event {
    Started(usize),
    Done(usize, Box<Result<check::Checked>>),
}

/// The device the workers share; replaced by a new one when it is lost.
struct SharedContext(RwLock<Arc<GpuContext>>);

impl SharedContext {
    fn current(&self) -> Arc<GpuContext> {
        self.0.read().unwrap().clone()
    }

    /// After `used` was lost: a new device, opened once however many workers saw the loss.
    fn replace(&self, used: &Arc<GpuContext>) -> Result<()> {
        let mut current = self.0.write().unwrap();
        if Arc::ptr_eq(&current, used) {
            *current = Arc::new(GpuContext::new().map_err(|e| {
                Error::DeviceLost(format!(
                    "{}; opening a new device failed: {e}",
                    used.lost().unwrap_or_default()
                ))
            })?);
        }
        Ok(())
    }
}

/// Checks `scenes` on `args.jobs` threads sharing `ctx`. A failure to write into the output folder
/// (or a reference), or to open a new device after one was lost, stops handing out scenes and is
/// returned once the running ones finish.
fn run_scenes(ctx: GpuContext, info: &RunInfo, scenes: &[SceneEntry]) -> Result<(Vec<Record>, usize)> {
    let args = info.args;
    let shared = SharedContext(RwLock::new(Arc::new(ctx)));
    let verbosity = Verbosity::from_flags(args.quiet, args.verbose);
    let mut progress = Progress::new(scenes.len(), verbosity);
    let (next, stop) = (AtomicUsize::new(0), AtomicBool::new(false));
    let mut records: Vec<Option<Record>> = vec![None; scenes.len()];
    let mut skipped = 0;
    let mut first_error = None;
    std::thread::scope(|s| {
        let (tx, rx) = mpsc::channel();
        for _ in 0..(args.jobs as usize).min(scenes.len()) {
            let (tx, next, stop, shared) = (tx.clone(), &next, &stop, &shared);
            s.spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(entry) = scenes.get(i) else { break };
                    let _ = tx.send(Event::Started(i));
                    let ctx = shared.current();
                    let mut result = catch_unwind(AssertUnwindSafe(|| check::check(&ctx, info, entry)))
                        .unwrap_or_else(|p| {
                            Err(Error::Invalid(format!("{}: {}", entry.rel, panic_text(&p))))
                        });
                    if ctx.lost().is_some() {
                        if let Err(e) = shared.replace(&ctx) {
                            // No device to go on with: hand out no more scenes.
                            stop.store(true, Ordering::Relaxed);
                            result = result.and(Err(e));
                        }
                    }
                    let _ = tx.send(Event::Done(i, Box::new(result)));
                }
            });
        }
        drop(tx);
        for event in rx {
            match event {
                Event::Started(i) => progress.started(&scenes[i].rel),
                Event::Done(i, result) => match *result {
                    Ok(checked) => {
                        progress::finished(&mut progress, &checked.record, checked.skipped);
                        skipped += usize::from(checked.skipped);
                        records[i] = Some(checked.record);
                    }
                    Err(e) => {
                        stop.store(true, Ordering::Relaxed);
                        progress.note(&format!("error: {}: {e}", scenes[i].rel));
                        first_error.get_or_insert(e);
                    }
                },
            }
        }
    });
    progress.end();
    match first_error {
        Some(e) => Err(e),
        None => Ok((records.into_iter().flatten().collect(), skipped)),
    }
}

/// The message of a caught panic.
pub(crate) fn panic_text(p: &Box<dyn std::any::Any + Send>) -> String {
    let msg = p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned());
    format!("internal error: panicked: {}", msg.unwrap_or_else(|| "(no message)".into()))
}
