//! The text of `voltex plan`: bakes, objects, passes in order with their pipeline variants,
//! what was pruned, and the GPU memory the frame allocates.

use crate::bake::{self, BakeSource};
use crate::graph::plan::PlannedPass;
use crate::graph::{ResourceDecl, TextureSize};
use crate::render::{object_constants, Blueprint, ObjectPlan};
use crate::types::SliceVertex;

impl Blueprint {
    /// Bytes of GPU memory the frame allocates, by item.
    pub fn memory(&self) -> Vec<(String, u64)> {
        let mut out = Vec::new();
        for (name, decl) in &self.plan.textures {
            let ResourceDecl::Texture { format, size, .. } = decl else { continue };
            let (w, h) = match size {
                TextureSize::Output => self.size,
                TextureSize::Fixed(w, h) => (*w, *h),
            };
            out.push((
                format!("texture {name} {w}x{h} {format:?}"),
                w as u64 * h as u64 * format.bytes_per_pixel(),
            ));
        }
        for (name, b) in &self.plan.buffers {
            out.push((format!("buffer {name} {} bytes", b.bytes), b.bytes));
        }
        for (name, v) in &self.plan.parameters {
            out.push((format!("parameter {name} {}", v.wgsl_type()), v.bytes().len() as u64));
        }
        for b in &self.bakes {
            let r = b.request.resolution;
            out.push((
                format!(
                    "texel {} {}x{}x{} rgba8{}",
                    b.texel,
                    r[0],
                    r[1],
                    r[2],
                    if b.request.per_pixel { " + normals" } else { "" }
                ),
                bake::bytes(r, b.request.per_pixel),
            ));
            if b.request.axis_slices {
                out.push((
                    format!("texel {} slice images (s, t, w; all levels) rgba16f", b.texel),
                    bake::axis_slices::bytes(r),
                ));
            }
        }
        if let Some(r) = &self.reference {
            out.push((
                format!(
                    "reference: BVH ({} nodes), {} prisms, shells, texel atlas{}, per-pixel state",
                    r.nodes.len(),
                    r.prisms.len(),
                    if r.normal_words > 1 { " + normal atlas" } else { "" }
                ),
                (r.nodes.len() * 32 + r.prisms.len() * 48 + r.vertices.len() * 32 + r.frames.len() * 32)
                    as u64
                    + (r.atlas_words + r.normal_words) * 4
                    + self.size.0 as u64 * self.size.1 as u64 * 32,
            ));
        }
        for o in &self.objects {
            let name = &o.object.name;
            let shell = (o.shell.vertices.len() * 32 + o.shell.prisms.len() * 64) as u64;
            if let Some(sweep) = &o.sweep {
                out.push((format!("object {name}: shell ({} prisms)", o.shell.prisms.len()), shell));
                let cap: u64 = o.chunks.iter().map(|c| c.capacity).sum();
                out.push((
                    format!(
                        "object {name}: slice vertices (capacity {cap} in {} chunk(s)) + {} plane cursors",
                        o.chunks.len(),
                        sweep.plane_count
                    ),
                    cap * std::mem::size_of::<SliceVertex>() as u64
                        + sweep.plane_count as u64 * 4
                        + o.chunks.len() as u64 * (16 + 48),
                ));
            }
            if let Some(a) = &o.axis {
                out.push((
                    format!("object {name}: axis slice vertices (capacity {}) + choices", a.capacity),
                    a.capacity * 48 + a.prisms.len() as u64 * (32 + 64) + shell + 16,
                ));
            }
            if let Some(frames) = &o.frames {
                out.push((
                    format!("object {name}: vertex frames (per-pixel lighting)"),
                    (frames.len() * 32) as u64,
                ));
            }
            if let Some(m) = &o.ray_march {
                out.push((
                    format!(
                        "object {name}: hypertexture parameters, transfer tables, per-pixel march state{}",
                        if m.packed.mesh.is_some() { ", mesh grid" } else { "" }
                    ) + if m.peel.is_some() { ", splat sets, per-pixel segment bounds" } else { "" }
                        + if m.splatting.is_some() { ", splat sets, per-pixel depth slabs" } else { "" },
                    m.bytes(self.size),
                ));
            }
            if let Some(base) = &o.base {
                out.push((format!("object {name}: base triangles"), (base.len() * 32) as u64));
            }
        }
        out
    }

    /// The text of `voltex plan`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "scene {}\noutput {}x{}\n\nbakes:\n",
            self.scene_path.display(),
            self.size.0,
            self.size.1
        );
        let grids: Vec<_> = self
            .objects
            .iter()
            .filter_map(|o| Some((&o.object.name, o.ray_march.as_ref()?.packed.mesh.as_ref()?)))
            .collect();
        let splats: Vec<_> = self
            .objects
            .iter()
            .filter_map(|o| Some((&o.object.name, o.ray_march.as_ref()?.lattice()?)))
            .collect();
        if self.bakes.is_empty() && grids.is_empty() && splats.is_empty() {
            s += "  (none)\n";
        }
        for (name, (shape, spec)) in grids {
            let [x, y, z] = spec.n;
            s += &format!(
                "  {name:<16} {x}x{y}x{z}  bake_mesh_grid.wgsl  mesh grid of {} triangles in {} part(s)\n",
                shape.triangles.len(),
                shape.parts.len(),
            );
        }
        for (name, l) in splats {
            let [x, y, z] = l.counts;
            s += &format!(
                "  {name:<16} {x}x{y}x{z}  bake_splats.wgsl  surface and interior splats, cell {:.4}, surface at \
                 support distance {:.4}\n",
                l.cell, l.level
            );
        }
        for b in &self.bakes {
            let r = b.request.resolution;
            let kind = match b.request.source {
                BakeSource::Implicit(_) => "bake/bake_implicit.wgsl",
                BakeSource::Heightfield(_) => "bake/bake_heightfield.wgsl",
                BakeSource::HeightImage(..) => "bake/bake_height_image.wgsl",
                BakeSource::Stack(_) => "slice stack (uploaded)",
                BakeSource::Mesh(_) => "bake_mesh_grid.wgsl + bake_mesh_texel.wgsl",
                BakeSource::Hypertexture(ref h) if h.packed.mesh.is_some() => {
                    "bake_transfer.wgsl + bake_mesh_grid.wgsl + bake_hypertexture.wgsl"
                }
                BakeSource::Hypertexture(_) => "bake_transfer.wgsl + bake_hypertexture.wgsl",
            };
            s += &format!(
                "  {:<16} {}x{}x{}  {kind}  lighting {}\n",
                b.texel,
                r[0],
                r[1],
                r[2],
                if b.request.per_pixel { "per-pixel (albedo + normals)" } else { "baked" }
            );
            if b.request.axis_slices {
                s += "  (and its slice images: bake_axis_slices.wgsl per direction and level)\n";
            }
        }
        s += "\nobjects:\n";
        for o in &self.objects {
            let method = match (&o.sweep, o.reference_step, &o.axis) {
                _ if o.ray_march.is_some() => {
                    let m = o.ray_march.as_ref().unwrap();
                    format!(
                        "{} of hypertexture \"{}\", {} noise(s), {} dispatch(es) per frame",
                        m.describe(),
                        m.hypertexture,
                        m.packed.noises.len(),
                        m.dispatches
                    )
                }
                (_, _, Some(a)) => format!("{:?}, vertex capacity {}", a.method, a.capacity),
                (_, Some(step), _) => format!(
                    "Reference step {step:.6} lighting {}, {} dispatch(es) per frame",
                    if o.per_pixel { "PerPixel" } else { "Baked" },
                    self.reference.as_ref().map_or(0, |r| r.dispatches)
                ),
                (Some(p), _, _) => format!(
                    "ViewSlices planes {} spacing {:.4} trivial_reject {} lighting {}, {} chunk(s)",
                    p.plane_count,
                    p.spacing,
                    o.trivial_reject,
                    if o.per_pixel { "PerPixel" } else { "Baked" },
                    o.chunks.len()
                ),
                (None, _, _) => "base surface only".into(),
            };
            let what = match &o.object.hypertexture {
                Some(_) => "hypertexture".to_string(),
                None => format!("{} triangles", o.shell.prisms.len()),
            };
            s += &format!("  {:<16} {what}  {method}\n", o.object.name);
            for w in &o.object.report.warnings {
                s += &format!("    warning: {w}\n");
            }
        }
        s += "\npasses (in order):\n";
        for p in &self.plan.passes {
            let inst = match &p.instances {
                None => "frame".to_string(),
                Some(ids) => format!("{} instance(s)", ids.len()),
            };
            let pipelines = self.pipeline_variants(p);
            s += &format!(
                "  {:<20} {:<26} {:<12} pipelines: {}\n",
                p.decl.name(),
                p.decl.shader(),
                inst,
                pipelines.join(", ")
            );
        }
        s += &self.describe_resources();
        s += &format!(
            "\nkernels compiled: {}\n",
            self.plan.kernels().into_iter().collect::<Vec<_>>().join(", ")
        );
        if !self.plan.pruned.is_empty() {
            s += "\npruned:\n";
            for p in &self.plan.pruned {
                s += &format!("  {p}\n");
            }
        }
        s += "\nGPU memory:\n";
        let mem = self.memory();
        for (what, bytes) in &mem {
            s += &format!("  {:>10.2} MiB  {what}\n", *bytes as f64 / 1048576.0);
        }
        s += &format!("  {:>10.2} MiB  total\n", mem.iter().map(|m| m.1).sum::<u64>() as f64 / 1048576.0);
        s
    }

    /// The graph's resources the plan allocates: textures with their size, buffers with their
    /// size expression and bytes, parameters with their value.
    fn describe_resources(&self) -> String {
        let mut s = "\nresources:\n".to_string();
        for (name, decl) in &self.plan.textures {
            if let ResourceDecl::Texture { format, size, .. } = decl {
                let (w, h) = match size {
                    TextureSize::Output => self.size,
                    TextureSize::Fixed(w, h) => (*w, *h),
                };
                s += &format!("  {name:<20} texture {w}x{h} {format:?}\n");
            }
        }
        for (name, b) in &self.plan.buffers {
            let Some(ResourceDecl::Buffer { size, .. }) = self.graph.file.resources.get(name) else {
                continue;
            };
            let (expr, unit) = size.expr();
            s += &format!(
                "  {name:<20} buffer {} bytes (\"{expr}\" x {unit}){}{}\n",
                b.bytes,
                if b.clear { ", cleared each frame" } else { "" },
                if b.indirect { ", indirect draws" } else { "" }
            );
        }
        for (name, v) in &self.plan.parameters {
            s += &format!("  {name:<20} parameter {} = {v:?}\n", v.wgsl_type());
        }
        s
    }

    fn pipeline_variants(&self, p: &PlannedPass) -> Vec<String> {
        let names: Vec<String> = crate::gpu::reflect::overrides(&p.kernel).into_iter().map(|o| o.0).collect();
        let mut variants: Vec<String> = match &p.instances {
            None => vec![String::new()],
            Some(ids) => {
                ids.iter().map(|&i| self.constants(&self.objects[self.instances[i].0], &names)).collect()
            }
        };
        variants.sort();
        variants.dedup();
        variants.into_iter().map(|v| if v.is_empty() { "default".into() } else { v }).collect()
    }

    fn constants(&self, o: &ObjectPlan, names: &[String]) -> String {
        object_constants(o)
            .into_iter()
            .filter(|(n, _)| names.contains(n))
            .map(|(n, v)| format!("{n}={}", v != 0.0))
            .collect::<Vec<_>>()
            .join(" ")
    }
}
