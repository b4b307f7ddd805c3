//! `voltex preview SCENE --measure-latency`: the save-to-frame latency of the edits a user makes
//! (a camera move, a light's direction, a method knob, a texel's value, a hypertexture noise),
//! each written into a copy of the scene beside it, picked up by the file watcher and rebuilt as
//! the preview does, timed stage by stage over several repetitions after a warm-up.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::{DQuat, DVec3};
use serde::Serialize;

use super::scene_text::{self as st, format_number, Step};
use super::session::ms;
use super::{Outcome, Session, Watcher};
use crate::error::{Error, Result};
use crate::gpu::cache::CacheStats;
use crate::gpu::GpuContext;
use crate::render::RenderOptions;

/// The goals of issue 18: a camera, light or knob edit, and a texel rebake (ms).
pub(crate) const GOAL_MS: f64 = 100.0;
pub(crate) const GOAL_REBAKE_MS: f64 = 300.0;

/// One save, from the write to the frame read back, in ms.
#[derive(Debug, Default, Clone, Copy, Serialize, PartialEq)]
pub(crate) struct Sample {
    /// Writing the file (temporary file, then rename: what the panel and most editors do).
    pub(crate) write: f64,
    /// From the write to the watcher's report (the debounce included).
    pub(crate) watch: f64,
    pub(crate) parse: f64,
    pub(crate) plan: f64,
    pub(crate) bake: f64,
    /// Buffers and pipelines not in the cache.
    pub(crate) build: f64,
    /// The frame's passes, submit to idle.
    pub(crate) render: f64,
    /// The output read back (the window presents it instead).
    pub(crate) readback: f64,
    pub(crate) total: f64,
    /// Files opened (scene, assets, graph, WGSL) and the time spent reading them (ms), within
    /// the stages above.
    pub(crate) files: f64,
    pub(crate) io: f64,
    /// Shaders parsed and validated and the time it took (ms), within the stages above.
    pub(crate) shaders: f64,
    pub(crate) validate: f64,
}

/// The stages of a [`Sample`] in order, with their values.
impl Sample {
    pub(crate) fn stages(&self) -> [(&'static str, f64); 13] {
        [
            ("write", self.write),
            ("watch", self.watch),
            ("parse", self.parse),
            ("plan", self.plan),
            ("bake", self.bake),
            ("build", self.build),
            ("render", self.render),
            ("readback", self.readback),
            ("total", self.total),
            ("files", self.files),
            ("io", self.io),
            ("shaders", self.shaders),
            ("validate", self.validate),
        ]
    }

    /// The median of each stage (and of the total) over `samples`.
    fn median(samples: &[Sample]) -> Sample {
        let m = |f: fn(&Sample) -> f64| {
            let mut v: Vec<f64> = samples.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(0.0)
        };
        Sample {
            write: m(|s| s.write),
            watch: m(|s| s.watch),
            parse: m(|s| s.parse),
            plan: m(|s| s.plan),
            bake: m(|s| s.bake),
            build: m(|s| s.build),
            render: m(|s| s.render),
            readback: m(|s| s.readback),
            total: m(|s| s.total),
            files: m(|s| s.files),
            io: m(|s| s.io),
            shaders: m(|s| s.shaders),
            validate: m(|s| s.validate),
        }
    }
}

/// One kind of edit: its samples and what the last one made.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// `camera`, `light`, `knob`, `texel`, `noise`.
    pub(crate) edit: String,
    /// The value edited and its two values, e.g. `lights[0].direction: (..) <-> (..)`.
    pub(crate) what: String,
    pub(crate) goal_ms: f64,
    /// What the last repetition had to make (not found in the cache).
    pub(crate) modules: u32,
    pub(crate) pipelines: u32,
    pub(crate) bakes: u32,
    pub(crate) median: Sample,
    pub(crate) samples: Vec<Sample>,
}

/// A whole `--json` file of `voltex preview-latency`: the run's settings and one row per edit.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub(crate) command: String,
    pub(crate) scene: String,
    /// The adapter, as [`GpuContext::adapter_line`](crate::gpu::GpuContext::adapter_line) names it.
    pub adapter: String,
    /// The 1-minute load average when the run began (a software adapter shares the CPU).
    pub(crate) load: Option<f64>,
    /// Render size in pixels (width, height).
    pub size: [u32; 2],
    pub(crate) debounce_ms: f64,
    pub(crate) repeat: usize,
    /// One row per edit measured.
    pub rows: Vec<Row>,
}

/// An edit probe: the value at `path` set to `values[1]`, `values[0]`, ... in turn.
struct Probe {
    edit: &'static str,
    path: Vec<Step>,
    values: [String; 2],
    goal: f64,
}

/// A copy of the scene beside it (its assets resolve as the scene's do), removed when dropped.
struct Copy(PathBuf);

impl Copy {
    fn new(scene: &Path) -> Result<Self> {
        let stem = scene.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
        let path = scene.with_file_name(format!("{stem}-latency-{}.ron", std::process::id()));
        let text = crate::input::read_text(scene, "scene file")?;
        crate::io::atomic::write_bytes(&path, text.as_bytes())?;
        Ok(Copy(path))
    }
}

impl Drop for Copy {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Measures every edit the scene has a value for, `repeat` times each after one warm-up.
pub fn measure(ctx: &GpuContext, scene: &Path, options: RenderOptions, repeat: usize) -> Result<Report> {
    // The scene's own errors name the user's file, not the copy.
    crate::scene::load(scene)?;
    let copy = Copy::new(scene)?;
    let mut session = Session::open(ctx, &copy.0, options);
    if let Some(e) = &session.error {
        return Err(Error::Invalid(e.clone()));
    }
    // Each edit toggles between two values: timed as a rebake, not as the cache's undo.
    session.keep_no_unused_bakes();
    frame(ctx, &mut session)?;
    let watcher = Watcher::new(&session.watch_dirs())?;
    let load =
        std::fs::read_to_string("/proc/loadavg").ok().and_then(|l| l.split_whitespace().next()?.parse().ok());
    let size = session.renderer().map_or((0, 0), |r| r.blueprint.size);
    let mut text = crate::input::read_text(&copy.0, "scene file")?;
    let mut rows = Vec::new();
    for probe in probes(&text, &session)? {
        let what = format!("{}: {} <-> {}", st::show(&probe.path), probe.values[0], probe.values[1]);
        rows.push(timed(probe.edit, what, probe.goal, repeat, |i| {
            text = st::set(&text, &probe.path, &probe.values[(i + 1) % 2])?.apply(&text)?;
            save(ctx, &mut session, &watcher, &copy.0, &text)
                .map_err(|e| Error::Invalid(format!("{} edit of {}: {e}", probe.edit, st::show(&probe.path))))
        })?);
    }
    // A camera drag in the window: no file, one rebuild and frame per step, at full quality and
    // at the draft quality a drag draws at.
    let scale = session.draft_scale();
    for draft in if scale > 1 { vec![1, scale] } else { vec![1] } {
        session.draft = draft;
        let drawn = session.scene().and_then(|s| session.draft_size(s)).unwrap_or(size);
        let what = format!("a camera drag step in the window, drawn at {}x{}", drawn.0, drawn.1);
        let edit = if draft == 1 { "orbit" } else { "drag" };
        rows.push(timed(edit, what, GOAL_MS, repeat, |i| orbit(ctx, &mut session, i))?);
    }
    session.draft = 1;
    Ok(Report {
        command: "preview --measure-latency".into(),
        scene: scene.display().to_string(),
        adapter: ctx.adapter_line(),
        load,
        size: [size.0, size.1],
        debounce_ms: super::watch::DEBOUNCE.as_secs_f64() * 1e3,
        repeat,
        rows,
    })
}

/// The row of `edit`: `step(i)` for a warm-up (`i` = 0) and `repeat` timed repetitions.
fn timed(
    edit: &str,
    what: String,
    goal_ms: f64,
    repeat: usize,
    mut step: impl FnMut(usize) -> Result<(Sample, CacheStats)>,
) -> Result<Row> {
    let mut samples = Vec::new();
    let mut made = CacheStats::default();
    for i in 0..=repeat {
        let (sample, stats) = step(i)?;
        made = stats;
        if i > 0 {
            samples.push(sample);
        }
    }
    let CacheStats { modules, pipelines, bakes } = made;
    let median = Sample::median(&samples);
    Ok(Row { edit: edit.into(), what, goal_ms, modules, pipelines, bakes, median, samples })
}

/// One save of `text` as `path`, waited for through the watcher, rebuilt, rendered, read back.
fn save(
    ctx: &GpuContext,
    session: &mut Session,
    watcher: &Watcher,
    path: &Path,
    text: &str,
) -> Result<(Sample, CacheStats)> {
    let start = Instant::now();
    st::write(path, text)?;
    let write = ms(start);
    let deadline = start + Duration::from_secs(10);
    let name = path.file_name();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(Error::file(path, "the file watcher reported no change within 10 s"));
        }
        if watcher.changes(left).iter().any(|p| p.file_name() == name) {
            break;
        }
    }
    let watch = ms(start) - write;
    let stats = match session.rebuild(ctx) {
        Outcome::Rebuilt(stats) => stats,
        Outcome::Failed(e) => return Err(Error::Invalid(e)),
    };
    let (render, readback) = frame(ctx, session)?;
    let s = session.stages;
    let sample = Sample {
        write,
        watch,
        parse: s.parse,
        plan: s.plan,
        bake: s.bake,
        build: s.build,
        render,
        readback,
        total: ms(start),
        ..worked(s.work)
    };
    Ok((sample, stats))
}

/// Step `i` of an orbit around the scene's target (the window's left drag): re-planned, rendered.
fn orbit(ctx: &GpuContext, session: &mut Session, i: usize) -> Result<(Sample, CacheStats)> {
    let start = Instant::now();
    let cam = *session.scene().ok_or_else(|| Error::Invalid("no scene".into()))?.camera;
    session.options.camera = Some(cam.orbited(2.0 * i as f64));
    // As the window does: the last good scene planned again, no file read.
    let stats = match session.replan(ctx) {
        Outcome::Rebuilt(stats) => stats,
        Outcome::Failed(e) => return Err(Error::Invalid(e)),
    };
    let (render, readback) = frame(ctx, session)?;
    let s = session.stages;
    let (parse, plan, bake, build) = (s.parse, s.plan, s.bake, s.build);
    let sample = Sample { parse, plan, bake, build, render, readback, total: ms(start), ..worked(s.work) };
    Ok((sample, stats))
}

/// A sample with only the work counters of a rebuild set.
fn worked(w: crate::work::Work) -> Sample {
    Sample {
        files: w.files as f64,
        io: w.io_ms,
        shaders: w.shaders as f64,
        validate: w.validate_ms,
        ..Default::default()
    }
}

/// Renders a frame and reads it back: the times of both (ms).
fn frame(ctx: &GpuContext, session: &mut Session) -> Result<(f64, f64)> {
    let t = Instant::now();
    session.draw(ctx).ok_or_else(|| Error::Invalid("no renderer".into()))??;
    let render = ms(t);
    let r = session.renderer().ok_or_else(|| Error::Invalid("no renderer".into()))?;
    let t = Instant::now();
    r.read_texture(ctx, &r.blueprint.graph.file.outputs[0])?;
    Ok((render, ms(t)))
}

/// The edits the scene has values for: its camera, its first light's direction, the first
/// object's quality knob, its first texel's first colour (or number), its first hypertexture's
/// first noise amplitude.
fn probes(src: &str, session: &Session) -> Result<Vec<Probe>> {
    let tree = st::tree(src)?;
    let field = |f: &str| Step::Field(f.into());
    let mut out = Vec::new();
    let scene = session.scene().ok_or_else(|| Error::Invalid("no scene".into()))?;
    let cam = *scene.camera;
    let up = cam.up.normalize();
    let turn = |v: DVec3| DQuat::from_axis_angle(up, 10f64.to_radians()) * v;
    let mut probe = |edit, path: Vec<Step>, after: String, goal| {
        if let Some(v) = tree.at(&path, src) {
            out.push(Probe { edit, values: [v.text(src).to_string(), after], path, goal });
        }
    };
    probe(
        "camera",
        vec![field("camera"), field("eye")],
        vec3(cam.target + turn(cam.eye - cam.target)),
        GOAL_MS,
    );
    let light = vec![field("lights"), Step::Index(0), field("direction")];
    if let Some(d) = tree.at(&light, src).and_then(|v| numbers(v, src)) {
        probe("light", light, vec3(turn(DVec3::new(d[0], d[1], d[2]))), GOAL_MS);
    }
    if let Some((path, after)) = knob(&tree, src, session) {
        probe("knob", path, after, GOAL_MS);
    }
    if let Some(source) = first_entry(&tree, src, "texels").map(|mut p| {
        p.push(field("source"));
        p
    }) {
        let color = find(&tree, src, &source, &|name, v| name == "color" && numbers(v, src).is_some());
        if let Some(path) = color {
            let c = tree.at(&path, src).and_then(|v| numbers(v, src)).unwrap_or_default();
            let mut c = c.clone();
            c[0] = if c[0] > 0.5 { c[0] - 0.2 } else { c[0] + 0.2 };
            let text = c.iter().map(|x| format_number(*x, "0.0")).collect::<Vec<_>>().join(", ");
            probe("texel", path, format!("({text})"), GOAL_REBAKE_MS);
        } else if let Some(path) = find(&tree, src, &source, &|_, v| is_float(v, src)) {
            let x = tree.at(&path, src).and_then(|v| v.number(src)).unwrap_or(1.0);
            probe("texel", path, format_number(x * 0.9, "0.0"), GOAL_REBAKE_MS);
        }
    }
    if let Some(mut noise) = first_entry(&tree, src, "hypertextures") {
        noise.extend([field("noises"), Step::Index(0), field("amplitude")]);
        if let Some(a) = tree.at(&noise, src).and_then(|v| v.number(src)) {
            probe("noise", noise, format_number(a * 0.8, "0.0"), GOAL_MS);
        }
    }
    Ok(out)
}

/// The first drawn object's quality knob as it is in the text (ViewSlices planes, a ray step,
/// AxisSlices depth), and the value one `-` key makes of it.
fn knob(tree: &st::Value, src: &str, session: &Session) -> Option<(Vec<Step>, String)> {
    let mut nodes = Vec::new();
    super::knobs::node_paths(tree, src, Vec::new(), &mut nodes);
    let r = session.renderer()?;
    r.blueprint.objects.iter().find_map(|o| {
        let method = o.scene_method()?;
        let (_, node) = nodes.iter().find(|(n, _)| *n == o.object.name)?;
        let edit = super::knobs::step_quality(src, node, &method, false).ok()??;
        // The knob's own value, when the file has it: the edit's text is the whole node.
        let stepped = edit.apply(src).ok()?;
        let mut path = node.clone();
        path.push(Step::Field("method".into()));
        let field = ["planes", "step", "depth"].into_iter().find_map(|f| {
            let mut p = path.clone();
            p.push(Step::Field(f.into()));
            let after = st::parse(&stepped).ok()?.at(&p, &stepped)?.text(&stepped).to_string();
            tree.at(&p, src).map(|_| (p, after))
        });
        Some(field.unwrap_or((edit.path.clone(), edit.after.clone())))
    })
}

/// The path of the first entry of the map field `name` of the root.
fn first_entry(tree: &st::Value, src: &str, name: &str) -> Option<Vec<Step>> {
    let v = tree.child(&Step::Field(name.into()), src)?;
    let st::Kind::Map(entries) = &v.kind else { return None };
    let key = st::unquote(entries.first()?.0.text(src))?;
    Some(vec![Step::Field(name.into()), Step::Key(key)])
}

/// The first value under `at` (depth first, in text order) whose field name and value pass `pick`.
fn find(
    tree: &st::Value,
    src: &str,
    at: &[Step],
    pick: &dyn Fn(&str, &st::Value) -> bool,
) -> Option<Vec<Step>> {
    let v = tree.at(at, src)?;
    let children: Vec<(Step, Option<&str>)> = match &v.kind {
        st::Kind::Paren { fields, .. } => fields
            .iter()
            .enumerate()
            .map(|(i, f)| match &f.name {
                Some(n) => (Step::Field(n.clone()), Some(n.as_str())),
                None => (Step::Index(i), None),
            })
            .collect(),
        st::Kind::List(items) => (0..items.len()).map(|i| (Step::Index(i), None)).collect(),
        _ => Vec::new(),
    };
    children.into_iter().find_map(|(step, name)| {
        let mut p = at.to_vec();
        p.push(step);
        let child = tree.at(&p, src)?;
        if pick(name.unwrap_or(""), child) {
            return Some(p);
        }
        find(tree, src, &p, pick)
    })
}

fn is_float(v: &st::Value, src: &str) -> bool {
    v.number(src).is_some() && v.text(src).contains('.')
}

/// A tuple of three numbers.
fn numbers(v: &st::Value, src: &str) -> Option<Vec<f64>> {
    let n: Option<Vec<f64>> = v.items().iter().map(|i| i.number(src)).collect();
    n.filter(|n| n.len() == 3)
}

fn vec3(v: DVec3) -> String {
    format!("({}, {}, {})", format_number(v.x, "0.0"), format_number(v.y, "0.0"), format_number(v.z, "0.0"))
}

impl Report {
    /// The table printed: one row per edit, the median of each stage (ms).
    pub fn table(&self) -> String {
        let mut s = format!(
            "save-to-frame latency, {} ({}x{}), {}, load {}, median of {} after a warm-up (ms)\n",
            self.scene,
            self.size[0],
            self.size[1],
            self.adapter,
            self.load.map_or("?".into(), |l| format!("{l:.2}")),
            self.repeat
        );
        let stages = Sample::default().stages();
        s.push_str(&format!("{:<8}", "edit"));
        for (name, _) in stages {
            s.push_str(&format!("{name:>9}"));
        }
        s.push_str(&format!("{:>7}  made (modules/pipelines/bakes)\n", "goal"));
        for r in &self.rows {
            s.push_str(&format!("{:<8}", r.edit));
            for (_, v) in r.median.stages() {
                s.push_str(&format!("{v:>9.1}"));
            }
            let met = if r.median.total <= r.goal_ms { "" } else { " over" };
            s.push_str(&format!("{:>7}{met}  {}/{}/{}\n", r.goal_ms, r.modules, r.pipelines, r.bakes));
        }
        for r in &self.rows {
            s.push_str(&format!("  {}: {}\n", r.edit, r.what));
        }
        s
    }

    /// Writes the report as JSON (temporary file, then rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(|e| Error::Invalid(format!("JSON: {e}")))?;
        crate::io::atomic::write_bytes(path, (text + "\n").as_bytes())
    }
}
