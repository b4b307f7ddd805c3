//! One ViewSlices object of a frame: its plane sweep in chunks, and what the renderer asks of it.

use crate::gpu::bindings::view_slices as B;
use super::lod::{self, LodChoice};
use super::{add_inputs, check_budget, check_capacity, chunks, sweep, tile_buffers, tiles, SliceChunk};
use crate::bake::texel_layers;
use crate::error::{Error, Result};
use crate::gpu::{buffers, Inputs};
use crate::methods::{texels, InputCx, MethodPlan, ObjectPlan, PartDecl, PlanCx};
use crate::scene::{Compositor, Lighting, Lod, Method, ViewSlices, MAX_PLANES};
use crate::types::{Prism, SliceParams, SliceVertex, VertexFrame};

/// One ViewSlices object of a frame: its plane sweep in chunks, and what the renderer asks of it.
pub struct ViewSlicesPlan {
    /// The whole sweep, and its chunks (consecutive planes with their own buffers).
    pub sweep: SliceParams,
    pub(crate) chunks: Vec<SliceChunk>,
    pub(crate) trivial_reject: bool,
    pub(crate) compositor: Compositor,
    /// `Tiles`: the tile-list entries of each chunk.
    pub tile_entries: Vec<u32>,
    /// The rendered size the tiles were planned for.
    pub(crate) size: (u32, u32),
    /// The scene's plane count (`lod: Auto`: the most it may draw).
    pub(crate) max_planes: u32,
    /// What `lod: Auto` chose; `None` when off.
    pub lod: Option<LodChoice>,
}

/// Plans `object`'s sweep, its texel bake and its lighting.
pub fn plan(cx: &mut PlanCx, object: &mut ObjectPlan, m: &ViewSlices) -> Result<()> {
    let planes = m.planes;
    if planes == 0 || planes > MAX_PLANES {
        return Err(Error::Invalid(format!("{planes} planes: expected a plane count in 1..={MAX_PLANES}")));
    }
    object.per_pixel = m.lighting == Lighting::PerPixel;
    let texel = object.object.texel.clone().unwrap_or_default();
    let bake = texels::bake_index(cx.scene, &texel, object.per_pixel, cx.light, cx.time, cx.bakes)?;
    object.bake = Some(bake);
    let forward = cx.view.forward_f32();
    let lod = (m.lod == Lod::Auto).then(|| {
        let res = cx.bakes[bake].request.resolution;
        let levels = crate::bake::texel_layers::mip_levels(res);
        lod::choose(&object.shell, forward, cx.view.focal, cx.view.near, res, levels, planes)
    });
    // Each fragment samples the level of its own footprint from the texel's layers.
    if lod.is_some() {
        cx.bakes[bake].request.layers = true;
    }
    let sweep = sweep(&object.shell, forward, lod.map_or(planes, |c| c.planes), cx.view.near);
    let chunks = chunks(&object.shell, &sweep);
    check_budget(&chunks, &object.object.name, planes)?;
    object.frames = object.per_pixel.then(|| object.object.prepared().frames(&object.object.surface).to_vec());
    let tile_entries = match m.compositor {
        Compositor::Raster => Vec::new(),
        Compositor::Tiles => {
            let view_proj = cx.view.frame_params(cx.scene, cx.view.size, cx.light).view_proj;
            chunks
                .iter()
                .map(|c| {
                    let bound = tile_buffers::entry_bound(&object.shell, &c.params, &view_proj, cx.view.size);
                    tile_buffers::entry_capacity(bound, cx.tile_entries)
                })
                .collect()
        }
    };
    object.methods.push(Box::new(ViewSlicesPlan {
        sweep,
        chunks,
        trivial_reject: m.trivial_reject,
        compositor: m.compositor,
        tile_entries,
        size: cx.view.size,
        max_planes: planes,
        lod,
    }));
    Ok(())
}

fn lighting(object: &ObjectPlan) -> &'static str {
    if object.per_pixel {
        "PerPixel"
    } else {
        "Baked"
    }
}

impl MethodPlan for ViewSlicesPlan {
    fn parts(&self) -> Vec<PartDecl> {
        let compositor = match self.compositor {
            Compositor::Raster => "ViewSlicesRaster",
            Compositor::Tiles => "ViewSlicesTiles",
        };
        (0..self.chunks.len())
            .map(|c| PartDecl { filters: vec!["ViewSlices", compositor], order: c as u32 })
            .collect()
    }

    fn constants(&self) -> Vec<(String, f64)> {
        vec![("trivial_reject".into(), self.trivial_reject as u32 as f64)]
    }

    fn check_limits(&self, object: &ObjectPlan, limits: &wgpu::Limits) -> Result<()> {
        let max = limits.max_storage_buffer_binding_size;
        for c in &self.chunks {
            check_capacity(c.capacity, max, &object.object.name, c.params.plane_count)?;
        }
        for (c, &entries) in self.chunks.iter().zip(&self.tile_entries) {
            let params = tiles::tile_params(self.size, c.params.plane_count, entries);
            for (buffer, bytes) in tile_buffers::tile_bytes(&params, c.capacity) {
                if bytes > max {
                    return Err(Error::Gpu(format!(
                        "object `{}`: the Tiles compositor's `{buffer}` needs {:.1} MiB in one binding at \
                         {}x{}, beyond this adapter's storage-binding limit of {:.1} MiB; use a smaller \
                         output or `compositor: Raster`",
                        object.object.name,
                        bytes as f64 / 1048576.0,
                        self.size.0,
                        self.size.1,
                        max as f64 / 1048576.0
                    )));
                }
            }
        }
        Ok(())
    }

    fn add_inputs(&self, cx: &InputCx, object: &ObjectPlan, part: usize, inputs: &mut Inputs) {
        let c = &self.chunks[part];
        add_inputs(cx.ctx, inputs, &object.shell, &c.params, c.capacity, self.trivial_reject);
        if let Some(&entries) = self.tile_entries.get(part) {
            tile_buffers::add_inputs(cx.ctx, inputs, cx.size, c.params.plane_count, entries, c.capacity);
        }
        // Bound even when unlit per pixel (the binding exists in the kernel): one entry then.
        let frames = object.frames.as_deref().unwrap_or(&[VertexFrame { ds: [0.0; 4], dt: [0.0; 4] }]);
        let frames = buffers::storage(cx.ctx, "vertex_frames", bytemuck::cast_slice(frames));
        inputs.buffers.insert(B::VERTEX_FRAMES.into(), frames);
        if let Some(b) = object.bake {
            let baked = &cx.baked[b];
            inputs.views.insert(B::VOLUME.into(), baked.volume.create_view(&Default::default()));
            inputs.views.insert(B::NORMALS.into(), baked.normals.create_view(&Default::default()));
            inputs.views.insert(B::VOLUME_LAYERS.into(), texel_layers::array_view(&baked.layers[0]));
            inputs.views.insert(B::NORMAL_LAYERS.into(), texel_layers::array_view(&baked.layers[1]));
        }
        inputs.constants.push(("layered_texel".into(), self.lod.is_some() as u32 as f64));
    }

    fn summary(&self, object: &ObjectPlan) -> String {
        let lod = self.choices(object).map(|c| format!(" {c}")).unwrap_or_default();
        format!(
            "ViewSlices planes {} spacing {:.4} trivial_reject {} lighting {} compositor {:?}{lod}, {} chunk(s)",
            self.sweep.plane_count,
            self.sweep.spacing,
            self.trivial_reject,
            lighting(object),
            self.compositor,
            self.chunks.len()
        )
    }

    fn choices(&self, _object: &ObjectPlan) -> Option<String> {
        self.lod.map(|c| {
            format!(
                "lod Auto ({} of {} planes, texel level {}: a pixel {:.4} against voxels {:.4} to {:.4} at the nearest depth)",
                c.planes, self.max_planes, c.level, c.pixel, c.voxel_min, c.voxel_max
            )
        })
    }

    fn metadata(&self, object: &ObjectPlan) -> String {
        let lod = match self.lod {
            Some(c) => format!(", lod: Auto, max planes: {}, texel level: {}", self.max_planes, c.level),
            None => String::new(),
        };
        format!(
            "ViewSlices(planes: {}, trivial_reject: {}, lighting: {}, compositor: {:?}{lod})",
            self.sweep.plane_count,
            self.trivial_reject,
            lighting(object),
            self.compositor
        )
    }

    fn memory(&self, object: &ObjectPlan, size: (u32, u32)) -> Vec<(String, u64)> {
        let name = &object.object.name;
        let shell = &object.shell;
        let cap: u64 = self.chunks.iter().map(|c| c.capacity).sum();
        let mut tile_memory = 0u64;
        for (c, &entries) in self.chunks.iter().zip(&self.tile_entries) {
            let params = tiles::tile_params(size, c.params.plane_count, entries);
            tile_memory += tile_buffers::tile_bytes(&params, c.capacity).iter().map(|b| b.1).sum::<u64>();
        }
        let mut items = vec![
            (
                format!("object {name}: shell ({} prisms)", shell.prisms.len()),
                (shell.vertices.len() * 32 + shell.prisms.len() * (std::mem::size_of::<Prism>() + 16)) as u64,
            ),
            (
                format!(
                    "object {name}: slice vertices (capacity {cap} in {} chunk(s)) + {} plane cursors",
                    self.chunks.len(),
                    self.sweep.plane_count
                ),
                cap * std::mem::size_of::<SliceVertex>() as u64
                    + self.sweep.plane_count as u64 * 4
                    + self.chunks.len() as u64 * (16 + 48),
            ),
        ];
        if tile_memory > 0 {
            let entries: u64 = self.tile_entries.iter().map(|&e| e as u64).sum();
            items.push((
                format!("object {name}: Tiles compositor (triangles, texel coordinates, cursors, {entries} list entries, layer)"),
                tile_memory,
            ));
        }
        items
    }

    fn scene_method(&self, object: &ObjectPlan) -> Option<Method> {
        let lighting = if object.per_pixel { Lighting::PerPixel } else { Lighting::Baked };
        Some(Method::ViewSlices(ViewSlices {
            planes: self.max_planes,
            trivial_reject: self.trivial_reject,
            lighting,
            compositor: self.compositor,
            lod: if self.lod.is_some() { Lod::Auto } else { Lod::Off },
        }))
    }

    crate::any_plan!();
}
