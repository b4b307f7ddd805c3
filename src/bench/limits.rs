//! `bench --limits`: the adapter's own rates, measured in the same run as the benchmark so that
//! a method's speed can be read as a share of what the adapter can do at all: blended fill
//! (`bench_fill.wgsl`: full-screen layers into Rgba32Float, premultiplied over, one trilinear
//! fetch of an rgba8 3D texture per fragment, as ViewSlices draws), the cost of small triangles
//! beyond their fragments (the same kernel with each layer cut into small squares), trilinear
//! texture samples in a compute kernel (`bench_texture.wgsl`) and 3D simplex noise
//! (`bench_simplex.wgsl`). Each is the median wall time of 5 runs after one that compiles, over
//! the work it did.

use std::borrow::Cow;
use std::time::Instant;

use super::json::Limits;
use crate::error::Result;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;

/// Target size and layers of the blend test; threads and samples of the texture test.
const BLEND_SIZE: u32 = 512;
const BLEND_LAYERS: u32 = 64;
/// Pixels on a side of the triangle test's squares, and its layers.
const TRIANGLE_CELL: u32 = 8;
const TRIANGLE_LAYERS: u32 = 16;
const TEXTURE_THREADS: u32 = 256;
const TEXTURE_SAMPLES: u32 = 256;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median seconds of `run` (submit and wait), after one untimed run.
fn time(ctx: &GpuContext, mut run: impl FnMut(&mut wgpu::CommandEncoder)) -> Result<f64> {
    let mut times = Vec::new();
    for i in 0..6 {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        run(&mut encoder);
        let t = Instant::now();
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        if i > 0 {
            times.push(t.elapsed().as_secs_f64());
        }
    }
    ctx.take_errors()?;
    Ok(median(times))
}

/// A 64^3 rgba8 volume of a smooth pattern, its view and a trilinear sampler.
fn volume(ctx: &GpuContext) -> (wgpu::TextureView, wgpu::Sampler) {
    let n = 64u32;
    let texels: Vec<u8> = (0..n * n * n)
        .flat_map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            [(x * 4) as u8, (y * 4) as u8, (z * 4) as u8, ((x ^ y ^ z) * 4) as u8]
        })
        .collect();
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bench_volume"),
        size: wgpu::Extent3d { width: n, height: n, depth_or_array_layers: n },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        texture.as_image_copy(),
        &texels,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * n), rows_per_image: Some(n) },
        wgpu::Extent3d { width: n, height: n, depth_or_array_layers: n },
    );
    let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("bench_sampler"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    (texture.create_view(&Default::default()), sampler)
}

fn module(ctx: &GpuContext, name: &str) -> Result<wgpu::ShaderModule> {
    let kernel = crate::gpu::shader::load_from(&Sources::project()?, name)?;
    ctx.scoped(name, || {
        ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Naga(Cow::Owned(kernel.module.clone())),
        })
    })
}

/// Seconds to draw `instances` layers of `cells` x `cells` squares (`bench_fill.wgsl`) into a
/// BLEND_SIZE square Rgba32Float target, blended premultiplied-over.
fn fill_seconds(ctx: &GpuContext, cells: u32, instances: u32) -> Result<f64> {
    let kernel = "bench/bench_fill.wgsl";
    let constants = [("layers", instances as f64), ("cells", cells as f64)];
    let (view, sampler) = volume(ctx);
    let module = module(ctx, kernel)?;
    let format = wgpu::TextureFormat::Rgba32Float;
    let options = || wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let pipeline = ctx.scoped(kernel, || {
        ctx.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(kernel),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: options(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: options(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        })
    })?;
    let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(kernel),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
        ],
    });
    let target = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bench_target"),
        size: wgpu::Extent3d { width: BLEND_SIZE, height: BLEND_SIZE, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let target = target.create_view(&Default::default());
    time(ctx, |encoder| {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(kernel),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..6 * cells * cells, 0..instances);
    })
}

/// Blended fragments per second (see the module's comment).
pub(crate) fn blend_rate(ctx: &GpuContext) -> Result<f64> {
    let seconds = fill_seconds(ctx, 1, BLEND_LAYERS)?;
    Ok((BLEND_SIZE * BLEND_SIZE * BLEND_LAYERS) as f64 / seconds)
}

/// Triangles per second beyond their fragments' blending: layers of small triangles (two per
/// TRIANGLE_CELL-pixel square, 32 pixels each; ViewSlices' slice triangles on torus_egg average
/// 22 to 360 pixels from 128x128 to 512x512) drawn as the blend test draws, less the time
/// `blend_rate` gives their fragments. `None` where the triangles cost under 5% of that draw (an
/// adapter whose setup is nearly free).
pub(crate) fn triangle_rate(ctx: &GpuContext, blend_rate: f64) -> Result<Option<f64>> {
    let cells = BLEND_SIZE / TRIANGLE_CELL;
    let seconds = fill_seconds(ctx, cells, TRIANGLE_LAYERS)?;
    let triangles = (2 * cells * cells * TRIANGLE_LAYERS) as f64;
    let setup = seconds - (BLEND_SIZE * BLEND_SIZE * TRIANGLE_LAYERS) as f64 / blend_rate;
    Ok((setup > 0.05 * seconds).then(|| triangles / setup))
}

/// Trilinear 3D texture samples per second in a compute kernel.
pub(crate) fn texture_rate(ctx: &GpuContext) -> Result<f64> {
    let (view, sampler) = volume(ctx);
    let module = module(ctx, "bench/bench_texture.wgsl")?;
    let constants = [("samples", TEXTURE_SAMPLES as f64)];
    let pipeline = ctx.scoped("bench_texture", || {
        ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("bench_texture"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        })
    })?;
    let out = crate::gpu::buffers::storage(
        ctx,
        "bench_out",
        &vec![0u8; (TEXTURE_THREADS * TEXTURE_THREADS * 4) as usize],
    );
    let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bench_texture"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
            wgpu::BindGroupEntry { binding: 2, resource: out.as_entire_binding() },
        ],
    });
    let seconds = time(ctx, |encoder| {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(TEXTURE_THREADS / 8, TEXTURE_THREADS / 8, 1);
    })?;
    Ok((TEXTURE_THREADS * TEXTURE_THREADS * TEXTURE_SAMPLES) as f64 / seconds)
}

/// All the rates. Compute first: lavapipe's compute timing is only trusted before any render
/// pass (wall clock here, but keep the habit).
pub(crate) fn measure(ctx: &GpuContext) -> Result<Limits> {
    let texture_samples_per_s = texture_rate(ctx)?;
    let noise_per_s = super::hyper::noise_rate(ctx)?;
    let blend_fragments_per_s = blend_rate(ctx)?;
    let triangles_per_s = triangle_rate(ctx, blend_fragments_per_s)?;
    Ok(Limits { blend_fragments_per_s, triangles_per_s, texture_samples_per_s, noise_per_s })
}

/// Seconds the adapter needs at least for `triangles` carrying `fragments`: their setup at the
/// triangle rate (where it was measurable) and their fragments at the blend rate.
pub(crate) fn bound_seconds(l: &Limits, triangles: f64, fragments: f64) -> f64 {
    fragments / l.blend_fragments_per_s + l.triangles_per_s.map_or(0.0, |r| triangles / r)
}

/// The triangle rate as text: "M/s", or why there is none.
pub(crate) fn triangles(l: &Limits) -> String {
    l.triangles_per_s
        .map_or("not measurable (under 5% of the draw)".into(), |r| format!("{:.2} M/s", r / 1e6))
}

pub(crate) fn describe(l: &Limits) -> String {
    format!(
        "adapter limits (same run, median of 5 after warm-up, wall clock): blended fragments into Rgba32Float with one \
         3D texture fetch {:.0} M/s; small triangles beyond their fragments {}; trilinear 3D texture samples {:.0} M/s; \
         3D simplex noise {:.0} M/s",
        l.blend_fragments_per_s / 1e6,
        triangles(l),
        l.texture_samples_per_s / 1e6,
        l.noise_per_s / 1e6
    )
}
