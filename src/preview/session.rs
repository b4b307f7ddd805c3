//! The preview's reload machinery, without a window: a scene file turned into a renderer, rebuilt
//! on demand through a [`GpuCache`] so that an edit re-makes only what it changed, and the last
//! good renderer kept (and shown) whenever a rebuild fails. After a lost device, [`Session::recover`]
//! rebuilds the last good scene on a new one.

use std::path::{Path, PathBuf};

use crate::gpu::cache::{CacheStats, GpuCache};
use crate::gpu::GpuContext;
use crate::render::{shader_sources, Blueprint, Frame, RenderOptions, Renderer};
use crate::scene::{self, Scene};
use crate::Result;

/// What a rebuild did.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// A new renderer is current; what it had to create (modules, pipelines, bakes).
    Rebuilt(CacheStats),
    /// The last good renderer stays; the error, with `file:line:col` where there is one.
    Failed(String),
}

pub struct Session {
    pub scene_path: PathBuf,
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
    pub text: Option<String>,
}

impl Session {
    /// Builds the first renderer; a failure leaves the session without one and with `error` set.
    pub fn open(ctx: &GpuContext, scene_path: &Path, options: RenderOptions) -> Self {
        Self::open_with(ctx, scene_path, options, None)
    }

    /// As [`Session::open`], from `text` instead of the file when given (edits the file lacks).
    pub fn open_with(
        ctx: &GpuContext,
        scene_path: &Path,
        options: RenderOptions,
        text: Option<String>,
    ) -> Self {
        let mut s = Session {
            scene_path: scene_path.to_path_buf(),
            options,
            cache: GpuCache::default(),
            scene: None,
            renderer: None,
            error: None,
            logged: None,
            text,
        };
        s.rebuild(ctx);
        s
    }

    /// Reloads the scene, graph and kernels and makes a renderer, reusing whatever is unchanged.
    pub fn rebuild(&mut self, ctx: &GpuContext) -> Outcome {
        let scene = match &self.text {
            Some(text) => scene::parse(text, &self.scene_path),
            None => scene::load(&self.scene_path),
        };
        match scene.and_then(|scene| self.build(ctx, scene)) {
            Ok(stats) => stats,
            Err(e) => self.failed(e),
        }
    }

    /// Builds the scene of `text` (an edit the panel proposes). On success it is current; on
    /// failure nothing changes (the panel refuses the edit and says why at the field).
    pub fn try_text(&mut self, ctx: &GpuContext, text: &str) -> std::result::Result<CacheStats, String> {
        match scene::parse(text, &self.scene_path).and_then(|scene| self.build(ctx, scene)) {
            Ok(Outcome::Rebuilt(stats)) => Ok(stats),
            Ok(Outcome::Failed(e)) => Err(e),
            Err(e) => Err(e.to_string()),
        }
    }

    fn build(&mut self, ctx: &GpuContext, scene: Scene) -> Result<Outcome> {
        self.cache.begin();
        let bp = Blueprint::new(&scene, &self.options)?;
        let renderer = Renderer::with_cache(ctx, bp, &mut self.cache)?;
        self.cache.retain_used();
        self.scene = Some(scene);
        self.renderer = Some(renderer);
        self.error = None;
        self.logged = None;
        Ok(Outcome::Rebuilt(self.cache.stats))
    }

    /// After the device was lost: drops everything made on it and rebuilds the last good scene
    /// (not the file, which may be broken by now) on `ctx`, a new device. Without a good scene
    /// yet, rebuilds from the file. The current error, if any, stays.
    pub fn recover(&mut self, ctx: &GpuContext) -> Outcome {
        self.renderer = None;
        self.cache = GpuCache::default();
        let Some(scene) = self.scene.as_ref() else { return self.rebuild(ctx) };
        self.cache.begin();
        let built = Blueprint::new(scene, &self.options)
            .and_then(|bp| Renderer::with_cache(ctx, bp, &mut self.cache));
        match built {
            Ok(renderer) => {
                self.cache.retain_used();
                self.renderer = Some(renderer);
                Outcome::Rebuilt(self.cache.stats)
            }
            Err(e) => self.failed(e),
        }
    }

    fn failed(&mut self, e: crate::Error) -> Outcome {
        let msg = e.to_string();
        if self.logged.as_deref() != Some(&msg) {
            eprintln!("error: {msg}");
            self.logged = Some(msg.clone());
        }
        self.error = Some(msg.clone());
        Outcome::Failed(msg)
    }

    /// Renders a frame with the last good renderer (`None` before any build succeeded).
    pub fn render(&mut self, ctx: &GpuContext) -> Option<Result<Frame>> {
        self.renderer.as_mut().map(|r| r.render(ctx))
    }

    pub fn renderer(&self) -> Option<&Renderer> {
        self.renderer.as_ref()
    }

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
