//! The preview window: a winit event loop around a [`Session`], redrawing when a watched file
//! changes or the user moves the camera, switches a method or steps its knobs.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DQuat, DVec3};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use super::present::{Mode, Presenter};
use super::{camera_file, Session, Watcher};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::io::Image;
use crate::render::{MethodKind, RenderOptions, DEFAULT_PLANES};
use crate::scene::{Camera, Method, Reference, Shading, ViewSlices, MAX_PLANES};

/// `voltex preview` options.
pub struct PreviewArgs {
    pub scene: PathBuf,
    pub options: RenderOptions,
    /// Write each newly shown frame, as presented, to `DIR/frame-N.png` (tests, recordings).
    pub record: Option<PathBuf>,
    /// Close the window after this many seconds (tests).
    pub quit_after: Option<f64>,
    /// The view to start in.
    pub mode: Mode,
}

pub fn run(args: PreviewArgs) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| Error::Invalid(format!("cannot open a window: {e}")))?;
    let mut app = App { args, state: None, error: None };
    event_loop.run_app(&mut app).map_err(|e| Error::Invalid(format!("window event loop: {e}")))?;
    app.error.map_or(Ok(()), Err)
}

struct App {
    args: PreviewArgs,
    state: Option<State>,
    error: Option<Error>,
}

struct State {
    window: Arc<Window>,
    /// Kept to open a new device on it after a device loss.
    adapter: wgpu::Adapter,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    presenter: Presenter,
    session: Session,
    /// The same frame with every object as `Reference`, made when the reference or difference
    /// view is first shown after a change.
    reference: Option<Session>,
    watcher: Watcher,
    home: Option<Camera>,
    selected: usize,
    mode: Mode,
    gpu_ms: Option<f64>,
    dirty: bool,
    status: String,
    drag: Option<(MouseButton, (f64, f64))>,
    cursor: (f64, f64),
    modifiers: ModifiersState,
    recorded: usize,
    started: Instant,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_none() {
            match State::new(event_loop, &self.args) {
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
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if matches!(event.logical_key, Key::Named(NamedKey::Escape)) {
                    event_loop.exit();
                }
                s.key(&event.logical_key);
            }
            WindowEvent::MouseInput { state, button, .. } => {
                s.drag = (state == ElementState::Pressed).then_some((button, s.cursor));
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
            WindowEvent::MouseWheel { delta, .. } => {
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
        if self.args.quit_after.is_some_and(|t| s.started.elapsed().as_secs_f64() > t) {
            event_loop.exit();
            return;
        }
        let changed = s.watcher.changes(Duration::ZERO);
        if !changed.is_empty() {
            s.session.rebuild(&s.ctx);
            s.reference = None;
            s.dirty = true;
            let _ = s.watcher.watch(&s.session.watch_dirs());
        }
        if s.dirty {
            s.window.request_redraw();
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(50)));
    }
}

impl State {
    /// A lost device: opens a new one on the same adapter, remakes the surface configuration and
    /// the presenter, and re-renders the last good scene on it.
    fn recover_device(&mut self) {
        let why = self.ctx.lost().unwrap_or_default();
        eprintln!("GPU device lost ({why}); opening a new one");
        match GpuContext::open(self.adapter.clone())
            .and_then(|ctx| Presenter::new(&ctx, self.config.format).map(|p| (ctx, p)))
        {
            Ok((ctx, presenter)) => {
                self.surface.configure(&ctx.device, &self.config);
                self.session.recover(&ctx);
                self.reference = None;
                self.ctx = ctx;
                self.presenter = presenter;
                self.dirty = true;
                self.status = format!("GPU device lost ({why}); re-created it");
                self.window.request_redraw();
            }
            Err(e) => self.status = format!("error: GPU device lost and no new one: {e}"),
        }
    }

    fn new(event_loop: &ActiveEventLoop, args: &PreviewArgs) -> Result<Self> {
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
        let session = Session::open(&ctx, &args.scene, args.options.clone());
        let mut watcher = Watcher::new(&session.watch_dirs())?;
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
            session,
            reference: None,
            watcher,
            home,
            selected: 0,
            mode: args.mode,
            gpu_ms: None,
            dirty: true,
            status: String::new(),
            drag: None,
            cursor: (0.0, 0.0),
            modifiers: ModifiersState::empty(),
            recorded: 0,
            started: Instant::now(),
        })
    }

    /// Renders the scene if something changed, then draws the current image and overlay.
    fn redraw(&mut self, args: &PreviewArgs) -> Result<()> {
        let fresh = self.dirty;
        if self.dirty {
            self.dirty = false;
            if let Some(frame) = self.session.render(&self.ctx) {
                self.gpu_ms = frame?.gpu_ms();
            }
            if self.mode != Mode::Image && self.reference.is_none() {
                let mut options = self.session.options.clone();
                options.method = Some(MethodKind::Reference);
                options.object_methods.clear();
                let mut r = Session::open(&self.ctx, &self.session.scene_path, options);
                if let Some(frame) = r.render(&self.ctx) {
                    frame?;
                }
                self.reference = Some(r);
            }
        }
        let Some(image) = self.session.renderer().and_then(|r| r.output_texture()) else {
            // No good build yet: only the overlay (with the error) on black.
            return self.present(None, false, args);
        };
        let image = image.clone();
        self.present(Some(image), fresh, args)
    }

    fn present(&mut self, image: Option<wgpu::Texture>, fresh: bool, args: &PreviewArgs) -> Result<()> {
        let lines = self.overlay();
        let reference =
            self.reference.as_ref().and_then(|r| r.renderer()).and_then(|r| r.output_texture()).cloned();
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
        let size = (self.config.width, self.config.height);
        if let (Some(dir), true) = (&args.record, fresh) {
            self.record(dir, size, &image, reference.as_ref(), &lines)?;
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
        self.presenter.draw(&self.ctx, &view, size, &image, reference.as_ref(), self.mode, &lines);
        self.window.pre_present_notify();
        self.ctx.queue.present(frame);
        Ok(())
    }

    /// Draws what the window shows into an offscreen texture and writes it as `frame-N.png`.
    fn record(
        &mut self,
        dir: &std::path::Path,
        size: (u32, u32),
        image: &wgpu::Texture,
        reference: Option<&wgpu::Texture>,
        lines: &[String],
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
        self.presenter.draw(&self.ctx, &view, size, image, reference, self.mode, lines);
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
        crate::io::png::write_rgba8(&path, size.0, size.1, &pixels)?;
        self.recorded += 1;
        Ok(())
    }

    fn overlay(&self) -> Vec<String> {
        let mode = match self.mode {
            Mode::Image => "image",
            Mode::Reference => "reference",
            Mode::Difference => "difference to the reference",
        };
        let mut lines = vec![format!("{}  [{mode}]", self.session.scene_path.display())];
        let gpu = self.gpu_ms.map(|t| format!("{t:.2} ms GPU")).unwrap_or_else(|| "no GPU timestamps".into());
        lines.push(format!("{gpu}  {}", self.ctx.info.name));
        let objects = self.methods();
        if let Some((name, m)) = objects.get(self.selected % objects.len().max(1)) {
            lines.push(format!(
                "[{}/{}] {name}: {}",
                self.selected % objects.len() + 1,
                objects.len(),
                describe(m)
            ));
        }
        lines.push("drag: orbit | right or shift drag: pan | wheel: zoom | R: reset | C: save camera".into());
        lines.push("Tab: next object | M: method | +/-: quality | 1 2 3: image, reference, difference | S: screenshot".into());
        if !self.status.is_empty() {
            lines.push(self.status.clone());
        }
        if let Some(e) = &self.session.error {
            let chars: Vec<char> = e.chars().collect();
            for chunk in chars.chunks(100).take(6) {
                lines.push(chunk.iter().collect());
            }
        }
        lines
    }

    /// The drawn objects and their methods as the current renderer has them.
    fn methods(&self) -> Vec<(String, Method)> {
        let Some(r) = self.session.renderer() else { return Vec::new() };
        r.blueprint.objects.iter().filter_map(|o| Some((o.object.name.clone(), o.scene_method()?))).collect()
    }

    fn set_method(&mut self, name: String, m: Method) {
        self.session.options.object_methods.retain(|(n, _)| *n != name);
        self.session.options.object_methods.push((name, m));
        self.session.rebuild(&self.ctx);
        self.dirty = true;
    }

    fn move_camera(&mut self, f: impl FnOnce(&mut Camera, f64)) {
        let Some(mut cam) = self.session.options.camera.or(self.home) else { return };
        f(&mut cam, self.config.height as f64);
        self.session.options.camera = Some(cam);
        self.session.rebuild(&self.ctx);
        self.reference = None;
        self.dirty = true;
    }

    fn key(&mut self, key: &Key) {
        let objects = self.methods();
        let selected = objects.get(self.selected % objects.len().max(1)).cloned();
        let Key::Character(c) = key else {
            if matches!(key, Key::Named(NamedKey::Tab)) {
                self.selected = (self.selected + 1) % objects.len().max(1);
                self.dirty = true;
            }
            return;
        };
        match c.as_str() {
            "r" | "R" => {
                self.session.options.camera = None;
                self.session.rebuild(&self.ctx);
                self.reference = None;
                self.dirty = true;
                self.status = "camera reset to the scene's".into();
            }
            "c" | "C" => {
                if let Some(cam) = self.session.options.camera {
                    self.status = match camera_file::write_camera(&self.session.scene_path, &cam) {
                        Ok(()) => format!("camera written to {}", self.session.scene_path.display()),
                        Err(e) => format!("error: {e}"),
                    };
                    self.home = Some(cam);
                }
            }
            "m" | "M" => {
                if let Some((name, m)) = selected {
                    // ViewSlices -> AxisSlices -> Reference -> ViewSlices (lighting kept where it exists).
                    let next = match m {
                        Method::ViewSlices(_) => Method::AxisSlices(crate::render::DEFAULT_AXIS_SLICES),
                        Method::AxisSlices(_) => {
                            Method::Reference(Reference { step: None, lighting: Default::default() })
                        }
                        Method::Reference(r) => Method::ViewSlices(ViewSlices {
                            planes: DEFAULT_PLANES,
                            trivial_reject: true,
                            lighting: r.lighting,
                            compositor: Default::default(),
                        }),
                        // Hypertextures have no texel for other methods: cycle their shading.
                        Method::RayMarch(mut h) => {
                            h.shading = match h.shading {
                                Shading::None => Shading::Phong,
                                Shading::Phong => Shading::PhongShadows,
                                Shading::PhongShadows => Shading::None,
                            };
                            Method::RayMarch(h)
                        }
                        // A method without keys here keeps its knobs.
                        #[allow(unreachable_patterns)]
                        other => other,
                    };
                    self.set_method(name, next);
                }
            }
            "+" | "=" | "-" => {
                let finer = c.as_str() != "-";
                if let Some((name, m)) = selected {
                    let next = match m {
                        Method::ViewSlices(mut v) => {
                            v.planes =
                                if finer { (v.planes * 2).min(MAX_PLANES) } else { (v.planes / 2).max(1) };
                            Method::ViewSlices(v)
                        }
                        Method::Reference(mut r) => {
                            r.step = r.step.map(|s| if finer { s / 2.0 } else { s * 2.0 });
                            Method::Reference(r)
                        }
                        // Finer: see less deep inside contours (more slices).
                        Method::AxisSlices(mut a) => {
                            a.depth = if finer {
                                (a.depth / 2.0).max(1.0 / 64.0)
                            } else {
                                (a.depth * 2.0).min(1024.0)
                            };
                            Method::AxisSlices(a)
                        }
                        Method::RayMarch(mut h) => {
                            // The adaptive stride's longest step scales with the step, so the
                            // stride stays on rather than vanishing below two steps.
                            let scale = if finer { 0.5 } else { 2.0 };
                            h.step = Some(h.step() * scale);
                            if let Some(a) = &mut h.adaptive {
                                a.max_step *= scale;
                            }
                            Method::RayMarch(h)
                        }
                        // A method without keys here keeps its knobs.
                        #[allow(unreachable_patterns)]
                        other => other,
                    };
                    self.set_method(name, next);
                }
            }
            "1" => self.set_mode(Mode::Image),
            "2" => self.set_mode(Mode::Reference),
            "3" => self.set_mode(Mode::Difference),
            "s" | "S" => self.status = self.screenshot().unwrap_or_else(|e| format!("error: {e}")),
            _ => {}
        }
    }

    fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
        self.dirty = true;
    }

    /// Writes the shown image (the reference in the reference view) as EXR and PNG under out/.
    fn screenshot(&mut self) -> Result<String> {
        let session = match (self.mode, &self.reference) {
            (Mode::Reference, Some(r)) => r,
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
    match m {
        Method::RayMarch(h) => {
            let adaptive = h.adaptive.map_or(String::new(), |a| format!(", max_step: {:.5}", a.max_step));
            format!(
                "RayMarch(step: {:.5}{adaptive}, shading: {:?}, segments: {:?})",
                h.step(),
                h.shading,
                h.segments
            )
        }
        Method::AxisSlices(a) => {
            format!("AxisSlices(depth: {}, pixels: {}, {:?})", a.depth, a.pixels, a.directions)
        }
        Method::ViewSlices(v) => format!("ViewSlices(planes: {}, lighting: {:?})", v.planes, v.lighting),
        Method::Reference(r) => {
            format!(
                "Reference(step: {}, lighting: {:?})",
                r.step.map_or("default".into(), |s| format!("{s:.5}")),
                r.lighting
            )
        }
        #[allow(unreachable_patterns)]
        other => format!("{other:?}"),
    }
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
