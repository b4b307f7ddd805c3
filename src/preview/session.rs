//! The preview's reload machinery, without a window: a scene file turned into a renderer, rebuilt
//! on demand through a [`GpuCache`] so that an edit re-makes only what it changed, and the last
//! good renderer kept (and shown) whenever a rebuild fails. After a lost device, [`Session::recover`]
//! rebuilds the last good scene on a new one.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::knobs;
use crate::gpu::cache::{CacheStats, GpuCache};
use crate::gpu::GpuContext;
use crate::graph::exec::Steps;
use crate::render::{shader_sources, Blueprint, Frame, RenderOptions, Renderer};
use crate::scene::{self, Scene, SceneObject};
use crate::Result;

/// What a rebuild did.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// A new renderer is current; what it had to create (modules, pipelines, bakes).
    Rebuilt(CacheStats),
    /// The last good renderer stays; the error, with `file:line:col` where there is one.
    Failed(String),
}

/// Where the last successful rebuild's time went, in ms (`voltex preview --measure-latency`).
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub(crate) struct Stages {
    /// Reading and parsing the scene file.
    pub(crate) parse: f64,
    /// The blueprint: objects, shells, plane sweeps, bakes to make, the graph plan.
    pub(crate) plan: f64,
    /// Bakes not found in the cache (texels, mesh grids, splat sets), GPU work waited for.
    pub(crate) bake: f64,
    /// The rest of the renderer: buffers, pipelines not found in the cache.
    pub(crate) build: f64,
    /// Files read and shaders validated over all of the above (set by `rebuild` and `replan`,
    /// which see the whole step).
    pub(crate) work: crate::work::Work,
}

/// Bakes an edit left unused that the preview keeps (beyond the frame's own memory), so that
/// undoing the edit finds them instead of baking again.
const STALE_BAKE_BYTES: u64 = 256 << 20;

/// The preview's state without a window: the scene, its renderer and what the last rebuild
/// found; rebuilt when a file it reads changes, keeping the last good state on an error.
pub struct Session {
    pub(crate) scene_path: PathBuf,
    /// Overrides (size, graph, methods, camera) applied on every rebuild.
    pub options: RenderOptions,
    cache: GpuCache,
    scene: Option<Scene>,
    renderer: Option<Renderer>,
    /// The current error (cleared by a successful rebuild).
    pub error: Option<String>,
    /// The last error printed, so each distinct error is logged once.
    logged: Option<String>,
    /// The scene's text when the panel holds edits the file does not have (else the file's).
    pub(crate) text: Option<String>,
    /// The last successful rebuild's stages.
    pub(crate) stages: Stages,
    /// Draft quality while a drag goes on: the frame is drawn at 1/`draft` of its width and
    /// height (1: full quality). The next rebuild applies it; setting it back to 1 and rebuilding
    /// refines the frame.
    pub draft: u32,
    /// Wall time of the last full-quality frame (ms), for [`Session::draft_scale`].
    frame_ms: Option<f64>,
    /// Wall time of the steps of the frame in flight (ms), and the units submitted a batch.
    step_ms: f64,
    batch: u32,
    /// The last good scene's objects (flattened, prisms checked, surfaces shared) at the time
    /// they were made for: a view change plans them again without flattening the scene.
    objects: Option<(Option<f64>, Vec<SceneObject>)>,
}

/// What a draft frame may take to draw (ms): with a rebuild and the panel, a drag stays near the
/// 100 ms save-to-frame goal on a software adapter.
pub(crate) const DRAFT_FRAME_MS: f64 = 40.0;

impl Session {
    /// Builds the first renderer; a failure leaves the session without one and with `error` set.
    pub fn open(ctx: &GpuContext, scene_path: &Path, options: RenderOptions) -> Self {
        Self::open_with(ctx, scene_path, options, None, GpuCache::with_stale_bytes(STALE_BAKE_BYTES))
    }

    /// As [`Session::open`], from `text` instead of the file when given (edits the file lacks),
    /// starting from `cache` (another session's, shared: its bakes and pipelines are not made
    /// again).
    pub(crate) fn open_with(
        ctx: &GpuContext,
        scene_path: &Path,
        options: RenderOptions,
        text: Option<String>,
        cache: GpuCache,
    ) -> Self {
        let mut s = Session {
            scene_path: scene_path.to_path_buf(),
            options,
            cache,
            scene: None,
            renderer: None,
            error: None,
            logged: None,
            text,
            stages: Stages::default(),
            draft: 1,
            frame_ms: None,
            step_ms: 0.0,
            batch: 1,
            objects: None,
        };
        s.rebuild(ctx);
        s
    }

    /// Reloads the scene, graph and kernels and makes a renderer, reusing whatever is unchanged.
    pub fn rebuild(&mut self, ctx: &GpuContext) -> Outcome {
        let work = crate::work::Work::now();
        let t = Instant::now();
        let scene = match &self.text {
            Some(text) => scene::parse(text, &self.scene_path),
            None => scene::load(&self.scene_path),
        };
        let parse = ms(t);
        match scene.and_then(|scene| self.build(ctx, scene)) {
            Ok(stats) => {
                self.stages.parse = parse;
                self.stages.work = crate::work::Work::since(work);
                stats
            }
            Err(e) => self.failed(e),
        }
    }

    /// Builds the scene of `text` (an edit the panel proposes). On success it is current; on
    /// failure nothing changes (the panel refuses the edit and says why at the field).
    pub(crate) fn try_text(
        &mut self,
        ctx: &GpuContext,
        text: &str,
    ) -> std::result::Result<CacheStats, String> {
        match scene::parse(text, &self.scene_path).and_then(|scene| self.build(ctx, scene)) {
            Ok(Outcome::Rebuilt(stats)) => Ok(stats),
            Ok(Outcome::Failed(e)) => Err(e),
            Err(e) => Err(e.to_string()),
        }
    }

    fn build(&mut self, ctx: &GpuContext, scene: Scene) -> Result<Outcome> {
        let stats = self.make(ctx, &scene, false)?;
        self.scene = Some(scene);
        self.error = None;
        self.logged = None;
        Ok(Outcome::Rebuilt(stats))
    }

    /// Plans `scene` with the session's options and makes its renderer (the stages timed).
    /// `same_scene`: `scene` is the last good one, whose objects may be planned again.
    fn make(&mut self, ctx: &GpuContext, scene: &Scene, same_scene: bool) -> Result<CacheStats> {
        self.cache.begin();
        let t = Instant::now();
        let kept = self.objects.as_ref().filter(|(time, _)| same_scene && *time == self.options.time);
        let objects = match kept {
            Some((_, objects)) => objects.clone(),
            None => scene.objects_at(self.options.time.unwrap_or(scene.time))?,
        };
        let bp = self.blueprint(scene, objects)?;
        let objects = bp.objects.iter().map(|o| o.object.clone()).collect();
        let plan = ms(t);
        let t = Instant::now();
        let renderer = Renderer::with_cache(ctx, bp, &mut self.cache)?;
        let made = ms(t);
        // The callers add what they read before (the scene file) to the work: see `Stages::work`.
        let (bake, build) = (renderer.bake_ms, made - renderer.bake_ms);
        self.stages = Stages { parse: 0.0, plan, bake, build, work: Default::default() };
        self.cache.retain_used();
        self.renderer = Some(renderer);
        self.objects = Some((self.options.time, objects));
        Ok(self.cache.stats)
    }

    /// Keeps no bake a rebuild left unused (the latency measurement: a value toggled back is
    /// rebaked, as a new value would be, instead of found in the cache).
    pub(crate) fn keep_no_unused_bakes(&mut self) {
        self.cache.set_stale_bytes(0);
    }

    /// After the device was lost: drops everything made on it and rebuilds the last good scene
    /// (not the file, which may be broken by now) on `ctx`, a new device. Without a good scene
    /// yet, rebuilds from the file. The current error, if any, stays.
    pub fn recover(&mut self, ctx: &GpuContext) -> Outcome {
        self.renderer = None;
        self.cache.clear();
        self.replan(ctx)
    }

    /// The view changed (camera, draft), not the files: plans the last good scene again
    /// without reading anything (its assets are in it). Without a good scene yet, rebuilds from
    /// the file. The current error, if any, stays.
    pub fn replan(&mut self, ctx: &GpuContext) -> Outcome {
        let Some(scene) = self.scene.take() else { return self.rebuild(ctx) };
        let work = crate::work::Work::now();
        let made = self.make(ctx, &scene, true);
        self.stages.work = crate::work::Work::since(work);
        self.scene = Some(scene);
        match made {
            Ok(stats) => Outcome::Rebuilt(stats),
            Err(e) => self.failed(e),
        }
    }

    fn failed(&mut self, e: crate::Error) -> Outcome {
        let msg = e.to_string();
        if self.logged.as_deref() != Some(&msg) {
            eprint!("{}", e.report());
            self.logged = Some(msg.clone());
        }
        self.error = Some(msg.clone());
        Outcome::Failed(msg)
    }

    /// This session's bakes and pipelines, for another session of the same scene.
    pub(crate) fn shared_cache(&self) -> GpuCache {
        self.cache.share()
    }

    /// Renders a frame with the last good renderer (`None` before any build succeeded).
    pub fn render(&mut self, ctx: &GpuContext) -> Option<Result<Frame>> {
        self.renderer.as_mut().map(|r| r.render(ctx))
    }

    /// Renders a frame to be shown from the renderer's output texture, without reading it back:
    /// the per-pass GPU times. Times full-quality frames for [`Session::draft_scale`].
    pub(crate) fn draw(&mut self, ctx: &GpuContext) -> Option<Result<Vec<(String, f64)>>> {
        let t = Instant::now();
        let times = self.renderer.as_mut()?.render_timed(ctx);
        if self.draft == 1 && times.is_ok() {
            self.frame_ms = Some(ms(t));
        }
        Some(times)
    }

    /// Starts the next frame in steps ([`Session::step`]); `None` without a renderer.
    pub(crate) fn begin_steps(&mut self, ctx: &GpuContext) -> Option<Steps> {
        self.step_ms = 0.0;
        self.batch = 1;
        self.renderer.as_mut().map(|r| r.begin_steps(ctx))
    }

    /// Renders `steps`' frame on for about `budget_ms`, so that the window's own frames run
    /// between calls ([`Renderer::step_for`]). The per-pass GPU times when the frame is finished.
    /// The steps' wall time times full-quality frames for [`Session::draft_scale`].
    pub(crate) fn step(
        &mut self,
        ctx: &GpuContext,
        steps: &mut Steps,
        budget_ms: f64,
    ) -> Result<Option<Vec<(String, f64)>>> {
        let Some(r) = self.renderer.as_mut() else { return Ok(Some(Vec::new())) };
        let start = Instant::now();
        let finished = r.step_for(ctx, steps, budget_ms, &mut self.batch)?;
        self.step_ms += ms(start);
        if !finished {
            return Ok(None);
        }
        if self.draft == 1 {
            self.frame_ms = Some(self.step_ms);
        }
        Ok(Some(r.spans().iter().map(|s| (s.name.clone(), s.ms)).collect()))
    }

    /// The draft scale for a drag: 1 when a full-quality frame draws within [`DRAFT_FRAME_MS`],
    /// else how many times over it is, at most 8. A draft divides the width and height, and
    /// the planes or steps, by it: a frame bound by its pixels gets cheaper by its cube, one
    /// bound by its geometry at least by the scale itself.
    pub(crate) fn draft_scale(&self) -> u32 {
        let ms = self.frame_ms.unwrap_or(0.0);
        ((ms / DRAFT_FRAME_MS).ceil() as u32).clamp(1, 8)
    }

    /// The blueprint of `scene` with the session's options, at draft quality while drafting.
    fn blueprint(&self, scene: &Scene, objects: Vec<SceneObject>) -> Result<Blueprint> {
        if self.draft <= 1 {
            return Blueprint::with_objects(scene, objects, &self.options);
        }
        let mut options = self.options.clone();
        options.size = self.draft_size(scene);
        options.supersample = None;
        // Each object's method (the preview's switch, else the file's) made coarser.
        for o in &objects {
            let chosen = options.object_methods.iter().find(|(n, _)| *n == o.name).map(|(_, m)| m);
            if let Some(m) = chosen.or(o.method.as_ref()).map(|m| knobs::coarser(m, self.draft as f64)) {
                options.object_methods.retain(|(n, _)| *n != o.name);
                options.object_methods.push((o.name.clone(), m));
            }
        }
        // A draft the planner refuses (a knob past a limit) is drawn at full quality.
        Blueprint::with_objects(scene, objects.clone(), &options)
            .or_else(|_| Blueprint::with_objects(scene, objects, &self.options))
    }

    /// The size frames are drawn at while drafting (`None` at full quality).
    pub(crate) fn draft_size(&self, scene: &Scene) -> Option<(u32, u32)> {
        let (w, h) = self.options.size.unwrap_or((scene.output.width, scene.output.height));
        (self.draft > 1).then(|| (w.div_ceil(self.draft), h.div_ceil(self.draft)))
    }

    /// The current renderer (none before the first good build).
    pub fn renderer(&self) -> Option<&Renderer> {
        self.renderer.as_ref()
    }

    pub(crate) fn renderer_mut(&mut self) -> Option<&mut Renderer> {
        self.renderer.as_mut()
    }

    /// The current scene (none before the first good load).
    pub fn scene(&self) -> Option<&Scene> {
        self.scene.as_ref()
    }

    /// Folders to watch, recursively: the scene's folder, those of the files it refers to, and the
    /// folders on disk that the graph and its shaders are read from (the graph's folder and the
    /// project's `wgsl/`; embedded files are not watched). Editors save by renaming, so files are
    /// not watched alone.
    pub fn watch_dirs(&self) -> Vec<PathBuf> {
        let parent = |p: &Path| p.parent().map(Path::to_path_buf).unwrap_or_else(|| PathBuf::from("."));
        let mut dirs = vec![parent(&self.scene_path)];
        if let Some(graph) = &self.options.graph {
            dirs.push(parent(graph));
        }
        dirs.extend(
            shader_sources(self.options.graph.as_deref()).map(|s| s.watched_dirs()).unwrap_or_default(),
        );
        if let Some(scene) = &self.scene {
            dirs.extend(scene.asset_paths().iter().map(|p| parent(p)));
        }
        let mut canonical: Vec<PathBuf> =
            dirs.into_iter().map(|d| std::fs::canonicalize(&d).unwrap_or(d)).collect();
        canonical.sort();
        canonical.dedup();
        // A folder inside another watched one is covered by the recursive watch.
        let all = canonical.clone();
        canonical.retain(|d| !all.iter().any(|o| o != d && d.starts_with(o)));
        canonical
    }
}

/// Milliseconds since `t`.
pub(crate) fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
