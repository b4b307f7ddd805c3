//! Drawing a rendered frame into the preview window (or an offscreen target of the same format):
//! `wgsl/present.wgsl` tonemaps the linear image, or shows the reference or the difference, and
//! draws the overlay text.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};

use crate::error::{Error, Result};
use crate::gpu::sources::Sources;
use crate::gpu::{shader, GpuContext};

/// Uniform of `present.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Default, Pod, Zeroable)]
struct PresentParams {
    mode: u32,
    lines: u32,
    columns: u32,
    scale: u32,
    image_size: [u32; 2],
    target_size: [u32; 2],
    srgb_target: u32,
    _pad: [u32; 3],
}

/// What the window shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The render.
    Image = 0,
    /// The same frame drawn by the ground truth (the exact Reference method): the "reference" view.
    Truth = 1,
    /// The difference between the render and the reference: FLIP's heat map (the image given
    /// is that map, shown as it is).
    Difference = 2,
}

const MAX_COLUMNS: usize = 110;
const MAX_LINES: usize = 16;

pub(crate) struct Presenter {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    text: wgpu::Buffer,
    /// The overlay's glyphs (`FONT` of `wgsl/shared/font.wgsl`), read from the kernel.
    font: wgpu::Buffer,
    pub(crate) format: wgpu::TextureFormat,
}

impl Presenter {
    pub(crate) fn new(ctx: &GpuContext, format: wgpu::TextureFormat) -> Result<Self> {
        let kernel = shader::load_from(&Sources::project()?, "present.wgsl")?;
        let module = ctx.scoped("present.wgsl", || {
            ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("present"),
                source: wgpu::ShaderSource::Naga(Cow::Owned(kernel.module.clone())),
            })
        })?;
        let bindings = crate::gpu::reflect::bindings(&kernel, &["vs_main", "fs_main"])?;
        let entries: Vec<_> = bindings.iter().map(crate::gpu::reflect::layout_entry).collect();
        let layout = ctx.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("present"),
            entries: &entries,
        });
        let pipeline_layout = ctx.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("present"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = ctx.scoped("present pipeline", || {
            ctx.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("present"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        let params = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("present params"),
            size: std::mem::size_of::<PresentParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let text = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("overlay text"),
            size: (MAX_COLUMNS * MAX_LINES * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let glyphs = crate::gpu::reflect::const_u32_array(&kernel, "FONT")
            .ok_or_else(|| Error::Invalid("present.wgsl: expected a `const FONT: array<u32, N>`".into()))?;
        let font = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("overlay font"),
            size: (glyphs.len() * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&font, 0, bytemuck::cast_slice(&glyphs));
        Ok(Self { pipeline, layout, params, text, font, format })
    }

    /// Draws `image` (and `reference` for the reference and difference views; the image itself
    /// otherwise) into `target` of `target_size`, with `lines` of overlay text.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn draw(
        &self,
        ctx: &GpuContext,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
        image: &wgpu::Texture,
        reference: Option<&wgpu::Texture>,
        mode: Mode,
        lines: &[String],
    ) {
        let columns = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0).min(MAX_COLUMNS);
        let lines = &lines[..lines.len().min(MAX_LINES)];
        let mut chars = vec![32u32; (columns * lines.len()).max(1)];
        for (y, line) in lines.iter().enumerate() {
            for (x, c) in line.chars().take(columns).enumerate() {
                chars[y * columns + x] = if c.is_ascii() { c as u32 } else { '?' as u32 };
            }
        }
        let scale = if target_size.0 >= 1400 { 2 } else { 1 };
        let params = PresentParams {
            mode: if reference.is_some() { mode as u32 } else { 0 },
            lines: lines.len() as u32,
            columns: columns as u32,
            scale,
            image_size: [image.width(), image.height()],
            target_size: [target_size.0, target_size.1],
            srgb_target: self.format.is_srgb() as u32,
            _pad: [0; 3],
        };
        ctx.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        ctx.queue.write_buffer(&self.text, 0, bytemuck::cast_slice(&chars));
        let image_view = image.create_view(&Default::default());
        let reference_view = reference.unwrap_or(image).create_view(&Default::default());
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("present"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&image_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&reference_view),
                },
                wgpu::BindGroupEntry { binding: 3, resource: self.text.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: self.font.as_entire_binding() },
            ],
        });
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("present"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
        ctx.queue.submit([enc.finish()]);
    }
}
