//! Host side of the `RayMarch` method (hypertextures, Gilet & Dischler 2009): per object, the
//! packed hypertexture with the camera and march settings (`HyperParams`), its transfer functions
//! for `bake_transfer.wgsl`, how many dispatches of `ray_march.wgsl` a frame needs so that
//! every ray finishes while no dispatch exceeds its work budget, and with depth peeling the
//! object's splat lattice and the segment buffers (`begin_segments.wgsl`, `peel_segments.wgsl`),
//! or with EWA-style splatting the work blocks of `splat_segments.wgsl` and the per-pixel depth
//! slabs `resolve_splats.wgsl` composites.

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::ray_march as knobs;
pub mod light_volume;
pub mod march;
mod object;
pub mod peel_segments;
pub(crate) mod plugin;
pub mod splat_segments;

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::ray_march as B;
use glam::{DMat4, DVec3};

use crate::cpu::bake_transfer::TRANSFER_SIZE;
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::hypertexture::mesh::{self, MeshGrid};
use crate::hypertexture::splats::{self, Lattice, SplatSet, FOOTPRINT_BLOCK};
use crate::hypertexture::{self, Packed};
use crate::methods::ray_march::march::Shade;
use crate::scene::hypertexture::diagonal;
use crate::scene::{Hypertexture, RayMarch, Segments, Shadows};
use crate::types::{HyperParams, LightVolumeParams, MarchState, SegmentParams};

/// What RayMarch brings to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "RayMarch",
    filters: &["RayMarch", "RayMarchPeeling", "RayMarchSplatting"],
    resources: &[
        B::HYPER,
        B::HYPER_NOISES,
        crate::gpu::bindings::bake::TRANSFER_POINTS,
        crate::gpu::bindings::bake::TRANSFER_FUNCTIONS,
        B::TRANSFER_TABLES,
        B::RAY_MARCH_STATE,
        B::MESH_GRID,
        B::MESH_DEPTH,
        B::SEGMENTS,
        B::SEGMENT_BOUNDS,
        B::SURFACE_SPLATS,
        B::INTERIOR_SPLATS,
        B::PEEL_TICKETS,
        B::SPLAT_SLABS,
        B::LIGHT_GRID,
        B::LIGHT_VOLUME,
    ],
    counts: &[
        "ray_march_dispatches",
        "transfer_functions",
        "surface_splats",
        "peel_blocks",
        "peel_phases",
        "interior_splats",
        "splat_blocks",
    ],
    texel_resources: &[],
    gather: None,
};

pub(crate) use object::plan_object;

/// Loop iterations one invocation may run per dispatch. Lavapipe silently ends every loop of an
/// invocation after 65535 iterations in all; a density evaluation costs one iteration per noise
/// plus one of the sample or shadow loop around it.
pub(crate) const LOOP_BUDGET: u32 = 48_000;
/// Most samples of one shadow ray (its step grows when the bounds are longer).
pub(crate) const MAX_SHADOW_SAMPLES: u32 = 256;
/// More dispatches than this means a step far finer than the scene needs.
pub(crate) const MAX_DISPATCHES: u32 = 20_000;

/// One RayMarch object of a frame.
#[derive(Debug, Clone)]
pub struct RayMarchPlan {
    pub(crate) hypertexture: String,
    /// The method as the scene (and the overrides) gave it: what the preview shows and steps.
    pub(crate) method: RayMarch,
    /// The hypertexture's noises, transfer tables and mesh, as the kernels read them.
    pub packed: Packed,
    /// The object's parameters (uniform `hyper`).
    pub params: HyperParams,
    /// Shading switches.
    pub shade: Shade,
    /// The ray step, world units.
    pub step: f64,
    pub(crate) shadow_step: f64,
    /// Dispatches of `ray_march.wgsl` per frame.
    pub dispatches: u32,
    /// World-space corners of the enlarged bounds.
    pub(crate) corners: [DVec3; 8],
    /// Benchmarks: `false` compiles the noises out (override `noise_off`).
    pub(crate) noise: bool,
    /// Depth peeling: its passes and the splat lattice (`None`: the bounds are the segment).
    pub peel: Option<(u32, Lattice)>,
    /// EWA-style splatting: its depth slabs and the splat lattice.
    pub(crate) splatting: Option<(u32, Lattice)>,
    /// The camera and splat lattice as `bake_splats.wgsl` and the peeling kernels see them.
    pub segments: SegmentParams,
    /// `shadows: LightVolume(..)`: the light volume's grid (`None`: shadow rays, or no shadows).
    pub light: Option<LightVolumeParams>,
}

/// `name`: the object's; `node`: its hypertexture's name and frame; `cx`: the frame's camera,
/// light, time and size.
pub fn plan(
    name: &str,
    node: &crate::scene::HyperNode,
    h: &Hypertexture,
    method: &RayMarch,
    cx: &super::PlanCx,
) -> Result<RayMarchPlan> {
    let (camera, light_dir, time, size) = (&cx.view.camera(), cx.light.direction, cx.time, cx.view.size);
    let packed = hypertexture::pack(h);
    let to_world = &node.to_world;
    let corners = h.world_corners(to_world);
    let diagonal = diagonal(&corners);
    let step = method.step();
    let shadow_step = method.shadow_step.unwrap_or(2.0 * step);
    let mut shade = Shade::of(method.shading);
    let resolution = match method.shadows {
        Shadows::LightVolume { resolution } if shade.shadows => Some(resolution),
        _ => None,
    };
    shade.volume = resolution.is_some();
    let evals = LOOP_BUDGET / (packed.noises.len() as u32 + 1);
    let shadow_samples = ((diagonal / shadow_step).ceil() as u32).clamp(1, MAX_SHADOW_SAMPLES);
    let worst = 1 + shade.evaluations(shadow_samples);
    let lattice = |grid| Lattice::new(h.bounds(), packed.tested_shift(), grid);
    let (peel, splatting) = match method.segments {
        Segments::Bounds => (None, None),
        Segments::DepthPeeling { passes, splat_grid } => (Some((passes, lattice(splat_grid))), None),
        Segments::Splatting { slabs, splat_grid } => (None, Some((slabs, lattice(splat_grid)))),
    };
    // Every unfinished ray advances at least `evals / worst` samples per dispatch (segments
    // take a subset of the bounds' samples).
    // An adaptive stride evaluates a sample at most twice (a strided one dropped for matter).
    let adaptive = method.max_stride() > 1;
    let samples = ((diagonal / step).ceil() + 1.0) * if adaptive { 2.0 } else { 1.0 };
    let mut dispatches = (samples / (evals / worst) as f64).ceil() + 1.0;
    if dispatches > MAX_DISPATCHES as f64 {
        return Err(Error::Invalid(format!(
            "object \"{name}\": a RayMarch step of {step} needs {dispatches} dispatches per frame (at most \
             {MAX_DISPATCHES}): use a larger `step`"
        )));
    }
    // Camera-relative world to the node's frame.
    let to_local = to_world.inverse() * DMat4::from_translation(camera.eye);
    let light_local = to_local.transform_vector3(DVec3::from(light_dir.map(|c| c as f64)));
    let to_local = to_local.as_mat4();
    let mut params = packed.params(time);
    params.to_local = to_local.to_cols_array_2d();
    params.right = [camera.right.x as f32, camera.right.y as f32, camera.right.z as f32, camera.near as f32];
    params.up = [camera.up.x as f32, camera.up.y as f32, camera.up.z as f32, camera.far as f32];
    params.bounds_min[3] = step as f32;
    params.march[0] = shadow_step as f32;
    params.march[1] = step as f32;
    params.budget = [evals, shadow_samples, worst, method.max_stride()];
    let from_local = DMat4::from_translation(-camera.eye) * *to_world;
    let scale = [from_local.x_axis, from_local.y_axis, from_local.z_axis]
        .iter()
        .map(|c| c.truncate().length())
        .fold(0.0, f64::max);
    let mut segments = SegmentParams {
        from_local: from_local.as_mat4().to_cols_array_2d(),
        surface: [0.0, scale as f32, 0.0, 0.0],
        counts: [0, 0, peel.map_or(0, |p| p.0), FOOTPRINT_BLOCK],
        ..Default::default()
    };
    if let Some((_, lattice)) = peel.as_ref().or(splatting.as_ref()) {
        lattice.write(&mut segments);
    }
    if let Some((slabs, lattice)) = &splatting {
        segments.splatting = splat_work(name, *slabs, lattice, scale * step.recip(), evals / worst, size)?;
        // The slabs are resolved into the march state: the marcher has nothing to do.
        dispatches = 0.0;
    }
    let light = resolution
        .map(|r| {
            let noises = packed.noises.len() as u32;
            light_volume::grid(&params, light_local, r, shadow_step, noises, LOOP_BUDGET)
                .map_err(|e| Error::Invalid(format!("object \"{name}\": {e}")))
        })
        .transpose()?;
    Ok(RayMarchPlan {
        hypertexture: node.name.clone(),
        method: *method,
        packed,
        params,
        shade,
        step,
        shadow_step,
        dispatches: dispatches as u32,
        corners,
        noise: true,
        peel,
        splatting,
        segments,
        light,
    })
}

/// Bytes of the per-pixel depth slabs of EWA-style splatting (`splat_slabs`): a header of three
/// words and seven per slab (see `wgsl/shared/segments.wgsl`).
pub(crate) fn slab_bytes(size: (u32, u32), slabs: u32) -> u64 {
    size.0 as u64 * size.1 as u64 * (3 + 7 * slabs as u64) * 4
}

/// Largest storage buffer a kernel may bind (lavapipe's limit, and wgpu's default).
const MAX_BINDING_BYTES: u64 = 128 << 20;

/// The work of `splat_segments.wgsl` (`SegmentParams::splatting`): slabs, footprint pixels per
/// block, pieces per chord, samples per piece. A chord through the largest interior splat (a
/// block of 8^3 cells: radius 4 sqrt(3) cells) has at most `2 r / step + 2` samples; one
/// invocation marches at most `samples` (the marcher's per-dispatch budget), so long chords are
/// cut into pieces and short ones share an invocation. `per_length`: object-space length to
/// samples (world scale over step).
fn splat_work(
    name: &str,
    slabs: u32,
    lattice: &Lattice,
    per_length: f64,
    samples: u32,
    size: (u32, u32),
) -> Result<[u32; 4]> {
    let bytes = slab_bytes(size, slabs);
    if bytes > MAX_BINDING_BYTES {
        return Err(Error::Invalid(format!(
            "object \"{name}\": Splatting with {slabs} slabs at {}x{} needs {} MiB of depth slabs (at most {}): use fewer \
             `slabs` or a smaller image",
            size.0,
            size.1,
            bytes >> 20,
            MAX_BINDING_BYTES >> 20
        )));
    }
    let radius = 4.0 * 3f64.sqrt() * lattice.cell;
    let chord = (2.0 * radius * per_length).ceil() as u32 + 2;
    let samples = samples.max(1);
    let pieces = chord.div_ceil(samples);
    let pixels = if pieces > 1 { 1 } else { samples / chord };
    let blocks = splat_blocks(size, pixels, pieces);
    if blocks > MAX_SPLAT_BLOCKS {
        return Err(Error::Invalid(format!(
            "object \"{name}\": Splatting needs {blocks} workgroups per splat at {}x{} (at most {MAX_SPLAT_BLOCKS}): use a \
             larger `step`, a finer `splat_grid`, less shading or a smaller image",
            size.0, size.1
        )));
    }
    Ok([slabs, pixels, pieces, samples])
}

/// Workgroups per splat of `splat_segments.wgsl`: blocks of 64 lanes x `pixels` footprint
/// pixels over the whole screen (the largest footprint), times the pieces of each chord.
pub(crate) fn splat_blocks(size: (u32, u32), pixels: u32, pieces: u32) -> u32 {
    (size.0 * size.1).div_ceil(64 * pixels.max(1)) * pieces
}

/// Workgroups per splat of `splat_segments.wgsl` (along y: the adapters' dispatch limit).
pub(crate) const MAX_SPLAT_BLOCKS: u32 = 65535;

impl RayMarchPlan {
    /// Values of the kernel's override constants.
    pub(crate) fn constants(&self) -> Vec<(String, f64)> {
        let mut c = vec![
            ("phong".into(), self.shade.phong as u32 as f64),
            ("shadows".into(), self.shade.shadows as u32 as f64),
        ];
        if let Some(g) = self.shade.phase {
            c.push(("phase".into(), 1.0));
            c.push(("phase_g".into(), g));
        }
        if !self.noise {
            c.push(("noise_off".into(), 1.0));
        }
        if hypertexture::animated(&self.packed.noises) {
            c.push(("animated".into(), 1.0));
        }
        if self.peel.is_some() {
            c.push(("peeling".into(), 1.0));
        }
        if self.light.is_some() {
            c.push(("volume_shadows".into(), 1.0));
        }
        c
    }

    /// The method as written in metadata and `voltex plan`.
    pub(crate) fn describe(&self) -> String {
        let shading = match (self.shade.phong, self.shade.shadows, self.shade.phase) {
            (_, shadows, Some(g)) => format!("HenyeyGreenstein(g: {g}, shadows: {shadows})"),
            (false, ..) => "None".into(),
            (true, false, _) => "Phong".into(),
            (true, true, _) => "PhongShadows".into(),
        };
        let segments = match (&self.peel, &self.splatting) {
            (Some((passes, l)), _) => format!(
                ", segments: DepthPeeling(passes: {passes}, splat_grid: {}, splat_spacing: {:.6})",
                l.grid, l.cell
            ),
            (_, Some((slabs, l))) => format!(
                ", segments: Splatting(slabs: {slabs}, splat_grid: {}, splat_spacing: {:.6})",
                l.grid, l.cell
            ),
            _ => String::new(),
        };
        let stride = self.params.budget[3];
        let adaptive = if stride > 1 {
            format!(", adaptive: strides up to {stride} steps ({:.6})", stride as f64 * self.step)
        } else {
            String::new()
        };
        let shadows = self.light.map_or(String::new(), |l| {
            format!(
                ", shadows: LightVolume({}x{}x{}, {} sub-step(s) per layer)",
                l.counts[0], l.counts[1], l.counts[2], l.counts[3]
            )
        });
        format!(
            "RayMarch(step: {:.6}, shading: {shading}, shadow_step: {:.6}{segments}{adaptive}{shadows})",
            self.step, self.shadow_step
        )
    }

    /// GPU bytes of the object's buffers (state per pixel included).
    pub(crate) fn bytes(&self, size: (u32, u32)) -> u64 {
        (std::mem::size_of::<HyperParams>()
            + self.packed.noises.len() * 32
            + self.packed.points.len() * 16
            + self.packed.functions.len() * (16 + 4 * TRANSFER_SIZE)) as u64
            + self.packed.grid_bytes()
            + size.0 as u64 * size.1 as u64 * std::mem::size_of::<MarchState>() as u64
            + std::mem::size_of::<SegmentParams>() as u64
            + self.peel.as_ref().map_or(0, |(passes, lattice)| {
                splats::bytes(lattice.cells()) + Self::segment_bytes(size, *passes) + 16
            })
            + self
                .splatting
                .as_ref()
                .map_or(0, |(slabs, lattice)| splats::bytes(lattice.cells()) + slab_bytes(size, *slabs))
            + self.light.as_ref().map_or(0, light_volume::bytes)
    }

    /// The splat lattice of a depth-peeled or splatted object.
    pub(crate) fn lattice(&self) -> Option<Lattice> {
        self.peel.or(self.splatting).map(|(_, l)| l)
    }

    /// The buffers sized per pixel, with their bytes (as `add_inputs` creates them).
    pub(crate) fn per_pixel_buffers(&self, size: (u32, u32)) -> Vec<(&'static str, u64)> {
        let mut out = vec![(
            "ray_march_state",
            size.0 as u64 * size.1 as u64 * std::mem::size_of::<MarchState>() as u64,
        )];
        if let Some((passes, _)) = &self.peel {
            out.push(("segment_bounds", Self::segment_bytes(size, *passes)));
        }
        if let Some((slabs, _)) = &self.splatting {
            out.push(("splat_slabs", slab_bytes(size, *slabs)));
        }
        out
    }

    /// Bytes of the per-pixel segment boundaries (`segment_bounds`).
    fn segment_bytes(size: (u32, u32), passes: u32) -> u64 {
        size.0 as u64 * size.1 as u64 * (2 * passes as u64 + 2) * 4
    }

    /// The splat set's cache key (its object and lattice), for depth-peeled objects.
    pub(crate) fn splat_key(&self) -> Option<u64> {
        let p = &self.params;
        let l = &self.segments;
        self.lattice().map(|_| {
            crate::gpu::cache::key(&(
                "splats",
                self.mesh_grid_key(),
                p.object,
                p.kinds[0],
                p.grid_min,
                p.grid_max,
                l.lattice_min,
                l.lattice,
                l.surface[0],
            ))
        })
    }

    /// Bakes the splat set of a depth-peeled or splatted object (`bake_splats.wgsl`); `grid`: its mesh grid.
    pub fn bake_splats(&self, ctx: &GpuContext, grid: Option<&MeshGrid>) -> Result<SplatSet> {
        let unused = mesh::unused(ctx);
        splats::bake(ctx, "ray_march/bake_splats.wgsl", &self.params, &self.segments, grid.unwrap_or(&unused))
    }

    /// The object grid's cache key, for mesh and point-set objects.
    pub(crate) fn mesh_grid_key(&self) -> Option<u64> {
        self.packed.grid_key()
    }

    /// Bakes the grid of a mesh object (`bake_mesh_grid.wgsl`) or point-set object
    /// (`bake_point_grid.wgsl`).
    pub fn bake_mesh_grid(&self, ctx: &GpuContext) -> Result<Option<MeshGrid>> {
        self.packed.bake_grid(ctx)
    }

    /// The light volume's cache key: its grid and everything the density depends on (not the
    /// camera, the step or the image), for objects with `shadows: LightVolume(..)`.
    pub(crate) fn light_key(&self) -> Option<u64> {
        let mut p = self.params;
        (p.to_local, p.right, p.up, p.budget) = Default::default();
        (p.bounds_min[3], p.march[1]) = (0.0, 0.0);
        let k = &self.packed;
        let key = ("light volume", self.mesh_grid_key(), p, &k.noises, &k.points, &k.functions, self.light?);
        Some(crate::gpu::cache::key(&key))
    }

    /// Buffers, counts and constants of the object's graph instance; `grid`: the baked mesh
    /// grid of a mesh object; `splats`: the splat set of a depth-peeled one; `light`: the light
    /// volume of one with `shadows: LightVolume(..)`.
    pub(crate) fn add_inputs(
        &self,
        ctx: &GpuContext,
        inputs: &mut Inputs,
        size: (u32, u32),
        grid: Option<&MeshGrid>,
        splats: Option<&SplatSet>,
        light: Option<&wgpu::Buffer>,
    ) {
        use crate::gpu::buffers::{storage, uniform};
        // The light volume (stand-ins without one).
        let light_grid = self.light.unwrap_or_default();
        inputs
            .buffers
            .insert(B::LIGHT_GRID.into(), uniform(ctx, "light_grid", bytemuck::bytes_of(&light_grid)));
        let light = light.cloned().unwrap_or_else(|| storage(ctx, "light_volume", &[0u8; 16]));
        inputs.buffers.insert(B::LIGHT_VOLUME.into(), light);
        let grid = grid.cloned().unwrap_or_else(|| mesh::unused(ctx));
        // Segments: the splats and per-pixel boundaries (stand-ins without depth peeling).
        let mut segments = self.segments;
        let mut bounds_bytes = 16;
        if let (Some((passes, _)), Some(set)) = (&self.peel, splats) {
            segments.counts[0] = set.counts[0];
            segments.counts[1] = set.counts[1];
            inputs.buffers.insert(B::SURFACE_SPLATS.into(), set.surface.clone());
            inputs.buffers.insert(B::INTERIOR_SPLATS.into(), set.interior.clone());
            inputs.counts.insert(C::SURFACE_SPLATS.into(), set.counts[0]);
            inputs.counts.insert(C::PEEL_PHASES.into(), 2 * passes);
            inputs.counts.insert(C::PEEL_BLOCKS.into(), (size.0 * size.1).div_ceil(segments.counts[3].max(1)));
            bounds_bytes = Self::segment_bytes(size, *passes);
        }
        let mut slabs_bytes = 16;
        if let (Some((slabs, _)), Some(set)) = (&self.splatting, splats) {
            segments.counts[0] = set.counts[0];
            segments.counts[1] = set.counts[1];
            inputs.buffers.insert(B::INTERIOR_SPLATS.into(), set.interior.clone());
            inputs.counts.insert(C::INTERIOR_SPLATS.into(), set.counts[1]);
            let [_, pixels, pieces, _] = segments.splatting;
            inputs.counts.insert(C::SPLAT_BLOCKS.into(), splat_blocks(size, pixels, pieces));
            slabs_bytes = slab_bytes(size, *slabs);
        }
        inputs.buffers.insert(B::SEGMENTS.into(), uniform(ctx, "segments", bytemuck::bytes_of(&segments)));
        inputs.buffers.insert(B::PEEL_TICKETS.into(), storage(ctx, "peel_tickets", &[0u8; 16]));
        inputs.buffers.insert(B::MESH_GRID.into(), grid.grid);
        inputs.buffers.insert(B::MESH_DEPTH.into(), grid.depth);
        inputs.counts.insert(C::RAY_MARCH_DISPATCHES.into(), self.dispatches);
        inputs.counts.insert(C::TRANSFER_FUNCTIONS.into(), self.packed.functions.len() as u32);
        inputs.constants.extend(self.constants());
        let b = &mut inputs.buffers;
        b.insert(B::HYPER.into(), uniform(ctx, "hyper", bytemuck::bytes_of(&self.params)));
        b.insert(
            "hyper_noises".into(),
            storage(ctx, "hyper_noises", bytemuck::cast_slice(&self.packed.noises)),
        );
        b.insert(
            "transfer_points".into(),
            storage(ctx, "transfer_points", bytemuck::cast_slice(&self.packed.points)),
        );
        b.insert(
            "transfer_functions".into(),
            storage(ctx, "transfer_functions", bytemuck::cast_slice(&self.packed.functions)),
        );
        let words = self.packed.functions.len() * TRANSFER_SIZE;
        for (name, bytes) in [
            ("transfer_tables", words as u64 * 4),
            ("ray_march_state", size.0 as u64 * size.1 as u64 * std::mem::size_of::<MarchState>() as u64),
            ("segment_bounds", bounds_bytes),
            ("splat_slabs", slabs_bytes),
        ] {
            let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(name),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            b.insert(name.into(), buffer);
        }
    }
}

/// What `probe_hypertexture.wgsl` returns: the transfer tables as `bake_transfer.wgsl` filled
/// them, and four vectors per point (see the kernel).
pub struct Probed {
    /// The transfer tables.
    pub tables: Vec<f32>,
    /// Four vectors per probed point.
    pub values: Vec<[f32; 4]>,
}

/// Runs `bake_transfer.wgsl` and then `probe_hypertexture.wgsl` at `points` (object space; w: a
/// noise seed as f32 bits) for this object: the kernels' side of the twin tests.
pub fn probe(ctx: &GpuContext, plan: &RayMarchPlan, points: &[[f32; 4]]) -> Result<Probed> {
    use crate::gpu::buffers::storage;
    use crate::gpu::kernel::ComputeKernel;
    let root = crate::gpu::sources::Sources::project()?;
    let mut inputs = Inputs::default();
    let grid = plan.bake_mesh_grid(ctx)?;
    plan.add_inputs(ctx, &mut inputs, (1, 1), grid.as_ref(), None, None);
    let b = &mut inputs.buffers;
    b.insert(B::PROBE_POINTS.into(), storage(ctx, "probe_points", bytemuck::cast_slice(points)));
    let zeros = vec![0u8; points.len() * 64];
    b.insert(B::PROBE_VALUES.into(), storage(ctx, "probe_values", &zeros));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    let functions = plan.packed.functions.len() as u32;
    ComputeKernel::load(ctx, &root, "bake/bake_transfer.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [TRANSFER_SIZE as u32, functions, 1],
    )?;
    ComputeKernel::load(ctx, &root, "ray_march/probe_hypertexture.wgsl")?.dispatch(
        ctx,
        &mut encoder,
        &inputs,
        [points.len() as u32, 1, 1],
    )?;
    ctx.queue.submit([encoder.finish()]);
    let read = |name: &str| {
        let buffer = &inputs.buffers[name];
        ctx.read_buffer(buffer, 0, buffer.size())
    };
    let tables = bytemuck::pod_collect_to_vec(&read("transfer_tables")?);
    let values = bytemuck::pod_collect_to_vec(&read("probe_values")?);
    ctx.take_errors()?;
    Ok(Probed { tables, values })
}
