//! The preview window: a winit event loop around a [`Session`], redrawing when a watched file
//! changes or the user moves the camera, edits the scene in the panel or presses a key. The
//! panel's edits and the method keys go into the scene file (`Editor`); the camera moves stay
//! in the window until `C` writes them.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DQuat, DVec3};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use super::difference::Difference;
use super::editor::Editor;
use super::gui::Gui;
use super::panel::{self, Action};
use super::present::{Mode, Presenter};
use super::scene_text::{self as st, Step};
use super::{camera_file, knobs, Session, Watcher};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::graph::exec::Steps;
use crate::io::Image;
use crate::render::{MethodKind, RenderOptions};
use crate::scene::{Camera, Method};

/// `voltex preview` options.
pub struct PreviewArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Overrides of the scene applied on every rebuild.
    pub options: RenderOptions,
    /// Write each newly shown frame, as presented, to `DIR/frame-N.png` (tests, recordings), with
    /// what it shows in `DIR/frame-N.json`.
    pub record: Option<PathBuf>,
    /// Close the window after this many seconds (tests).
    pub quit_after: Option<f64>,
    /// The view to start in.
    pub mode: Mode,
    /// Keep the per-pass GPU times of the last frames rendered in this Chrome/Perfetto trace.
    pub trace: Option<PathBuf>,
    /// `--measure-ui`: switch to the reference view this many times, timing the window's frames
    /// while its frame renders, then print (and write to the file) the measurements and close.
    pub measure_ui: Option<(u32, Option<PathBuf>)>,
}

/// Said when a key or the panel would edit a scene that has no file of its own.
const NO_FILE: &str = "a mesh opened directly has no scene file to edit: `voltex import` writes one";
/// Frames a preview trace keeps (the latest).
const TRACE_FRAMES: usize = 100;
/// How long (ms) one window frame renders the frame in flight before drawing itself: a slow
/// frame renders in steps between window frames (see `State::run_steps`).
const STEP_MS: f64 = 30.0;

/// Runs `voltex preview`: opens the window and renders the scene, rebuilding when its files
/// change, until the window closes.
pub fn run(args: PreviewArgs) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| Error::Invalid(format!("cannot open a window: {e}")))?;
    let proxy = event_loop.create_proxy();
    let mut app = App { args, state: None, error: None, proxy };
    event_loop.run_app(&mut app).map_err(|e| Error::Invalid(format!("window event loop: {e}")))?;
    app.error.map_or(Ok(()), Err)
}

struct App {
    args: PreviewArgs,
    state: Option<State>,
    error: Option<Error>,
    /// Wakes the event loop when a watched file changes.
    proxy: EventLoopProxy<()>,
}

struct State {
    window: Arc<Window>,
    /// Kept to open a new device on it after a device loss.
    adapter: wgpu::Adapter,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    presenter: Presenter,
    gui: Gui,
    session: Session,
    /// The same frame with every object as `Reference`, made when the reference or difference
    /// view is first shown after a change.
    reference: Option<Session>,
    watcher: Watcher,
    /// The scene file's edits (`None` for a mesh opened directly).
    editor: Option<Editor>,
    /// The scene file, canonical, to tell its changes from those of other watched files.
    scene_file: PathBuf,
    home: Option<Camera>,
    /// The methods `M` switched away from, per node (see `knobs::LeftMethods`).
    left_methods: knobs::LeftMethods,
    selected: usize,
    mode: Mode,
    gpu_ms: Option<f64>,
    /// The scene must be rendered again.
    dirty: bool,
    /// The frame being rendered in steps, between which the window draws itself (`None` once
    /// it is shown), and the reference's.
    inflight: Option<Steps>,
    reference_inflight: Option<Steps>,
    /// The reference's session being built on another thread, and since when.
    reference_build: Option<(std::thread::JoinHandle<Session>, Instant)>,
    /// The last finished frame, shown while the next one renders in steps.
    shown: Option<wgpu::Texture>,
    /// The renderer must be rebuilt before the next frame (the camera moved, a drag ended).
    stale: bool,
    /// The next frame is recorded even if the image is unchanged (the user did something).
    record_next: bool,
    /// The panel is shown (`H` hides it).
    panel: bool,
    /// When egui wants its next frame.
    repaint_at: Option<Instant>,
    /// The panel's curve editors by path, from its last frame.
    rects: Vec<(String, egui::Rect)>,
    status: String,
    drag: Option<(MouseButton, (f64, f64))>,
    /// Where the last press on the image was (a release there is a click).
    pressed_at: Option<(f64, f64)>,
    cursor: (f64, f64),
    modifiers: ModifiersState,
    recorded: usize,
    started: Instant,
    /// `--trace`: the passes of the frames rendered so far (the last `TRACE_FRAMES`).
    trace: crate::render::trace::Track,
    /// `--measure-ui`'s measurement, and whether it ended (the window closes).
    measure: Option<super::measure_ui::UiMeasure>,
    measured: bool,
    /// Frames and reference frames finished so far: which pair `difference` was made from.
    finished: (u64, u64),
    /// The difference view's FLIP, made once both frames of a pair are finished.
    difference: Option<Difference>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_none() {
            match State::new(event_loop, &self.args, self.proxy.clone()) {
                Ok(s) => self.state = Some(s),
                Err(e) => {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(s) = self.state.as_mut() else { return };
        // Keys go to the panel only while one of its fields has the focus (typing a value).
        let typing = s.gui.ctx.egui_wants_keyboard_input();
        if (!matches!(event, WindowEvent::KeyboardInput { .. }) || typing)
            && s.gui.on_event(&s.window, &event).repaint
        {
            s.window.request_redraw();
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                s.config.width = size.width.max(1);
                s.config.height = size.height.max(1);
                s.surface.configure(&s.ctx.device, &s.config);
                s.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = s.redraw(&self.args) {
                    s.status = format!("error: {e}");
                }
                if s.ctx.lost().is_some() {
                    s.recover_device();
                }
            }
            WindowEvent::ModifiersChanged(m) => s.modifiers = m.state(),
            // The modifier keys' own events: synthetic input (xdotool under Xvfb) can leave the
            // modifiers' state event late or stale.
            WindowEvent::KeyboardInput {
                event: winit::event::KeyEvent { logical_key: Key::Named(k), state, .. },
                ..
            } if matches!(k, NamedKey::Control | NamedKey::Shift) => {
                let held = state == ElementState::Pressed;
                s.modifiers.set(
                    if k == NamedKey::Control { ModifiersState::CONTROL } else { ModifiersState::SHIFT },
                    held,
                );
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed && !typing => {
                if matches!(event.logical_key, Key::Named(NamedKey::Escape)) {
                    event_loop.exit();
                }
                s.key(&event.logical_key);
                s.record_next = true;
                s.window.request_redraw();
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let on_image = !s.panel || s.cursor.0 < s.image_width() as f64;
                if state == ElementState::Pressed && on_image {
                    s.drag = Some((button, s.cursor));
                    s.pressed_at = Some(s.cursor);
                    s.session.draft = s.session.draft_scale();
                } else if state == ElementState::Released {
                    s.drag = None;
                    // A click (the pointer moved under 3 pixels) selects what is under it.
                    let at = s.pressed_at.take();
                    if button == MouseButton::Left
                        && at.is_some_and(|(x, y)| (x - s.cursor.0).hypot(y - s.cursor.1) < 3.0)
                    {
                        s.select_at(s.cursor);
                    }
                    s.refine();
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                s.cursor = (position.x, position.y);
                if let Some((button, from)) = s.drag {
                    let d = (s.cursor.0 - from.0, s.cursor.1 - from.1);
                    s.drag = Some((button, s.cursor));
                    let pan = button == MouseButton::Right || s.modifiers.shift_key();
                    s.move_camera(|c, h| if pan { pan_camera(c, d, h) } else { orbit(c, d) });
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !s.panel || s.cursor.0 < s.image_width() as f64 => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                s.move_camera(|c, _| zoom(c, lines));
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(s) = self.state.as_mut() else { return };
        if s.measured || self.args.quit_after.is_some_and(|t| s.started.elapsed().as_secs_f64() > t) {
            event_loop.exit();
            return;
        }
        let changed = s.watcher.changes(Duration::ZERO);
        if !changed.is_empty() {
            s.files_changed(&changed);
        }
        if s.repaint_at.is_some_and(|t| Instant::now() >= t) {
            s.repaint_at = None;
            s.window.request_redraw();
        }
        if s.dirty {
            s.window.request_redraw();
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(50)));
    }
}

impl State {
    /// A lost device: opens a new one on the same adapter, remakes the surface configuration, the
    /// presenter and the panel's renderer, and re-renders the last good scene on it.
    fn recover_device(&mut self) {
        let why = self.ctx.lost().unwrap_or_default();
        eprintln!("GPU device lost ({why}); opening a new one");
        match GpuContext::open(self.adapter.clone())
            .and_then(|ctx| Presenter::new(&ctx, self.config.format).map(|p| (ctx, p)))
        {
            Ok((ctx, presenter)) => {
                self.surface.configure(&ctx.device, &self.config);
                self.session.recover(&ctx);
                self.gui.reset(&ctx.device, self.config.format);
                self.reference = None;
                self.reference_build = None;
                self.ctx = ctx;
                self.presenter = presenter;
                self.dirty = true;
                self.status = format!("GPU device lost ({why}); re-created it");
                self.window.request_redraw();
            }
            Err(e) => self.status = format!("error: GPU device lost and no new one: {e}"),
        }
    }

    fn new(event_loop: &ActiveEventLoop, args: &PreviewArgs, proxy: EventLoopProxy<()>) -> Result<Self> {
        let window = Arc::new(
            event_loop
                .create_window(
                    Window::default_attributes()
                        .with_title(format!("voltex preview: {}", args.scene.display()))
                        .with_inner_size(winit::dpi::PhysicalSize::new(960, 720)),
                )
                .map_err(|e| Error::Invalid(format!("cannot open a window: {e}")))?,
        );
        let desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        ));
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::Gpu(format!("cannot draw into the window: {e}")))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("no GPU adapter can draw into the window: {e}")))?;
        let ctx = GpuContext::open(adapter.clone())?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| Error::Gpu("the window surface is not supported by the adapter".into()))?;
        // Lavapipe defaults to Immediate; Fifo is supported everywhere.
        config.present_mode = wgpu::PresentMode::Fifo;
        config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        surface.configure(&ctx.device, &config);
        let presenter = Presenter::new(&ctx, config.format)?;
        let gui = Gui::new(&window, &ctx.device, config.format);
        let session = Session::open(&ctx, &args.scene, args.options.clone());
        let editor = match crate::scene::import::is_asset(&args.scene) {
            true => None,
            false => Editor::open(&args.scene).ok(),
        };
        // A change wakes the event loop at once (about_to_wait then reads it).
        let mut watcher = Watcher::with_wake(&session.watch_dirs(), move || {
            let _ = proxy.send_event(());
        })?;
        // Recordings and screenshots are written by the preview itself.
        let cwd = std::env::current_dir().unwrap_or_default();
        watcher.ignore.push(cwd.join("out"));
        let home = session.scene().map(|s| *s.camera);
        if let Some(dir) = &args.record {
            std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e))?;
            watcher.ignore.push(std::fs::canonicalize(dir).unwrap_or(dir.clone()));
        }
        Ok(State {
            adapter,
            window,
            surface,
            config,
            ctx,
            presenter,
            gui,
            scene_file: std::fs::canonicalize(&args.scene).unwrap_or(args.scene.clone()),
            session,
            reference: None,
            inflight: None,
            reference_inflight: None,
            reference_build: None,
            shown: None,
            watcher,
            editor,
            home,
            left_methods: Default::default(),
            selected: 0,
            mode: args.mode,
            gpu_ms: None,
            dirty: true,
            stale: false,
            record_next: false,
            panel: true,
            repaint_at: None,
            rects: Vec::new(),
            status: String::new(),
            drag: None,
            pressed_at: None,
            cursor: (0.0, 0.0),
            modifiers: ModifiersState::empty(),
            recorded: 0,
            finished: (0, 0),
            difference: None,
            started: Instant::now(),
            trace: crate::render::trace::Track { name: "preview".into(), frames: Vec::new() },
            measure: args
                .measure_ui
                .clone()
                .map(|(runs, json)| super::measure_ui::UiMeasure::new(runs as usize, json)),
            measured: false,
        })
    }

    /// Watched files changed: the scene file is re-read (our own writes are no change; an edit
    /// the panel held is dropped, the file wins), and the scene rebuilt if anything it reads
    /// changed.
    fn files_changed(&mut self, changed: &[PathBuf]) {
        let scene_file = &self.scene_file;
        let is_scene =
            |p: &PathBuf| p == scene_file || std::fs::canonicalize(p).is_ok_and(|c| c == *scene_file);
        let scene_touched = changed.iter().any(is_scene);
        let others = changed.iter().any(|p| !is_scene(p));
        let scene_changed = match &mut self.editor {
            Some(e) if scene_touched => e.reload(),
            _ => scene_touched,
        };
        if others || scene_changed {
            self.session.text = self.unsaved_text();
            self.session.rebuild(&self.ctx);
            self.reference = None;
            self.reference_build = None;
            self.dirty = true;
            let _ = self.watcher.watch(&self.session.watch_dirs());
        }
    }

    /// The text the panel holds that the file does not have.
    fn unsaved_text(&self) -> Option<String> {
        self.editor.as_ref().filter(|e| e.unsaved()).map(|e| e.text().to_string())
    }

    /// Width of the image's part of the window (the rest is the panel's).
    fn image_width(&self) -> u32 {
        let panel =
            if self.panel { (panel::WIDTH as f64 * self.window.scale_factor()).ceil() as u32 } else { 0 };
        self.config.width.saturating_sub(panel).max(1)
    }

    /// Renders the scene if something changed, runs the panel, then draws both.
    fn redraw(&mut self, args: &PreviewArgs) -> Result<()> {
        // Only the view changed (a camera move, a draft refined): no file is read again.
        if std::mem::take(&mut self.stale) {
            self.session.replan(&self.ctx);
        }
        if std::mem::take(&mut self.dirty) {
            // A new frame supersedes the one in flight.
            self.inflight = self.session.begin_steps(&self.ctx);
            if self.mode != Mode::Image && self.reference.is_none() && self.reference_build.is_none() {
                let mut options = self.session.options.clone();
                if let Some(size) = self.session.scene().and_then(|s| self.session.draft_size(s)) {
                    options.size = Some(size);
                    options.supersample = None;
                }
                options.method = Some(MethodKind::truth());
                options.object_methods.clear();
                // Built on another thread, so the window keeps drawing meanwhile, from the
                // image's bakes and pipelines (torus_egg's texel bake was half a second of
                // llvmpipe on the device's one queue, which the window's presents wait behind).
                let (ctx, path, text) =
                    (self.ctx.clone(), self.session.scene_path.clone(), self.unsaved_text());
                let cache = self.session.shared_cache();
                let build = std::thread::spawn(move || Session::open_with(&ctx, &path, options, text, cache));
                self.reference_build = Some((build, Instant::now()));
            }
        }
        if self.reference_build.as_ref().is_some_and(|(b, _)| b.is_finished()) {
            let (build, started) = self.reference_build.take().expect("a build");
            let mut r =
                build.join().map_err(|_| Error::Invalid("building the reference view failed".into()))?;
            if let Some(m) = &mut self.measure {
                m.build_ms = started.elapsed().as_secs_f64() * 1e3;
            }
            self.reference_inflight = r.begin_steps(&self.ctx);
            self.reference = Some(r);
        }
        let fresh = self.run_steps(args)?;
        self.update_difference()?;
        let actions = self.run_panel();
        let image = match self.inflight {
            Some(_) => self.shown.clone(),
            None => self.session.renderer().and_then(|r| r.output_texture()).cloned(),
        };
        // A recording shows finished frames only: what the user did is recorded once the frames
        // it started are shown.
        let settled = self.settled();
        if fresh && !settled {
            self.record_next = true;
        }
        let record = settled && (fresh || std::mem::take(&mut self.record_next));
        self.present(image, record, args)?;
        self.act(actions);
        self.measure_ui()
    }

    /// `--measure-ui`: after each window frame, what the measurement does next.
    fn measure_ui(&mut self) -> Result<()> {
        use super::measure_ui::Next;
        let settled = self.settled();
        let Some(m) = &mut self.measure else { return Ok(()) };
        let reference = self.reference.as_mut().and_then(|r| r.renderer_mut());
        match m.presented(settled, reference, &self.ctx)? {
            Next::Wait => {}
            Next::Switch => self.set_mode(Mode::Truth),
            Next::Back => {
                self.reference = None;
                self.reference_build = None;
                self.set_mode(Mode::Image);
            }
            Next::Quit => self.measured = true,
        }
        self.window.request_redraw();
        Ok(())
    }

    /// Renders the frames in flight, step by step, for at most [`STEP_MS`] of this window frame
    /// (at least one step), so the window keeps drawing and taking input while a slow frame
    /// renders; asks for another window frame while one is unfinished. Whether the image's
    /// frame finished now.
    fn run_steps(&mut self, args: &PreviewArgs) -> Result<bool> {
        let start = Instant::now();
        let mut fresh = false;
        if let Some(steps) = &mut self.inflight {
            if let Some(times) = self.session.step(&self.ctx, steps, STEP_MS)? {
                self.inflight = None;
                fresh = true;
                self.finished.0 += 1;
                self.gpu_ms = (!times.is_empty()).then(|| times.iter().map(|t| t.1).sum());
                self.keep_shown();
                if let (Some(path), Some(r)) = (&args.trace, self.session.renderer()) {
                    // Written after every frame, so the file holds the latest whatever ends the preview.
                    self.trace.frames.push(r.spans().to_vec());
                    let excess = self.trace.frames.len().saturating_sub(TRACE_FRAMES);
                    self.trace.frames.drain(..excess);
                    crate::render::trace::write(
                        path,
                        std::slice::from_ref(&self.trace),
                        &self.ctx.adapter_line(),
                    )?;
                }
            }
        }
        // The reference gets what is left of the window frame, and at least a step.
        if let (Some(steps), Some(r)) = (&mut self.reference_inflight, &mut self.reference) {
            let left = (STEP_MS - start.elapsed().as_secs_f64() * 1e3).max(1.0);
            if r.step(&self.ctx, steps, left)?.is_some() {
                self.reference_inflight = None;
                self.finished.1 += 1;
                self.record_next = true;
            }
        }
        if !self.settled() {
            self.window.request_redraw();
        }
        Ok(fresh)
    }

    /// In the difference view, once a new pair of frames is finished: FLIP between them (both
    /// read back; `voltex compare`'s metric and heat map).
    fn update_difference(&mut self) -> Result<()> {
        let current = self.difference.as_ref().is_some_and(|d| d.key == self.finished);
        if self.mode != Mode::Difference || current || !self.settled() {
            return Ok(());
        }
        let (Some(r), Some(reference)) =
            (self.session.renderer_mut(), self.reference.as_mut().and_then(|r| r.renderer_mut()))
        else {
            return Ok(());
        };
        let image = r.read_frame(&self.ctx)?.image;
        let truth = reference.read_frame(&self.ctx)?.image;
        self.difference = Some(Difference::new(&self.ctx, &image, &truth, self.finished));
        Ok(())
    }

    /// No frame is rendering and no reference building: what is shown is the latest.
    fn settled(&self) -> bool {
        self.inflight.is_none() && self.reference_inflight.is_none() && self.reference_build.is_none()
    }

    /// Copies the finished frame, to be shown while the next one renders in steps.
    fn keep_shown(&mut self) {
        let Some(out) = self.session.renderer().and_then(|r| r.output_texture()) else { return };
        let fits = self.shown.as_ref().is_some_and(|t| t.size() == out.size() && t.format() == out.format());
        if !fits {
            self.shown = Some(self.ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("shown frame"),
                size: out.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: out.format(),
                usage: wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            }));
        }
        let Some(shown) = &self.shown else { return };
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_texture(out.as_image_copy(), shown.as_image_copy(), out.size());
        self.ctx.queue.submit([encoder.finish()]);
    }

    /// Runs the panel's code for this frame: what the user did in it.
    fn run_panel(&mut self) -> Vec<Action> {
        if !self.panel {
            return Vec::new();
        }
        let src = match (&self.editor, self.session.scene()) {
            (Some(e), _) => e.text().to_string(),
            (None, Some(s)) => s.source().to_string(),
            (None, None) => String::new(),
        };
        let tree = st::parse(&src).ok();
        let objects = self.objects(tree.as_ref(), &src);
        let lines = self.info_lines();
        let editor = self.editor.as_ref();
        let view = panel::PanelView {
            src: &src,
            tree: tree.as_ref(),
            scene: self.session.scene(),
            objects: &objects,
            selected: self.selected % objects.len().max(1),
            mode: self.mode,
            lines: &lines,
            error: self.session.error.as_deref(),
            heat_scale: self.mode == Mode::Difference
                && self.difference.as_ref().is_some_and(|d| d.texture.is_some()),
            note: editor.and_then(|e| e.note.as_deref()),
            refused: editor.and_then(|e| e.refused.as_ref()),
            read_only: editor.is_some_and(|e| e.read_only),
            can_undo: editor.is_some_and(|e| e.can_undo()),
            can_redo: editor.is_some_and(|e| e.can_redo()),
        };
        let mut out = (Vec::new(), Vec::new());
        let delay = self.gui.run(&self.ctx, &self.window, |ui| out = panel::show(ui, &view));
        self.repaint_at = delay.map(|d| Instant::now() + d);
        self.rects = out.1;
        out.0
    }

    /// Makes what the user did in the panel.
    fn act(&mut self, actions: Vec<Action>) {
        for a in actions {
            self.record_next = true;
            self.window.request_redraw();
            match a {
                Action::Edit { edit, live } => self.edit(edit, live),
                Action::EndGesture => {
                    if let Some(e) = &mut self.editor {
                        e.end_gesture();
                    }
                    self.session.text = self.unsaved_text();
                    self.refine();
                }
                Action::Select(i) => self.selected = i,
                Action::Mode(m) => self.set_mode(m),
                Action::Undo => self.history(true),
                Action::Redo => self.history(false),
                Action::Note(n) => self.status = n,
            }
        }
    }

    /// An edit of the scene text: built (refused with the reason at its field if it cannot be),
    /// then written into the file (a drag's steps when it ends).
    fn edit(&mut self, edit: st::Edit, live: bool) {
        let Some(editor) = self.editor.as_mut() else {
            self.status = NO_FILE.into();
            return;
        };
        if live && self.session.draft == 1 {
            self.session.draft = self.session.draft_scale();
        }
        let (session, ctx) = (&mut self.session, &self.ctx);
        if editor.edit(edit, live, |text| session.try_text(ctx, text).map(drop)) {
            self.edited();
        }
    }

    fn history(&mut self, undo: bool) {
        let Some(editor) = self.editor.as_mut() else { return };
        let (session, ctx) = (&mut self.session, &self.ctx);
        let build = |text: &str| session.try_text(ctx, text).map(drop);
        let done = if undo { editor.undo(build) } else { editor.redo(build) };
        self.status = match (done, undo) {
            (true, true) => "undone".into(),
            (true, false) => "redone".into(),
            (false, true) => "nothing to undo".into(),
            (false, false) => "nothing to redo".into(),
        };
        if done {
            self.edited();
        }
    }

    /// The scene was rebuilt from the editor's text.
    fn edited(&mut self) {
        self.session.text = self.unsaved_text();
        self.reference = None;
        self.reference_build = None;
        self.dirty = true;
        self.window.request_redraw();
    }

    fn present(&mut self, image: Option<wgpu::Texture>, record: bool, args: &PreviewArgs) -> Result<()> {
        // Without the panel, a few lines of text over the image say what it would.
        let lines = if self.panel { Vec::new() } else { self.hidden_lines() };
        // The reference's views wait for its frame: until then the image is shown.
        let reference = (self.reference_inflight.is_none())
            .then(|| {
                self.reference.as_ref().and_then(|r| r.renderer()).and_then(|r| r.output_texture()).cloned()
            })
            .flatten();
        let blank = || {
            self.ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("blank"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let image = image.unwrap_or_else(blank);
        // The difference view shows FLIP's heat map as it is, once there is one; the image
        // until then.
        let heat = self.difference.as_ref().and_then(|d| d.texture.clone()).filter(|_| reference.is_some());
        let (image, reference, mode) = match (self.mode, heat) {
            // (The presenter shows its first image tonemapped unless given a second.)
            (Mode::Difference, Some(heat)) => (heat.clone(), Some(heat), Mode::Difference),
            (Mode::Difference, None) => (image, None, Mode::Image),
            (mode, _) => (image, reference, mode),
        };
        let size = (self.config.width, self.config.height);
        let area = (self.image_width(), size.1);
        if let (Some(dir), true) = (&args.record, record) {
            self.record(dir, size, (&image, reference.as_ref(), mode), &lines, area)?;
        }
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                // Draw again into the reconfigured surface; the frame itself is still good.
                self.surface.configure(&self.ctx.device, &self.config);
                self.window.request_redraw();
                return Ok(());
            }
            _ => return Ok(()),
        };
        let view = frame.texture.create_view(&Default::default());
        self.presenter.draw(&self.ctx, &view, area, &image, reference.as_ref(), mode, &lines);
        if self.panel {
            self.gui.paint(&self.ctx, &view, size);
        }
        self.window.pre_present_notify();
        self.ctx.queue.present(frame);
        Ok(())
    }

    /// Draws what the window shows into an offscreen texture and writes it as `frame-N.png`.
    fn record(
        &mut self,
        dir: &std::path::Path,
        size: (u32, u32),
        (image, reference, mode): (&wgpu::Texture, Option<&wgpu::Texture>, Mode),
        lines: &[String],
        area: (u32, u32),
    ) -> Result<()> {
        let target = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("recording"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.presenter.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = target.create_view(&Default::default());
        self.presenter.draw(&self.ctx, &view, area, image, reference, mode, lines);
        if self.panel {
            self.gui.paint(&self.ctx, &view, size);
        }
        let row = (size.0 * 4).div_ceil(256) * 256;
        let buffer = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("recording readback"),
            size: row as u64 * size.1 as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            target.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        );
        self.ctx.queue.submit([enc.finish()]);
        let bytes = self.ctx.map_read(&buffer)?;
        let bgra = matches!(
            self.presenter.format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let mut pixels = Vec::with_capacity((size.0 * size.1) as usize);
        for y in 0..size.1 as usize {
            for px in bytes[y * row as usize..][..size.0 as usize * 4].chunks_exact(4) {
                pixels.push(if bgra { [px[2], px[1], px[0], 255] } else { [px[0], px[1], px[2], 255] });
            }
        }
        let path = dir.join(format!("frame-{}.png", self.recorded));
        // What the frame shows besides its pixels, for tests: the selection, view and messages,
        // and where the curve editors are (window pixels).
        let scale = self.window.scale_factor() as f32;
        let editors: serde_json::Map<String, serde_json::Value> = (self.rects.iter())
            .map(|(p, r)| {
                (
                    p.clone(),
                    serde_json::json!([r.min.x * scale, r.min.y * scale, r.max.x * scale, r.max.y * scale]),
                )
            })
            .collect();
        let objects = self.methods();
        let state = serde_json::json!({
            "selected": objects.get(self.selected % objects.len().max(1)).map(|o| o.0.clone()),
            "method": objects.get(self.selected % objects.len().max(1)).map(|o| describe(&o.1)),
            "mode": format!("{:?}", self.mode),
            "panel": self.panel,
            "status": self.status,
            "note": self.editor.as_ref().and_then(|e| e.note.clone()),
            "refused": self.editor.as_ref().and_then(|e| e.refused.as_ref().map(|r| (st::show(&r.0), r.1.clone()))),
            "read_only": self.editor.as_ref().is_some_and(|e| e.read_only),
            "error": self.session.error,
            "editors": editors,
            "flip": self.difference.as_ref().filter(|_| self.mode == Mode::Difference).and_then(|d| d.flip.clone().ok()),
        });
        let json = path.with_extension("json");
        crate::io::atomic::write_bytes(&json, state.to_string().as_bytes())?;
        crate::io::png::write_rgba8(&path, size.0, size.1, &pixels)?;
        self.recorded += 1;
        Ok(())
    }

    /// The panel's first lines: scene and view, GPU time and adapter, the last action.
    fn info_lines(&self) -> Vec<String> {
        let mode = match self.mode {
            Mode::Image => "image",
            Mode::Truth => "reference",
            Mode::Difference => "difference to the reference",
        };
        let mut lines = vec![format!("{}  [{mode}]", self.session.scene_path.display())];
        let gpu = self.gpu_ms.map(|t| format!("{t:.2} ms GPU")).unwrap_or_else(|| "no GPU timestamps".into());
        // While a slow frame renders (the last finished one shown), its progress takes the GPU
        // line's place: the panel's layout stays put under the pointer.
        let progress = [("frame", &self.inflight), ("reference", &self.reference_inflight)]
            .into_iter()
            .find_map(|(what, steps)| steps.as_ref().map(|s| (what, s.progress())));
        lines.push(match progress {
            Some((what, (done, total))) => {
                let bar: String = (0..20).map(|i| if i * total < 20 * done { '#' } else { '.' }).collect();
                format!("rendering the {what} [{bar}] {}%", done * 100 / total.max(1))
            }
            None if self.reference_build.is_some() => {
                "building the reference (scene, bakes, pipelines)".into()
            }
            None => format!("{gpu}  {}", self.ctx.info.name),
        });
        if let Some(d) = self.difference.as_ref().filter(|_| self.mode == Mode::Difference) {
            lines.push(d.line());
        }
        if !self.status.is_empty() {
            lines.push(self.status.clone());
        }
        lines
    }

    /// What the image shows when the panel is hidden.
    fn hidden_lines(&self) -> Vec<String> {
        let mut lines = self.info_lines();
        let objects = self.methods();
        if let Some((name, m)) = objects.get(self.selected % objects.len().max(1)) {
            lines.push(format!(
                "[{}/{}] {name}: {}",
                self.selected % objects.len() + 1,
                objects.len(),
                describe(m)
            ));
        }
        lines.push("H: show the panel".into());
        if let Some(e) = &self.session.error {
            let chars: Vec<char> = e.chars().collect();
            lines.extend(chars.chunks(100).take(6).map(|c| c.iter().collect::<String>()));
        }
        lines
    }

    /// The drawn objects and their methods as the current renderer has them.
    fn methods(&self) -> Vec<(String, Method)> {
        let Some(r) = self.session.renderer() else { return Vec::new() };
        r.blueprint.objects.iter().filter_map(|o| Some((o.object.name.clone(), o.scene_method()?))).collect()
    }

    /// The drawn objects with the paths of their nodes in the text.
    fn objects(&self, tree: Option<&st::Value>, src: &str) -> Vec<panel::Object> {
        let mut nodes = Vec::new();
        if let Some(t) = tree {
            knobs::node_paths(t, src, Vec::new(), &mut nodes);
        }
        (self.methods().into_iter())
            .filter_map(|(name, _)| {
                let node = nodes.iter().find(|(n, _)| *n == name)?.1.clone();
                Some(panel::Object { name, node })
            })
            .collect()
    }

    /// The selected object: its name, method and node path (when the text has it).
    fn selected(&self) -> Option<(String, Method, Option<Vec<Step>>)> {
        let objects = self.methods();
        let (name, m) = objects.get(self.selected % objects.len().max(1))?.clone();
        let src = self.editor.as_ref().map(|e| e.text().to_string()).unwrap_or_default();
        let node = st::parse(&src).ok().and_then(|t| {
            let mut nodes = Vec::new();
            knobs::node_paths(&t, &src, Vec::new(), &mut nodes);
            nodes.into_iter().find(|(n, _)| *n == name).map(|(_, p)| p)
        });
        Some((name, m, node))
    }

    /// Selects the textured object whose shell is under window position `at`, if any.
    fn select_at(&mut self, at: (f64, f64)) {
        let (Some(cam), Some(r)) = (self.session.options.camera.or(self.home), self.session.renderer())
        else {
            return;
        };
        // The image as the presenter fits it into its area (aspect kept, centred).
        let (w, h) = (r.blueprint.size.0 as f64, r.blueprint.size.1 as f64);
        let area = (self.image_width() as f64, self.config.height as f64);
        let scale = (area.0 / w).min(area.1 / h);
        let pixel =
            ((at.0 - 0.5 * (area.0 - w * scale)) / scale, (at.1 - 0.5 * (area.1 - h * scale)) / scale);
        if !(0.0..w).contains(&pixel.0) || !(0.0..h).contains(&pixel.1) {
            return;
        }
        let objects: Vec<_> = r.blueprint.objects.iter().map(|o| &o.object).collect();
        let Some(i) = super::pick::pick(&objects, &cam, r.blueprint.size, pixel) else { return };
        let name = objects[i].name.clone();
        if let Some(k) = self.methods().iter().position(|(n, _)| *n == name) {
            self.selected = k;
            self.status = format!("selected {name}");
            self.record_next = true;
            self.window.request_redraw();
        }
    }

    fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
        self.dirty = true;
    }

    fn move_camera(&mut self, f: impl FnOnce(&mut Camera, f64)) {
        let Some(mut cam) = self.session.options.camera.or(self.home) else { return };
        f(&mut cam, self.config.height as f64);
        self.session.options.camera = Some(cam);
        // Rebuilt once before the next frame, however many moves come before it.
        self.stale = true;
        self.reference = None;
        self.reference_build = None;
        self.dirty = true;
    }

    /// A drag ended: the frame drawn at draft quality is drawn again at full quality.
    fn refine(&mut self) {
        if self.session.draft > 1 {
            self.session.draft = 1;
            self.stale = true;
            self.reference = None;
            self.reference_build = None;
            self.dirty = true;
            self.window.request_redraw();
        }
    }

    /// A key edit of the selected object's node (`M`, `+`, `-`).
    fn node_edit(&mut self, make: impl FnOnce(&str, &[Step], &Method) -> Result<Option<st::Edit>>) {
        let Some(editor) = &self.editor else {
            self.status = NO_FILE.into();
            return;
        };
        let Some((name, m, node)) = self.selected() else { return };
        let Some(node) = node else {
            self.status = format!("no node \"{name}\" in the scene text");
            return;
        };
        match make(editor.text(), &node, &m) {
            Ok(Some(edit)) => {
                let what = format!("{name}: {}", st::show(&edit.path));
                self.edit(edit, false);
                if let Some((_, why)) = self.editor.as_ref().and_then(|e| e.refused.clone()) {
                    self.status = format!("{what}: refused: {why}");
                } else {
                    let objects = self.methods();
                    let now =
                        objects.iter().find(|o| o.0 == name).map(|o| describe(&o.1)).unwrap_or_default();
                    self.status = format!("{name}: {now}");
                }
            }
            Ok(None) => self.status = format!("{name}: no knob to step"),
            Err(e) => self.status = format!("error: {e}"),
        }
    }

    fn key(&mut self, key: &Key) {
        let n = self.methods().len().max(1);
        let Key::Character(c) = key else {
            if matches!(key, Key::Named(NamedKey::Tab)) {
                self.selected = (self.selected + 1) % n;
            }
            return;
        };
        if self.modifiers.control_key() {
            // Shift may reach us as the key's case before the modifiers' own event.
            if c.eq_ignore_ascii_case("z") {
                self.history(!(self.modifiers.shift_key() || c == "Z"));
            }
            return;
        }
        match c.as_str() {
            "r" | "R" => {
                self.session.options.camera = None;
                self.session.rebuild(&self.ctx);
                self.reference = None;
                self.reference_build = None;
                self.dirty = true;
                self.status = "camera reset to the scene's".into();
            }
            "c" | "C" => {
                let Some(cam) = self.session.options.camera else { return };
                match &self.editor {
                    Some(e) => {
                        let edit = st::set(
                            e.text(),
                            &[Step::Field("camera".into())],
                            &camera_file::format_camera(&cam),
                        );
                        match edit {
                            Ok(edit) => self.edit(edit, false),
                            Err(e) => self.status = format!("error: {e}"),
                        }
                        let e = self.editor.as_ref();
                        self.status =
                            match (e.and_then(|e| e.note.clone()), e.and_then(|e| e.refused.clone())) {
                                (Some(note), _) => note,
                                (_, Some((_, why))) => format!("camera not written: {why}"),
                                _ => format!("camera written to {}", self.session.scene_path.display()),
                            };
                    }
                    None => self.status = NO_FILE.into(),
                }
                self.home = Some(cam);
            }
            "m" | "M" => {
                let mut left = std::mem::take(&mut self.left_methods);
                self.node_edit(|src, node, m| knobs::next_method(src, node, m, &mut left).map(Some));
                self.left_methods = left;
            }
            "+" | "=" | "-" => {
                let finer = c.as_str() != "-";
                self.node_edit(|src, node, m| knobs::step_quality(src, node, m, finer));
            }
            "h" | "H" => {
                self.panel = !self.panel;
                self.dirty = true;
            }
            "1" => self.set_mode(Mode::Image),
            "2" => self.set_mode(Mode::Truth),
            "3" => self.set_mode(Mode::Difference),
            "s" | "S" => self.status = self.screenshot().unwrap_or_else(|e| format!("error: {e}")),
            _ => {}
        }
    }

    /// Writes the shown image (the reference in the reference view) as EXR and PNG under out/.
    fn screenshot(&mut self) -> Result<String> {
        let session = match (self.mode, &self.reference) {
            (Mode::Truth, Some(r)) => r,
            _ => &self.session,
        };
        let Some(r) = session.renderer() else { return Err(Error::Invalid("nothing rendered yet".into())) };
        let image: Image = r.read_texture(&self.ctx, &r.blueprint.graph.file.outputs[0])?;
        let dir = PathBuf::from("out");
        std::fs::create_dir_all(&dir).map_err(|e| Error::file(&dir, e))?;
        let stem =
            self.session.scene_path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string();
        let n = (0..).find(|n| !dir.join(format!("preview-{stem}-{n}.exr")).exists()).unwrap_or(0);
        let exr = dir.join(format!("preview-{stem}-{n}.exr"));
        let meta = [
            ("voltex_scene", self.session.scene_path.display().to_string()),
            ("voltex_adapter", self.ctx.adapter_line()),
        ];
        crate::io::exr::write(&exr, &image, &meta)?;
        crate::io::png::write_tonemapped(&exr.with_extension("png"), &image)?;
        Ok(format!("screenshot {} and .png", exr.display()))
    }
}

fn describe(m: &Method) -> String {
    m.plugin().describe()
}

/// Turns the eye around the target: horizontal drags about `up`, vertical ones about the
/// camera's right axis (stopping short of the poles).
fn orbit(c: &mut Camera, d: (f64, f64)) {
    let up = c.up.normalize();
    let offset = c.eye - c.target;
    let right = offset.cross(up).normalize_or_zero();
    let yaw = DQuat::from_axis_angle(up, -d.0 * 0.008);
    let mut o = yaw * offset;
    let pitched = DQuat::from_axis_angle(yaw * right, -d.1 * 0.008) * o;
    if pitched.normalize().dot(up).abs() < 0.995 {
        o = pitched;
    }
    c.eye = c.target + o;
}

/// Moves eye and target together in the view plane, a drag across the window moving by about
/// the distance to the target.
fn pan_camera(c: &mut Camera, d: (f64, f64), height: f64) {
    let forward = (c.target - c.eye).normalize();
    let right = forward.cross(c.up).normalize_or_zero();
    let up = right.cross(forward);
    let scale = (c.target - c.eye).length() * 2.0 * (0.5 * c.fov_y.to_radians()).tan() / height.max(1.0);
    let shift: DVec3 = (-right * d.0 + up * d.1) * scale;
    c.eye += shift;
    c.target += shift;
}

fn zoom(c: &mut Camera, lines: f64) {
    c.eye = c.target + (c.eye - c.target) * (-0.1 * lines).exp();
}
