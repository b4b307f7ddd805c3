//! The text of `voltex plan`: bakes, objects, passes in order with their pipeline variants,
//! what was pruned, and the GPU memory the frame allocates.

use crate::graph::plan::PlannedPass;
use crate::graph::{ResourceDecl, TextureSize};
use crate::render::{Blueprint, ObjectPlan};

impl Blueprint {
    /// Bytes of GPU memory the frame allocates, by item.
    pub(crate) fn memory(&self) -> Vec<(String, u64)> {
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
        out.push(("image readback buffer".to_string(), self.readback_bytes()));
        for b in &self.bakes {
            out.extend(b.request.memory(&b.texel));
        }
        for g in &self.groups {
            out.extend(g.memory(&self.objects[g.members()[0]], self.size));
        }
        for o in &self.objects {
            let name = &o.object.name;
            for m in &o.methods {
                out.extend(m.memory(o, self.size));
            }
            if let Some(frames) = &o.frames {
                out.push((
                    format!("object {name}: vertex frames (per-pixel lighting)"),
                    (frames.len() * 32) as u64,
                ));
            }
        }
        out
    }

    /// The text of `voltex plan`.
    pub fn describe(&self, verbose: bool) -> String {
        let mut s = format!(
            "scene {}\noutput {}x{}\n\nbakes:\n",
            self.scene_path.display(),
            self.size.0,
            self.size.1
        );
        let own: Vec<String> =
            self.objects.iter().flat_map(|o| o.methods.iter().flat_map(|m| m.bake_lines(o))).collect();
        if self.bakes.is_empty() && own.is_empty() {
            s += "  (none)\n";
        }
        for line in own {
            s += &format!("  {line}\n");
        }
        for b in &self.bakes {
            s += &b.request.describe(&b.texel);
        }
        s += "\nobjects:\n";
        for o in &self.objects {
            let method = o.methods.last().map_or("nothing drawn".into(), |m| m.summary(o));
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
            if verbose {
                for p in &self.plan.pruned {
                    s += &format!("  {p}\n");
                }
            } else {
                // A pass or resource per line is dozens of lines for a one-object scene: counted
                // by reason unless `verbose`.
                let mut reasons: Vec<(String, usize)> = Vec::new();
                for p in &self.plan.pruned {
                    let reason = pruned_reason(p);
                    match reasons.iter_mut().find(|r| r.0 == reason) {
                        Some(r) => r.1 += 1,
                        None => reasons.push((reason, 1)),
                    }
                }
                for (reason, n) in reasons {
                    s += &format!("  {n} {reason}\n");
                }
                s += "  (--verbose lists them)\n";
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
                ids.iter().map(|&i| self.constants(&self.objects[self.instances[i].object], &names)).collect()
            }
        };
        variants.sort();
        variants.dedup();
        variants.into_iter().map(|v| if v.is_empty() { "default".into() } else { v }).collect()
    }

    fn constants(&self, o: &ObjectPlan, names: &[String]) -> String {
        o.constants()
            .into_iter()
            .filter(|(n, _)| names.contains(n))
            .map(|(n, v)| format!("{n}={}", v != 0.0))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// What a line of `Plan::pruned` says, without the name: `passes: no object matches ...` for a
/// method's passes (whatever the method), else its kind and reason.
fn pruned_reason(line: &str) -> String {
    let (kind, reason) = match line.split_once(' ') {
        Some((kind, rest)) => (kind, rest.split_once(": ").map_or(rest, |r| r.1)),
        None => ("", line),
    };
    if reason.starts_with("no object matches") {
        return "pass(es) of methods and object kinds this scene does not use".into();
    }
    let kinds = if kind == "pass" { "pass(es)".to_string() } else { format!("{kind}(s)") };
    format!("{kinds}: {reason}")
}
