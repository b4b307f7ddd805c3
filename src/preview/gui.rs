//! egui in the preview window: window events in (egui-winit), the panel's triangles out, drawn
//! over the frame by egui-wgpu into the window surface or a recording target of its format.

use std::time::Duration;

use winit::window::Window;

use crate::gpu::GpuContext;

pub(crate) struct Gui {
    pub(crate) ctx: egui::Context,
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    primitives: Vec<egui::ClippedPrimitive>,
    free: Vec<egui::TextureId>,
    pixels_per_point: f32,
}

impl Gui {
    pub(crate) fn new(window: &Window, device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let ctx = egui::Context::default();
        let max_side = device.limits().max_texture_dimension_2d as usize;
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_side),
        );
        let renderer = egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        Gui { ctx, state, renderer, primitives: Vec::new(), free: Vec::new(), pixels_per_point: 1.0 }
    }

    /// A new device (after a device loss): the renderer and its textures are made again.
    pub(crate) fn reset(&mut self, device: &wgpu::Device, format: wgpu::TextureFormat) {
        self.renderer = egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        self.ctx = egui::Context::default();
        self.primitives.clear();
        self.free.clear();
    }

    /// Hands a window event to egui: whether egui used it, and whether it wants a repaint.
    pub(crate) fn on_event(
        &mut self,
        window: &Window,
        event: &winit::event::WindowEvent,
    ) -> egui_winit::EventResponse {
        self.state.on_window_event(window, event)
    }

    /// Runs the panel's code for one frame and uploads the textures it made; returns how soon
    /// egui wants the next frame (`None`: not until an event).
    pub(crate) fn run(
        &mut self,
        ctx: &GpuContext,
        window: &Window,
        ui: impl FnMut(&mut egui::Ui),
    ) -> Option<Duration> {
        for id in self.free.drain(..) {
            self.renderer.free_texture(&id);
        }
        let input = self.state.take_egui_input(window);
        let mut out = self.ctx.run_ui(input, ui);
        self.state.handle_platform_output(window, out.platform_output);
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        self.free = out.textures_delta.free.iter().copied().collect();
        out.textures_delta.clear();
        self.pixels_per_point = out.pixels_per_point;
        self.primitives = self.ctx.tessellate(out.shapes, out.pixels_per_point);
        out.viewport_output
            .get(&egui::ViewportId::ROOT)
            .map(|v| v.repaint_delay)
            .filter(|d| *d < Duration::from_secs(3600))
    }

    /// Draws the last frame's panel over `target` (of `size` pixels).
    pub(crate) fn paint(&mut self, ctx: &GpuContext, target: &wgpu::TextureView, size: (u32, u32)) {
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: self.pixels_per_point,
        };
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let extra =
            self.renderer.update_buffers(&ctx.device, &ctx.queue, &mut enc, &self.primitives, &screen);
        {
            let pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("panel"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.render(&mut pass.forget_lifetime(), &self.primitives, &screen);
        }
        ctx.queue.submit(extra.into_iter().chain([enc.finish()]));
    }
}
