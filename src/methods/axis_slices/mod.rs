//! Host side of Meyer & Neyret's axis-aligned slicing (1998): per object the slicing parameters,
//! the prisms sorted back to front and the buffers of `choose_axis_slices`, `scan_axis_slices`,
//! `emit_axis_slices` and `draw_axis_slices`. The slice images are derived in the texel bake (`slice_images`).

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::axis_slices as knobs;
mod object;
pub mod slice_images;
pub(crate) mod plugin;
pub mod twin;

pub(crate) use object::plan;

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::axis_slices as B;
use slice_images::AxisBaked;
use crate::error::{Error, Result};
use crate::mesh::shell::Shell;
use crate::scene::{AxisSlices, DrawOrder, SliceBlend, SliceDirections};
use crate::types::{AxisParams, AxisVertex, Prism};
use twin::AxisFrame;

/// What AxisSlices brings to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "AxisSlices",
    filters: &["AxisSlices", "AxisSlicesBinary", "AxisSlicesBlended", "AxisSlicesBySlice"],
    resources: &[
        B::SHELL_VERTICES,
        B::PRISMS,
        B::AXIS_PARAMS,
        B::AXIS_OCCUPANCY,
        B::AXIS_CHOICES,
        B::AXIS_DRAW_ARGS,
        B::AXIS_VERTICES,
        B::AXIS_LAYER_COUNTS,
        B::AXIS_SLICES_S,
        B::AXIS_SLICES_T,
        B::AXIS_SLICES_W,
        B::AXIS_SAMPLER,
        B::AXIS_SAMPLER_SIDE,
    ],
    counts: &[C::PRISMS, C::AXIS_TRIANGLES],
    texel_resources: &[B::AXIS_SLICES_S, B::AXIS_SLICES_T, B::AXIS_SLICES_W],
    gather: None,
};

/// Slice-vertex budget of one object: the storage-binding size every WebGPU adapter offers.
pub(crate) const MAX_VERTEX_BYTES: u64 = 128 << 20;

/// One AxisSlices object of a frame (Meyer & Neyret 1998): its parameters and prism order.
pub struct AxisPlan {
    /// The object's slicing parameters, as `choose_axis_slices.wgsl` reads them.
    pub params: AxisParams,
    /// The shell's prisms sorted back to front by centre distance (the draw order of texels).
    pub prisms: Vec<Prism>,
    /// Their bounding spheres, in that order.
    spheres: Vec<[f32; 4]>,
    /// Slice-vertex capacity: every prism at its finest level in its largest direction.
    pub capacity: u64,
    pub(crate) blended: bool,
    /// Drawn grouped by slice image (`draw_order: Slices`): the vertex buffer holds a second,
    /// grouped copy after the emitted slices.
    pub(crate) grouped: bool,
    pub(crate) method: AxisSlices,
}

impl AxisPlan {
    /// `forward` is the camera's unit forward, `focal` the focal length in pixels.
    pub(crate) fn new(
        shell: &Shell,
        m: &AxisSlices,
        resolution: [u32; 3],
        forward: [f32; 3],
        focal: f64,
        object: &str,
    ) -> Result<Self> {
        let directions = match m.directions {
            SliceDirections::Three => 0b111,
            SliceDirections::Horizontal => 0b100,
        };
        let mut params = AxisParams {
            resolution: [resolution[0], resolution[1], resolution[2], shell.prisms.len() as u32],
            criteria: [m.depth as f32, m.pixels as f32, m.max_angle.to_radians() as f32, focal as f32],
            forward: [forward[0], forward[1], forward[2], eye_inside(shell) as u32 as f32],
            flags: [directions, 0, m.occlusion_culling as u32, m.empty_culling as u32],
        };
        let distance = |i: usize| {
            let c = shell.spheres[i];
            c[0] * c[0] + c[1] * c[1] + c[2] * c[2]
        };
        let mut order: Vec<usize> = (0..shell.prisms.len()).collect();
        order.sort_by(|&a, &b| distance(b).total_cmp(&distance(a)));
        let prisms = order.iter().map(|&i| shell.prisms[i]).collect();
        let spheres = order.iter().map(|&i| shell.spheres[i]).collect();
        let capacity: u64 = (0..shell.prisms.len()).map(|i| finest_vertices(shell, i, &params)).sum();
        let bytes = capacity * std::mem::size_of::<AxisVertex>() as u64;
        if bytes > MAX_VERTEX_BYTES {
            return Err(Error::Invalid(format!(
                "object `{object}`: axis slices need up to {:.0} MiB of slice vertices, beyond the limit of {} \
                 MiB per object; use a coarser texel or fewer uv tiles per triangle",
                bytes as f64 / 1048576.0,
                MAX_VERTEX_BYTES >> 20
            )));
        }
        params.flags[1] = capacity.max(3) as u32;
        Ok(Self {
            params,
            prisms,
            spheres,
            capacity: capacity.max(3),
            blended: m.blend == SliceBlend::Blended,
            grouped: m.draw_order == DrawOrder::Slices,
            method: *m,
        })
    }

    /// The prisms in draw order with the shell's vertices (what the kernels read).
    pub fn shell(&self, shell: &Shell) -> Shell {
        Shell::from_parts(shell.vertices.clone(), self.prisms.clone(), self.spheres.clone())
    }
}

/// Whether the eye (the origin of the camera-relative shell) is inside a prism of the shell: the
/// kernels then slice the prisms whose layer holds the eye at the finest level and split the slab
/// holding the eye at it (`eye_in_layer` in `wgsl/shared/axis_slices.wgsl`).
pub(crate) fn eye_inside(shell: &Shell) -> bool {
    use crate::cpu::prism_map::{inverse, PrismCorners};
    use glam::{DVec3, Vec4Swizzles};
    shell.prisms.iter().zip(&shell.spheres).any(|(p, &s)| {
        let s = glam::Vec4::from(s);
        if s.xyz().length() > s.w {
            return false;
        }
        let v = |i: usize, top: bool| {
            let x = &shell.vertices[p.vertices[i] as usize];
            let c = if top { x.top } else { x.bottom };
            DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
        };
        let corners = PrismCorners {
            bottom: [v(0, false), v(1, false), v(2, false)],
            top: [v(0, true), v(1, true), v(2, true)],
            ids: [p.vertices[0], p.vertices[1], p.vertices[2]],
        };
        inverse(DVec3::ZERO, &corners).is_some()
    })
}

/// Upper bound of a prism's vertices: its finest level in whichever allowed direction has most,
/// plus one slice (the slab holding the eye is drawn as two).
fn finest_vertices(shell: &Shell, index: usize, params: &AxisParams) -> u64 {
    let f = AxisFrame::of_shell(shell, index);
    (0..3)
        .filter(|&d| params.flags[0] & (1 << d) != 0)
        .map(|d| {
            let r = params.resolution[d];
            if d == 2 {
                return 3 * (r as u64 + 1);
            }
            let c = f.uv.map(|uv| uv[d]);
            let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
            let span = ((hi - lo) * r as f32).ceil() as u64 + 2;
            6 * (span.min(twin::MAX_PRISM_SLICES as u64) + 1)
        })
        .max()
        .unwrap_or(0)
}

/// Adds the buffers, views and samplers of one object's axis slicing to `inputs`.
pub(crate) fn add_inputs(
    ctx: &crate::gpu::GpuContext,
    inputs: &mut crate::gpu::Inputs,
    shell: &Shell,
    plan: &AxisPlan,
    baked: &AxisBaked,
) {
    use crate::gpu::buffers::{storage, uniform};
    let buffer = |label: &str, size: u64, extra| crate::gpu::buffers::work_buffer(ctx, label, size, extra);
    let b = &mut inputs.buffers;
    b.insert(B::AXIS_PARAMS.into(), uniform(ctx, "axis_params", bytemuck::bytes_of(&plan.params)));
    b.insert(B::SHELL_VERTICES.into(), storage(ctx, "shell_vertices", bytemuck::cast_slice(&shell.vertices)));
    b.insert(B::PRISMS.into(), storage(ctx, "prisms", bytemuck::cast_slice(&plan.prisms)));
    b.insert(B::AXIS_OCCUPANCY.into(), baked.occupancy.clone());
    let choices = plan.prisms.len() as u64 * std::mem::size_of::<crate::types::AxisChoice>() as u64;
    b.insert(B::AXIS_CHOICES.into(), buffer("axis_choices", choices, wgpu::BufferUsages::empty()));
    b.insert(B::AXIS_DRAW_ARGS.into(), buffer("axis_draw_args", 16, wgpu::BufferUsages::INDIRECT));
    let bytes = plan.capacity * std::mem::size_of::<AxisVertex>() as u64;
    let copies = if plan.grouped { 2 } else { 1 };
    b.insert(B::AXIS_VERTICES.into(), buffer("axis_vertices", copies * bytes, wgpu::BufferUsages::empty()));
    // One counter per slice image (the stride: the most layers of any direction); a stand-in
    // when not grouped.
    let stride = plan.params.resolution[..3]
        .iter()
        .map(|&r| slice_images::array_layers(r))
        .max()
        .unwrap_or(1);
    let counters = if plan.grouped { 3 * stride as u64 } else { 3 };
    b.insert(
        "axis_layer_counts".into(),
        buffer("axis_layer_counts", 4 * counters, wgpu::BufferUsages::empty()),
    );
    if plan.grouped {
        inputs.counts.insert(C::AXIS_TRIANGLES.into(), (plan.capacity / 3) as u32);
    }
    for (name, t) in ["axis_slices_s", "axis_slices_t", "axis_slices_w"].iter().zip(&baked.arrays) {
        let view = t.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        inputs.views.insert(name.to_string(), view);
    }
    // Trilinear between the MIP levels of `mipmaps: true` (the kernel picks each sample's level).
    let mipmap_filter = match plan.method.mipmaps {
        true => wgpu::MipmapFilterMode::Linear,
        false => wgpu::MipmapFilterMode::Nearest,
    };
    let sampler = |label: &str, v: wgpu::AddressMode| {
        ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some(label),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: v,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter,
            ..Default::default()
        })
    };
    inputs.samplers.insert(B::AXIS_SAMPLER.into(), sampler("axis_sampler", wgpu::AddressMode::Repeat));
    inputs
        .samplers
        .insert(B::AXIS_SAMPLER_SIDE.into(), sampler("axis_sampler_side", wgpu::AddressMode::ClampToEdge));
    inputs.counts.insert(C::PRISMS.into(), plan.prisms.len() as u32);
    inputs.constants.push(("blended_slices".into(), plan.blended as u32 as f64));
    inputs.constants.push(("grouped_slices".into(), plan.grouped as u32 as f64));
    inputs.constants.push(("mipmapped_slices".into(), plan.method.mipmaps as u32 as f64));
}

/// Reads back the per-prism choices and the drawn vertices after a frame (tests, `bench`).
pub fn read_back(
    ctx: &crate::gpu::GpuContext,
    inputs: &crate::gpu::Inputs,
    prisms: usize,
) -> Result<(Vec<crate::types::AxisChoice>, Vec<AxisVertex>)> {
    let choices = ctx.read_buffer(&inputs.buffers["axis_choices"], 0, (prisms * 32) as u64)?;
    let args = ctx.read_buffer(&inputs.buffers["axis_draw_args"], 0, 16)?;
    let drawn = bytemuck::pod_read_unaligned::<u32>(&args[..4]) as u64;
    let vertices = if drawn > 0 {
        ctx.read_buffer(
            &inputs.buffers["axis_vertices"],
            0,
            drawn * std::mem::size_of::<AxisVertex>() as u64,
        )?
    } else {
        Vec::new()
    };
    Ok((bytemuck::pod_collect_to_vec(&choices), bytemuck::pod_collect_to_vec(&vertices)))
}
