//! Host side of the bake kernels: a texel source becomes an RGBA texel volume (3D texture,
//! premultiplied `rgba8unorm`; level 0 only, which every method samples at full resolution,
//! unless `ViewSlices(lod: Auto)` asks for its MIP levels), plus a normal volume when a
//! per-pixel-lit object uses it. Only texels some object draws are baked, each (texel, lighting) pair once.

pub mod derived;
pub mod hypertexture;
pub(crate) mod occupancy;
pub mod shadow;
pub mod texel_layers;
pub mod volume;

use crate::gpu::sources::Sources;

use crate::cpu::bake::PackedShapes;
use crate::error::{Error, Result};
use crate::gpu::budget::{Allocation, AllocationKind, Driver};
use crate::gpu::buffers::{storage, uniform};
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::GpuContext;
use crate::gpu::Inputs;
use crate::mesh::shape::{GridSpec, MeshShape};
use crate::types::{BakeParams, HeightImageParams, HeightfieldParams, MeshTexelParams};
use glam::DVec3;

/// What a bake kernel evaluates.
#[derive(Debug)]
pub enum BakeSource {
    /// A union of implicit shapes (`bake_implicit.wgsl`).
    Implicit(PackedShapes),
    /// A periodic Perlin height field (`bake_heightfield.wgsl`).
    Heightfield(HeightfieldParams),
    /// A height field from an image and its heights (`bake_height_image.wgsl`).
    HeightImage(HeightImageParams, Heights),
    /// A slice stack's texels (16-bit premultiplied RGBA), uploaded at the volume's precision.
    Stack(StackTexels),
    /// A pattern mesh sampled at the voxel centres (`bake_mesh_grid.wgsl`), then coloured.
    Mesh(MeshTexel),
    /// A hypertexture sampled at the voxel centres of a box of its object space.
    Hypertexture(Box<hypertexture::HyperTexel>),
    /// A volume (an OpenVDB grid) sampled at the voxel centres of a box of its world space.
    Volume(Box<volume::VolumeTexel>),
}

/// A mesh texel's pattern, where its voxel centres lie, and its colouring; shown in `Debug` (the
/// bake cache's key) by the mesh's digest.
#[derive(Clone)]
pub struct MeshTexel {
    /// The pattern mesh, shared between the bakes that use it.
    pub shape: std::sync::Arc<MeshShape>,
    /// The grid the mesh is sampled on (bounds, samples per axis, fill or shell).
    pub spec: GridSpec,
    /// Colour, extent and mode of the texel made from the grid.
    pub params: MeshTexelParams,
}

impl MeshTexel {
    /// Voxel `(i, j, k)` of a texel of `n` voxels per axis samples the centre of its cell of the
    /// box `lo..hi`: the grid's vertices from half a voxel inside the box. A shell (`fill:
    /// false`) needs no inside, so the grid skips the parity test.
    pub fn new(
        shape: std::sync::Arc<MeshShape>,
        lo: DVec3,
        hi: DVec3,
        n: [u32; 3],
        color: [f32; 3],
        opacity: f32,
        fill: bool,
    ) -> Self {
        let e = hi - lo;
        let voxel = e / DVec3::from_array(n.map(f64::from));
        let spec = GridSpec { lo: lo + voxel / 2.0, hi: hi - voxel / 2.0, n, parity: fill };
        let params = MeshTexelParams {
            color: [color[0], color[1], color[2], opacity],
            // w: the largest voxel side, so that a shell has no gaps along any axis.
            extent: [e.x as f32, e.y as f32, e.z as f32, voxel.max_element() as f32],
            mode: [0, fill as u32, 0, 0],
        };
        MeshTexel { shape, spec, params }
    }
}

impl std::fmt::Debug for MeshTexel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshTexel(mesh {:016x}, {:?}, {:?})", self.shape.hash, self.spec, self.params)
    }
}

/// The heights of a height image (row-major from the top row), shown in `Debug` (and so in the
/// bake cache's content key) by a digest of the values rather than the values themselves.
#[derive(Clone)]
pub struct Heights(pub std::sync::Arc<Vec<f32>>);

impl std::fmt::Debug for Heights {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.0.iter().for_each(|v| v.to_bits().hash(&mut h));
        write!(f, "Heights({} values, digest {:016x})", self.0.len(), h.finish())
    }
}

/// A slice stack's 16-bit premultiplied RGBA, shown in `Debug` by a digest, like [`Heights`].
#[derive(Clone)]
pub struct StackTexels(pub std::sync::Arc<Vec<u16>>);

impl std::fmt::Debug for StackTexels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.0.hash(&mut h);
        write!(f, "Bytes({}, digest {:016x})", self.0.len(), h.finish())
    }
}

/// One texel to bake: its resolution, its source and what the methods drawing it need.
#[derive(Debug)]
pub struct BakeRequest {
    /// Voxels along s, t and w.
    pub resolution: [u32; 3],
    /// What the kernel evaluates.
    pub source: BakeSource,
    /// Write unshaded albedo and a normal volume instead of baked shading.
    pub per_pixel: bool,
    /// Texel-space direction towards the light, and the ambient term.
    pub light: [f32; 3],
    /// Light a voxel keeps without direct light, in [0, 1].
    pub ambient: f32,
    /// What the methods drawing it derive from the volume in the same bake (see
    /// [`BakeRequest::derive`]).
    pub derived: derived::Derivations,
    /// The texel's layers too (`ViewSlices(lod: Auto)`): its w slices as f16 2D arrays whose
    /// MIP levels filter s and t only (`texel_layers`), of the volume and of the normals.
    pub layers: bool,
    /// Self-shadowing baked into the colour after the source's bake (`shadow_texel.wgsl`).
    pub shadow: Option<shadow::Shadow>,
}

impl BakeRequest {
    /// The kernels the bake runs (under `wgsl/`), so that `plan` can check them before any GPU
    /// work: the same files [`Baker::bake`] loads.
    pub fn kernels(&self) -> Vec<&'static str> {
        let mut k = match &self.source {
            BakeSource::Implicit(_) => vec!["bake/bake_implicit.wgsl"],
            BakeSource::Heightfield(_) => vec!["bake/bake_heightfield.wgsl"],
            BakeSource::HeightImage(..) => vec!["bake/bake_height_image.wgsl"],
            BakeSource::Stack(_) => vec![],
            BakeSource::Mesh(_) => vec!["bake/bake_mesh_grid.wgsl", "bake/bake_mesh_texel.wgsl"],
            BakeSource::Hypertexture(h) => {
                let mut k = vec!["bake/bake_transfer.wgsl", "bake/bake_hypertexture.wgsl"];
                k.extend(h.packed.grid_kernel());
                k
            }
            BakeSource::Volume(_) => vec!["bake/bake_volume.wgsl"],
        };
        if self.shadow.is_some() {
            k.push(shadow::KERNEL);
        }
        k.extend(self.derived.0.iter().flat_map(|d| d.kernels()));
        if self.layers {
            k.extend([texel_layers::COPY_KERNEL, texel_layers::MIP_KERNEL]);
        }
        k
    }
}

/// A baked texel: its premultiplied RGBA volume, its normals and its slice images.
#[derive(Clone)]
pub struct Baked {
    /// The texel volume, with its MIP levels when the request asked for them.
    pub volume: wgpu::Texture,
    /// The normal volume (1x1x1 when `per_pixel` is off: the binding exists, nothing is stored).
    pub normals: wgpu::Texture,
    /// The volume's and the normals' layers when the request asked for them (else 1x1, one
    /// layer: the bindings exist, nothing is stored).
    pub layers: [wgpu::Texture; 2],
    /// What the request's methods derived from the volume (see [`BakeRequest::derive`]).
    pub derived: derived::MadeProducts,
}

impl crate::gpu::cache::GpuBytes for Baked {
    fn gpu_bytes(&self) -> u64 {
        let layers: u64 = self.layers.iter().map(|l| l.gpu_bytes()).sum();
        self.volume.gpu_bytes() + self.normals.gpu_bytes() + layers + self.derived.gpu_bytes()
    }
}

impl BakeRequest {
    /// Asks for the product `D` derived from the volume, made by `make` from the one already
    /// asked for (another object drawing the same texel), which it replaces.
    pub(crate) fn derive<D: derived::Derived>(&mut self, make: impl FnOnce(Option<&D>) -> D) {
        let all = &mut self.derived.0;
        let at = all.iter().position(|d| (d.as_ref() as &dyn std::any::Any).is::<D>());
        let before = at.and_then(|i| (all[i].as_ref() as &dyn std::any::Any).downcast_ref::<D>());
        let made: std::sync::Arc<dyn derived::Derived> = std::sync::Arc::new(make(before));
        match at {
            Some(i) => all[i] = made,
            None => all.push(made),
        }
    }

    /// GPU memory of the bake of `texel`, by item (`voltex plan`).
    pub(crate) fn memory(&self, texel: &str) -> Vec<(String, u64)> {
        let [x, y, z] = self.resolution;
        let normals = if self.per_pixel { " + normals" } else { "" };
        let mut out = vec![(
            format!("texel {texel} {x}x{y}x{z} rgba8{normals}"),
            bytes(self.resolution, self.per_pixel),
        )];
        if self.layers {
            let copies = if self.per_pixel { 2 } else { 1 };
            out.push((
                format!("texel {texel} layers ({z} of {x}x{y}, s and t MIP levels){normals} rgba16f"),
                copies * texel_layers::bytes(self.resolution),
            ));
        }
        out.extend(self.derived.0.iter().map(|d| d.memory(texel, self.resolution)));
        out
    }

    /// Each texture and large buffer of the bake of `texel`, for the checks against the limits.
    pub(crate) fn allocations(&self, texel: &str) -> Vec<Allocation> {
        let res = self.resolution;
        let voxels = res.iter().map(|&r| r as u64).product::<u64>();
        let driver = Driver::Texel(texel.to_string());
        let volume = |what: String, size| Allocation {
            what,
            bytes: voxels * 4,
            shape: AllocationKind::Texture3d { size },
            driver: driver.clone(),
        };
        let mut out = vec![volume(format!("texel \"{texel}\"'s volume"), res)];
        if self.shadow.is_some() {
            out.push(volume(format!("texel \"{texel}\"'s shadowed volume"), res));
        }
        if self.per_pixel {
            out.push(volume(format!("texel \"{texel}\"'s normal volume"), res));
        }
        if self.layers {
            let names: &[&str] = if self.per_pixel { &["layers", "normal layers"] } else { &["layers"] };
            for name in names {
                out.push(Allocation {
                    what: format!("texel \"{texel}\"'s {name}"),
                    bytes: texel_layers::bytes(res),
                    shape: AllocationKind::Texture2d { size: [res[0], res[1]], layers: res[2] },
                    driver: driver.clone(),
                });
            }
        }
        if let BakeSource::Volume(v) = &self.source {
            let size = volume::atlas_size(volume::slots(&v.grid));
            let texels = size.iter().map(|&s| s as u64).product::<u64>();
            out.push(Allocation {
                what: format!("texel \"{texel}\"'s volume atlas ({} bricks)", v.grid.bricks()),
                bytes: texels * if v.grid.color.is_some() { 12 } else { 4 },
                shape: AllocationKind::Texture3d { size },
                driver: driver.clone(),
            });
        }
        if let BakeSource::Mesh(_) = self.source {
            out.push(Allocation {
                what: format!("texel \"{texel}\"'s mesh grid"),
                bytes: voxels * 16,
                shape: AllocationKind::Buffer { storage: true },
                driver: driver.clone(),
            });
        }
        out.extend(self.derived.0.iter().flat_map(|d| d.allocations(texel, res, &driver)));
        out
    }

    /// The bake's lines in `voltex plan`: size, kernels and lighting.
    pub(crate) fn describe(&self, texel: &str) -> String {
        let [x, y, z] = self.resolution;
        let kind = match self.source {
            BakeSource::Implicit(_) => "bake/bake_implicit.wgsl",
            BakeSource::Heightfield(_) => "bake/bake_heightfield.wgsl",
            BakeSource::HeightImage(..) => "bake/bake_height_image.wgsl",
            BakeSource::Stack(_) => "slice stack (uploaded)",
            BakeSource::Mesh(_) => "bake_mesh_grid.wgsl + bake_mesh_texel.wgsl",
            BakeSource::Hypertexture(ref h) if h.packed.mesh.is_some() => {
                "bake_transfer.wgsl + bake_mesh_grid.wgsl + bake_hypertexture.wgsl"
            }
            BakeSource::Hypertexture(ref h) if h.packed.point_set.is_some() => {
                "bake_transfer.wgsl + bake_point_grid.wgsl + bake_hypertexture.wgsl"
            }
            BakeSource::Hypertexture(_) => "bake_transfer.wgsl + bake_hypertexture.wgsl",
            BakeSource::Volume(_) => "bake/bake_volume.wgsl",
        };
        let lighting = if self.per_pixel { "per-pixel (albedo + normals)" } else { "baked" };
        let mut s = format!("  {texel:<16} {x}x{y}x{z}  {kind}  lighting {lighting}\n");
        if self.layers {
            s += "  (and its layers: layer_texel_volume.wgsl, then mip_layers.wgsl per s,t level)\n";
        }
        if let Some(sh) = &self.shadow {
            let [lx, ly, lz] = sh.toward_light.map(|c| c as f64);
            let l = glam::DVec3::new(lx, ly, lz).normalize();
            s += &format!(
                "  (and its baked shadows: {} towards ({:.3}, {:.3}, {:.3}), extinction {}, ambient {})\n",
                shadow::KERNEL,
                l.x,
                l.y,
                l.z,
                sh.extinction,
                sh.ambient
            );
        }
        s.extend(self.derived.0.iter().map(|d| d.describe()));
        s
    }
}

/// Bytes a bake allocates on the GPU for its volume, plus normals at the same resolution.
pub(crate) fn bytes(res: [u32; 3], per_pixel: bool) -> u64 {
    let volume = res.iter().map(|&r| r as u64).product::<u64>() * 4;
    volume + if per_pixel { volume } else { 4 }
}

/// Each kernel with the hash of its source, so that a baker kept across the preview's rebuilds
/// reloads a kernel whose file (or include) changed.
type Slot = Option<(u64, ComputeKernel)>;

/// The bake kernels, loaded once and reused for every texel.
pub struct Baker {
    implicit: Slot,
    heightfield: Slot,
    height_image: Slot,
    mesh: Slot,
    hyper: Slot,
    transfer: Slot,
    /// The kernels of derived products (see `derived::Kernels`).
    derived: Vec<(&'static str, Slot)>,
    volume: Slot,
    layer_copy: Slot,
    /// `mip_layers`: the slice images' and the texel layers' MIP levels.
    layer_mip: Slot,
    shadow: Slot,
    sources: Sources,
    /// `Rgba32Float` for [`Baker::full_precision`], else `Rgba8Unorm`.
    format: wgpu::TextureFormat,
}

impl Baker {
    /// A baker whose kernels are looked up in `sources` (usually [`Sources::project`]).
    pub fn new(sources: &Sources) -> Self {
        Self {
            implicit: None,
            heightfield: None,
            height_image: None,
            mesh: None,
            hyper: None,
            transfer: None,
            derived: Vec::new(),
            volume: None,
            layer_copy: None,
            layer_mip: None,
            shadow: None,
            sources: sources.clone(),
            format: wgpu::TextureFormat::Rgba8Unorm,
        }
    }

    /// A baker whose volumes hold f32 RGBA: the same kernels, their `volume` declared
    /// `rgba32float` instead of `rgba8unorm`, so nothing is quantised (`voltex export`). The
    /// normal volume stays `rgba8snorm`.
    pub fn full_precision(sources: &Sources) -> Self {
        Self { format: wgpu::TextureFormat::Rgba32Float, ..Self::new(sources) }
    }

    /// The format of the texel volumes this baker makes.
    pub(crate) fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    fn kernel<'a>(
        slot: &'a mut Slot,
        ctx: &GpuContext,
        sources: &Sources,
        name: &str,
        format: wgpu::TextureFormat,
    ) -> Result<&'a mut ComputeKernel> {
        let shared = crate::gpu::shader::load_shared(sources, name)?;
        let hash = shared.source_hash;
        if slot.as_ref().is_none_or(|(h, _)| *h != hash) {
            let mut kernel = (*shared).clone();
            let writes_volume = crate::gpu::reflect::bindings(&kernel, &["main"])?.iter().any(|b| {
                b.name == "volume"
                    && matches!(b.kind, crate::gpu::reflect::BindingKind::StorageTexture { .. })
            });
            if format == wgpu::TextureFormat::Rgba32Float && writes_volume {
                kernel = kernel.with_storage_format("volume", naga::StorageFormat::Rgba32Float)?;
            }
            *slot = Some((hash, ComputeKernel::new(ctx, kernel)?));
        }
        Ok(&mut slot.as_mut().unwrap().1)
    }

    /// Bakes `req` on the GPU: the source's kernel, then what the request asks for (shadows, MIP
    /// levels, slice images); a volume beyond the adapter's 3D texture limit is an error.
    pub fn bake(&mut self, ctx: &GpuContext, req: &BakeRequest) -> Result<Baked> {
        let max3d = ctx.limits.max_texture_dimension_3d;
        if req.resolution.iter().any(|&r| r == 0 || r > max3d) {
            return Err(Error::Gpu(format!(
                "texel resolution {:?} is beyond this adapter's 3D texture limit of {max3d}",
                req.resolution
            )));
        }
        let volume = volume_texture(ctx, "texel volume", req.resolution, self.format);
        let normals_res = if req.per_pixel { req.resolution } else { [1, 1, 1] };
        let normals = volume_texture(ctx, "texel normals", normals_res, wgpu::TextureFormat::Rgba8Snorm);
        let params = crate::cpu::bake::bake_params(req.resolution, 0, req.light, req.ambient);
        let mut inputs = Inputs::default();
        inputs.constants.push(("per_pixel_lighting".into(), req.per_pixel as u32 as f64));
        inputs.views.insert("volume".into(), level_view(&volume, 0));
        inputs.views.insert("normals".into(), level_view(&normals, 0));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let root = self.sources.clone();
        match &req.source {
            BakeSource::Implicit(packed) => {
                let params = BakeParams {
                    resolution: [
                        params.resolution[0],
                        params.resolution[1],
                        params.resolution[2],
                        packed.shape_count,
                    ],
                    ..params
                };
                inputs
                    .buffers
                    .insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&params)));
                inputs
                    .buffers
                    .insert("shapes".into(), storage(ctx, "shapes", bytemuck::cast_slice(&packed.shapes)));
                inputs
                    .buffers
                    .insert("balls".into(), storage(ctx, "balls", bytemuck::cast_slice(&packed.balls)));
                Self::kernel(&mut self.implicit, ctx, &root, "bake/bake_implicit.wgsl", self.format)?
                    .dispatch(ctx, &mut encoder, &inputs, req.resolution)?;
            }
            BakeSource::Heightfield(hf) => {
                inputs
                    .buffers
                    .insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&params)));
                inputs
                    .buffers
                    .insert("heightfield".into(), uniform(ctx, "heightfield", bytemuck::bytes_of(hf)));
                Self::kernel(&mut self.heightfield, ctx, &root, "bake/bake_heightfield.wgsl", self.format)?
                    .dispatch(ctx, &mut encoder, &inputs, req.resolution)?;
            }
            BakeSource::HeightImage(hi, heights) => {
                inputs
                    .buffers
                    .insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&params)));
                inputs
                    .buffers
                    .insert("height_image".into(), uniform(ctx, "height_image", bytemuck::bytes_of(hi)));
                inputs.buffers.insert(
                    "heights".into(),
                    storage(ctx, "heights", bytemuck::cast_slice(heights.0.as_slice())),
                );
                Self::kernel(&mut self.height_image, ctx, &root, "bake/bake_height_image.wgsl", self.format)?
                    .dispatch(ctx, &mut encoder, &inputs, req.resolution)?;
            }
            BakeSource::Stack(texels) => {
                let [w, h, d] = req.resolution;
                if texels.0.len() != (w * h * d * 4) as usize || req.per_pixel {
                    return Err(Error::Invalid(format!(
                        "a {w}x{h}x{d} slice stack with baked shading was expected (got {} values{})",
                        texels.0.len(),
                        if req.per_pixel { ", per-pixel lighting" } else { "" }
                    )));
                }
                // Stacks are read at 16 bits: rounded to the volume's 8 bits, or as floats.
                let (floats, bytes): (Vec<f32>, Vec<u8>);
                let (data, texel_bytes) = match self.format {
                    wgpu::TextureFormat::Rgba32Float => {
                        floats = texels.0.iter().map(|&v| v as f32 / 65535.0).collect();
                        (bytemuck::cast_slice(&floats), 16)
                    }
                    _ => {
                        bytes = texels.0.iter().map(|&v| ((v as u32 * 255 + 32767) / 65535) as u8).collect();
                        (bytes.as_slice(), 4)
                    }
                };
                ctx.queue.write_texture(
                    volume.as_image_copy(),
                    data,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(w * texel_bytes),
                        rows_per_image: Some(h),
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: d },
                );
            }
            BakeSource::Mesh(m) => {
                if req.resolution != m.spec.n {
                    return Err(Error::Invalid(format!(
                        "a mesh texel of {:?} samples was expected, the request is {:?}",
                        m.spec.n, req.resolution
                    )));
                }
                let grid = crate::hypertexture::mesh::bake(ctx, &m.shape, &m.spec)?;
                inputs
                    .buffers
                    .insert("bake_params".into(), uniform(ctx, "bake_params", bytemuck::bytes_of(&params)));
                inputs
                    .buffers
                    .insert("mesh_texel".into(), uniform(ctx, "mesh_texel", bytemuck::bytes_of(&m.params)));
                inputs.buffers.insert("mesh_grid".into(), grid.grid);
                let colors = grid.colors.unwrap_or_else(|| storage(ctx, "mesh_colors", &[0u8; 16]));
                inputs.buffers.insert("mesh_colors".into(), colors);
                inputs.constants.push(("colored".into(), m.shape.colors.is_some() as u32 as f64));
                Self::kernel(&mut self.mesh, ctx, &root, "bake/bake_mesh_texel.wgsl", self.format)?
                    .dispatch(ctx, &mut encoder, &inputs, req.resolution)?;
            }
            BakeSource::Hypertexture(ht) => {
                let format = self.format;
                let transfer =
                    Self::kernel(&mut self.transfer, ctx, &root, "bake/bake_transfer.wgsl", format)?;
                let hyper = Self::kernel(&mut self.hyper, ctx, &root, "bake/bake_hypertexture.wgsl", format)?;
                ht.bake(ctx, (transfer, hyper), &mut encoder, &mut inputs, params)?;
            }
            BakeSource::Volume(v) => {
                let kernel =
                    Self::kernel(&mut self.volume, ctx, &root, "bake/bake_volume.wgsl", self.format)?;
                v.bake(ctx, kernel, &mut encoder, &mut inputs, params)?;
            }
        }
        let volume = match &req.shadow {
            Some(sh) => {
                let kernel = Self::kernel(&mut self.shadow, ctx, &root, shadow::KERNEL, self.format)?;
                shadow::apply(ctx, kernel, &mut encoder, &volume, sh)?
            }
            None => volume,
        };
        let layers = match req.layers {
            true => {
                let format = self.format;
                let copy = Self::kernel(&mut self.layer_copy, ctx, &root, texel_layers::COPY_KERNEL, format)?;
                let mip = Self::kernel(&mut self.layer_mip, ctx, &root, texel_layers::MIP_KERNEL, format)?;
                let mut make = |t: &wgpu::Texture, label| {
                    texel_layers::record(ctx, (&mut *copy, &mut *mip), &mut encoder, t, label)
                };
                [make(&volume, "texel layers")?, make(&normals, "texel normal layers")?]
            }
            false => [0, 1].map(|_| texel_layers::texture(ctx, "no texel layers", [1, 1], 1, 1)),
        };
        let mut kernels = derived::Kernels { slots: &mut self.derived, sources: &root, format: self.format };
        let made = (req.derived.0.iter())
            .map(|d| d.record(ctx, &mut kernels, &mut encoder, &volume, req.resolution))
            .collect::<Result<Vec<_>>>()?;
        ctx.queue.submit([encoder.finish()]);
        ctx.take_errors()?;
        Ok(Baked { volume, normals, layers, derived: derived::MadeProducts(made) })
    }
}

fn volume_texture(
    ctx: &GpuContext,
    label: &str,
    res: [u32; 3],
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: res[0], height: res[1], depth_or_array_layers: res[2] },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// A view of one mip level.
pub(crate) fn level_view(t: &wgpu::Texture, level: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        base_mip_level: level,
        mip_level_count: Some(1),
        ..Default::default()
    })
}
