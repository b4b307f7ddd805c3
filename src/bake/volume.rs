//! Volumes on the GPU: a grid's brick table and atlases uploaded (shared by volume objects and
//! volume texels), and the host side of `bake_volume.wgsl`, which bakes a box of a volume into a
//! texel, with its CPU twin.

use std::sync::Arc;

use glam::{DMat4, DVec3};

use crate::error::Result;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::{GpuContext, Inputs};
use crate::types::{BakeParams, VolumeParams};
use crate::vdb::sparse::{BRICK, BRICK_VALUES};
use crate::vdb::SparseVolume;

/// The atlases' brick slots are laid out for 3D textures of this side (WebGPU's guaranteed
/// `max_texture_dimension_3d`), so a plan holds on every adapter.
pub(crate) const ATLAS_SIDE: u32 = 2048;

/// A grid's brick table and atlases on the GPU.
#[derive(Clone)]
pub(crate) struct Uploaded {
    pub(crate) table: wgpu::Buffer,
    pub(crate) density: wgpu::TextureView,
    pub(crate) color: wgpu::TextureView,
}

impl crate::gpu::cache::GpuBytes for Uploaded {
    fn gpu_bytes(&self) -> u64 {
        self.table.gpu_bytes() + self.density.texture().gpu_bytes() + self.color.texture().gpu_bytes()
    }
}

impl Uploaded {
    /// Binds the table and atlases by their kernel names.
    pub(crate) fn bind(&self, inputs: &mut Inputs) {
        inputs.buffers.insert("volume_table".into(), self.table.clone());
        inputs.views.insert("volume_density".into(), self.density.clone());
        inputs.views.insert("volume_color".into(), self.color.clone());
    }
}

/// Brick slots of `grid`'s atlases per axis.
pub(crate) fn slots(grid: &SparseVolume) -> [u32; 3] {
    SparseVolume::atlas_slots(grid.bricks(), ATLAS_SIDE)
}

/// Atlas texture size: slots times the brick side.
pub(crate) fn atlas_size(slots: [u32; 3]) -> [u32; 3] {
    slots.map(|s| s * BRICK as u32)
}

/// The parts of `VolumeParams` that describe `grid` itself: table and atlas layout.
pub(crate) fn grid_params(grid: &SparseVolume, params: &mut VolumeParams) {
    let s = slots(grid);
    params.origin = [grid.origin.x, grid.origin.y, grid.origin.z, 0];
    params.table = [grid.top.x, grid.top.y, grid.top.z, grid.color.is_some() as u32];
    params.atlas = [s[0], s[1], s[2], 0];
}

/// Uploads `grid`'s table and bricks (value (x, y, z) of brick b at atlas texel
/// `slot(b) * 9 + (x, y, z)`, slots x fastest).
pub(crate) fn upload(ctx: &GpuContext, grid: &SparseVolume) -> Uploaded {
    let slots = slots(grid);
    let size = atlas_size(slots);
    let texels = size.iter().map(|&s| s as usize).product::<usize>();
    let place = |b: usize, i: usize| {
        let (x, y, z) = (i % BRICK, i / BRICK % BRICK, i / (BRICK * BRICK));
        let s = [
            b % slots[0] as usize,
            b / slots[0] as usize % slots[1] as usize,
            b / (slots[0] * slots[1]) as usize,
        ];
        let p = [s[0] * BRICK + x, s[1] * BRICK + y, s[2] * BRICK + z];
        (p[2] * size[1] as usize + p[1]) * size[0] as usize + p[0]
    };
    let mut density = vec![0f32; texels];
    for (i, v) in grid.density.iter().enumerate() {
        density[place(i / BRICK_VALUES, i % BRICK_VALUES)] = *v;
    }
    let table = crate::gpu::buffers::storage(ctx, "volume_table", bytemuck::cast_slice(&grid.table));
    let density = texture(
        ctx,
        "volume_density",
        size,
        wgpu::TextureFormat::R32Float,
        bytemuck::cast_slice(&density),
        4,
    );
    let color = match &grid.color {
        Some(c) => {
            let mut rgba = vec![[half::f16::ZERO; 4]; texels];
            for (i, v) in c.iter().enumerate() {
                rgba[place(i / BRICK_VALUES, i % BRICK_VALUES)] =
                    [v[0], v[1], v[2], 1.0].map(half::f16::from_f32);
            }
            texture(
                ctx,
                "volume_color",
                size,
                wgpu::TextureFormat::Rgba16Float,
                bytemuck::cast_slice(&rgba),
                8,
            )
        }
        None => texture(ctx, "volume_color", [1; 3], wgpu::TextureFormat::Rgba16Float, &[0; 8], 8),
    };
    Uploaded { table, density, color }
}

fn texture(
    ctx: &GpuContext,
    label: &str,
    size: [u32; 3],
    format: wgpu::TextureFormat,
    bytes: &[u8],
    texel: u32,
) -> wgpu::TextureView {
    let extent = wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: size[2] };
    let t = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    ctx.queue.write_texture(
        t.as_image_copy(),
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size[0] * texel),
            rows_per_image: Some(size[1]),
        },
        extent,
    );
    t.create_view(&Default::default())
}

/// A volume texel: a box of a volume's world space mapped onto texel space.
#[derive(Clone)]
pub struct VolumeTexel {
    pub(crate) grid: Arc<SparseVolume>,
    /// Texel space to index space, the medium and the opacity length (see `bake_volume.wgsl`).
    pub(crate) params: VolumeParams,
}

impl std::fmt::Debug for VolumeTexel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "VolumeTexel(grid {:016x}, {:?})", self.grid.hash, self.params)
    }
}

impl VolumeTexel {
    /// The box `bounds` of the grid's world space (default: the box its density fills) as
    /// texel space; `albedo`, `density_scale` and the texel's `opacity_length`.
    pub fn new(
        grid: Arc<SparseVolume>,
        bounds: Option<(DVec3, DVec3)>,
        albedo: [f32; 3],
        density_scale: f64,
        opacity_length: f32,
    ) -> Self {
        let (lo, hi) = bounds.unwrap_or_else(|| {
            let c = grid.world_corners(&DMat4::IDENTITY);
            c.iter().fold((c[0], c[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
        });
        let to_index =
            grid.index_to_world.inverse() * DMat4::from_translation(lo) * DMat4::from_scale(hi - lo);
        let mut params = VolumeParams {
            to_index: to_index.as_mat4().to_cols_array_2d(),
            box_lo: [0.0, 0.0, 0.0, opacity_length],
            medium: [albedo[0], albedo[1], albedo[2], density_scale as f32],
            ..Default::default()
        };
        grid_params(&grid, &mut params);
        VolumeTexel { grid, params }
    }

    /// Runs `bake_volume.wgsl` into the texel volume bound in `inputs`.
    pub(crate) fn bake(
        &self,
        ctx: &GpuContext,
        kernel: &mut ComputeKernel,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &mut Inputs,
        params: BakeParams,
    ) -> Result<()> {
        use crate::gpu::buffers::uniform;
        upload(ctx, &self.grid).bind(inputs);
        inputs.buffers.insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&params)));
        inputs
            .buffers
            .insert("volume_params".into(), uniform(ctx, "volume_params", bytemuck::bytes_of(&self.params)));
        let res = [params.resolution[0], params.resolution[1], params.resolution[2]];
        kernel.dispatch(ctx, encoder, inputs, res)
    }
}

/// CPU twin of `bake_volume.wgsl`: voxel `id`'s premultiplied colour and opacity, and its normal
/// (texel space), before the 8-bit rounding.
pub fn bake_volume(
    t: &VolumeTexel,
    resolution: [u32; 3],
    id: [u32; 3],
    light: [f32; 4],
    per_pixel: bool,
) -> ([f64; 4], [f64; 3]) {
    use crate::cpu::bake::{gradient_normal, shade_lambert};
    let m = DMat4::from_cols_array_2d(&t.params.to_index.map(|c| c.map(f64::from)));
    let u = DVec3::new(
        (id[0] as f64 + 0.5) / resolution[0] as f64,
        (id[1] as f64 + 0.5) / resolution[1] as f64,
        (id[2] as f64 + 0.5) / resolution[2] as f64,
    );
    let x = m.transform_point3(u);
    let medium = t.params.medium;
    let sigma = medium[3] as f64 * t.grid.density_at(x);
    let alpha = 1.0 - (-sigma * t.params.box_lo[3] as f64).exp();
    if alpha <= 0.0 {
        return ([0.0; 4], [0.0, 0.0, 1.0]);
    }
    let e = 0.5;
    let g = |a: DVec3| t.grid.density_at(x + a * e) - t.grid.density_at(x - a * e);
    let gi = DVec3::new(g(DVec3::X), g(DVec3::Y), g(DVec3::Z));
    let gt = glam::DMat3::from_mat4(m).transpose() * gi;
    let normal = gradient_normal((-gt).as_vec3().to_array());
    let c = t.grid.color_at(x);
    let mut rgb = [0, 1, 2].map(|k| (medium[k] as f64 * c[k]) as f32);
    if !per_pixel {
        rgb = shade_lambert(rgb, normal, light);
    }
    let rgb = rgb.map(|v| (v as f64).clamp(0.0, 1.0) * alpha);
    ([rgb[0], rgb[1], rgb[2], alpha], normal.map(f64::from))
}
