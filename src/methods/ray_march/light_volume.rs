//! Light volumes (`RayMarch(shading: PhongShadows, shadows: LightVolume(resolution: N))`): the
//! transmittance towards a directional light at the vertices of a grid laid in the light's frame
//! over an object's bounds, marched once per light and density by `bake_light_volume.wgsl` (one
//! thread per column, from the light's side away from it) and read trilinearly by the shading
//! instead of a shadow ray per sample: a shaded sample takes its shadow ray's first sample
//! exactly (whether a sample just inside dense matter is lit is decided within a skin far thinner
//! than a cell) and the volume from the end of that step on. This file plans the grid (`grid`), bakes it on the GPU
//! (`bake`) and holds the CPU twins (f64, same names as the kernel and its lookup):
//! [`bake_light_volume`] and [`light_transmittance`].
//!
//! Each vertex stores its transmittance (the shadow ray from the vertex, sampled at `m` sub-steps
//! per layer of the column, with the shared step-corrected opacity) and its openness, the
//! transmittance of one layer of the matter at the vertex itself. The lookup weights the eight
//! vertices around a point by trilinear weight times openness: a shaded sample lies on or just
//! inside matter, and vertices buried in opaque matter (transmittance near 0 whatever the light
//! does) would darken every lit surface by about half; in thin media every openness is near 1 and
//! the lookup is plain trilinear.

use crate::gpu::bindings::ray_march as B;
use glam::{DMat4, DVec3};

use crate::cpu::hypertexture::Model;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::hypertexture::mesh::MeshGrid;
use crate::methods::ray_march::march::{MAX_ALPHA, MIN_TRANSMITTANCE};
use crate::types::{HyperParams, LightVolumeParams};

/// Weight of plain trilinear interpolation in the lookup (where every vertex is buried).
pub(crate) const OPEN_FLOOR: f64 = 1e-3;

/// Most sub-steps per layer: finer sampling along the light than a quarter of a cell changed
/// FLIP against shadow rays by under 2e-4 on the Figure 11 scenes (1 to 22 sub-steps at
/// resolution 64, HQ), at up to 5x the bake's cost.
pub(crate) const MAX_SUB_STEPS: u32 = 4;

/// The light volume's grid for an object whose (enlarged) bounds are `params`' and whose light is
/// `light` (object space, a world unit along the direction towards the light, as
/// `HyperParams::to_local` maps it): `resolution` vertices along the grid's longest axis, cubic
/// cells, `m` sub-steps per layer so that each is at most `shadow_step` (world) long, but at most
/// [`MAX_SUB_STEPS`] and as many as the per-invocation loop budget allows (`loop_budget`
/// iterations, `noises + 1` per density).
pub(crate) fn grid(
    params: &HyperParams,
    light: DVec3,
    resolution: u32,
    shadow_step: f64,
    noises: u32,
    loop_budget: u32,
) -> Result<LightVolumeParams> {
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let (lo, hi) = (v3(params.bounds_min), v3(params.bounds_max));
    // World length per object-space length along the light.
    let per_world = light.length();
    if !(per_world.is_finite() && per_world > 0.0) {
        return Err(Error::Invalid("the light direction has no length in the object's frame".into()));
    }
    let down = -light / per_world;
    let u_dir = down.any_orthonormal_vector();
    let v_dir = down.cross(u_dir);
    let axes = [u_dir, v_dir, down];
    let corners: Vec<DVec3> = (0..8)
        .map(|c| DVec3::new([lo.x, hi.x][c & 1], [lo.y, hi.y][(c >> 1) & 1], [lo.z, hi.z][c >> 2]))
        .collect();
    let range = |a: DVec3| {
        let d: Vec<f64> = corners.iter().map(|c| c.dot(a)).collect();
        (d.iter().copied().fold(f64::INFINITY, f64::min), d.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    };
    let ranges = axes.map(range);
    let longest = ranges.iter().map(|r| r.1 - r.0).fold(0.0, f64::max);
    let spacing = longest / (resolution.max(2) - 1) as f64;
    let counts = ranges.map(|r| (((r.1 - r.0) / spacing).ceil() as u32 + 1).clamp(2, resolution.max(2)));
    let origin = axes[0] * ranges[0].0 + axes[1] * ranges[1].0 + axes[2] * ranges[2].0;
    let layer = spacing / per_world;
    let noises = noises + 1;
    // A column evaluates its vertices' openness and m sub-steps per layer.
    let fits = (loop_budget / counts[2]).saturating_sub(noises) / noises;
    if fits == 0 {
        return Err(Error::Invalid(format!(
            "a light volume of resolution {resolution} with {} noise(s) exceeds one invocation's loop budget: use a \
             smaller resolution",
            noises - 1
        )));
    }
    let m = ((layer / shadow_step).ceil() as u32).clamp(1, fits.min(MAX_SUB_STEPS));
    let [u, v, w] = axes.map(|a| a * spacing);
    let from_grid = DMat4::from_cols(u.extend(0.0), v.extend(0.0), w.extend(0.0), origin.extend(1.0));
    let f = |a: DVec3, w: f64| [a.x as f32, a.y as f32, a.z as f32, w as f32];
    Ok(LightVolumeParams {
        origin: f(origin, layer / m as f64),
        u: f(u, params.bounds_max[3] as f64),
        v: f(v, layer),
        w: f(w, 0.0),
        to_grid: from_grid.inverse().as_mat4().to_cols_array_2d(),
        counts: [counts[0], counts[1], counts[2], m],
    })
}

/// Bytes of a light volume (one word per vertex).
pub(crate) fn bytes(light: &LightVolumeParams) -> u64 {
    4 * light.counts[0] as u64 * light.counts[1] as u64 * light.counts[2] as u64
}

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// The shared step-corrected opacity over `length` (world) at opacity `a` per opacity length.
fn light_alpha(light: &LightVolumeParams, a: f64, length: f64) -> f64 {
    1.0 - (1.0 - a.min(MAX_ALPHA)).powf(length / light.u[3] as f64)
}

/// CPU twin of `bake_light_volume.wgsl`: per vertex (i fastest, then j, then k) its
/// transmittance towards the light and its openness.
pub fn bake_light_volume(model: &Model, light: &LightVolumeParams) -> Vec<[f64; 2]> {
    let [nx, ny, nz, m] = light.counts;
    let opacity = |p: DVec3| model.hyper_color(model.hyper_density(p))[3];
    let (origin, u, v, w) = (v3(light.origin), v3(light.u), v3(light.v), v3(light.w));
    let mut out = vec![[0.0; 2]; (nx * ny * nz) as usize];
    for j in 0..ny {
        for i in 0..nx {
            let base = origin + u * i as f64 + v * j as f64;
            let mut t = 1.0;
            for k in 0..nz {
                let p = base + w * k as f64;
                if k > 0 && t >= MIN_TRANSMITTANCE {
                    for s in 0..m {
                        let q = p - w * ((s as f64 + 0.5) / m as f64);
                        t *= 1.0 - light_alpha(light, opacity(q), light.origin[3] as f64);
                    }
                }
                let open = 1.0 - light_alpha(light, opacity(p), light.v[3] as f64);
                out[((k * ny + j) * nx + i) as usize] = [t, open];
            }
        }
    }
    out
}

/// CPU twin of `light_transmittance` (wgsl/shared/light_volume.wgsl): the transmittance towards
/// the light at `x` (object space) from the eight vertices around it, weighted trilinearly and by
/// their openness.
pub fn light_transmittance(volume: &[[f64; 2]], light: &LightVolumeParams, x: DVec3) -> f64 {
    let to_grid = DMat4::from_cols_array_2d(&light.to_grid.map(|c| c.map(|v| v as f64)));
    let n = [light.counts[0], light.counts[1], light.counts[2]];
    let g = (to_grid * x.extend(1.0)).truncate();
    let g = g.clamp(DVec3::ZERO, DVec3::new(n[0] as f64 - 1.0, n[1] as f64 - 1.0, n[2] as f64 - 1.0));
    let i = [0, 1, 2].map(|a| (g[a] as u32).min(n[a] - 2));
    let f = g - DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64);
    let (mut lit, mut open, mut plain) = (0.0, 0.0, 0.0);
    for c in 0..8u32 {
        let o = [c & 1, (c >> 1) & 1, c >> 2];
        let weight: f64 = (0..3).map(|a| if o[a] == 1 { f[a] } else { 1.0 - f[a] }).product();
        let [t, s] = volume[(((i[2] + o[2]) * n[1] + i[1] + o[1]) * n[0] + i[0] + o[0]) as usize];
        plain += weight * t;
        lit += weight * s * t;
        open += weight * s;
    }
    (lit + OPEN_FLOOR * plain) / (open + OPEN_FLOOR)
}

/// The kernel's words unpacked (transmittance, openness), as `unpack2x16unorm` reads them.
pub fn unpack(words: &[u32]) -> Vec<[f64; 2]> {
    words.iter().map(|w| [(w & 0xffff) as f64 / 65535.0, (w >> 16) as f64 / 65535.0]).collect()
}

/// Runs `bake_transfer.wgsl` and `bake_light_volume.wgsl` for `plan`'s object (`grid`: its mesh
/// grid): the light volume, one word per vertex.
pub(crate) fn bake(
    ctx: &GpuContext,
    plan: &super::RayMarchPlan,
    light: &LightVolumeParams,
    grid: Option<&MeshGrid>,
) -> Result<wgpu::Buffer> {
    use crate::gpu::kernel::ComputeKernel;
    let sources = crate::gpu::sources::Sources::project()?;
    let mut inputs = crate::gpu::Inputs::default();
    plan.add_inputs(ctx, &mut inputs, (1, 1), grid, None, None);
    let bytes = bytes(light);
    let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
    if bytes > limit {
        return Err(Error::Invalid(format!(
            "a light volume of {:?} vertices needs {} MiB in one storage buffer, beyond this adapter's limit of {} MiB",
            &light.counts[..3],
            bytes >> 20,
            limit >> 20
        )));
    }
    let volume = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("light_volume"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    inputs.buffers.insert(B::LIGHT_VOLUME.into(), volume.clone());
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let functions = plan.packed.functions.len() as u32;
    let tables = crate::cpu::bake_transfer::TRANSFER_SIZE as u32;
    ComputeKernel::load(ctx, &sources, "bake/bake_transfer.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [tables, functions, 1],
    )?;
    ComputeKernel::load(ctx, &sources, "ray_march/bake_light_volume.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [light.counts[0], light.counts[1], 1],
    )?;
    ctx.queue.submit([encoder.finish()]);
    ctx.take_errors()?;
    Ok(volume)
}
