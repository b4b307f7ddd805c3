//! A frame's allocations estimated from the blueprint's counts (no GPU), checked against limits
//! and the memory budget with the position of the value that sizes them: `voltex plan` against
//! wgpu's default limits, `Renderer` against the adapter's, before anything is allocated.

use crate::error::{Error, FileLoc, Result};
use crate::gpu::budget::{self, Allocation, AllocationKind, Driver, Failure};
use crate::graph::{ResourceDecl, TextureSize};
use crate::render::Blueprint;
use crate::scene::Scene;

/// Where the values that size allocations are written in the scene file (found when it was
/// parsed: `scene::Locations`).
#[derive(Debug, Clone, Default)]
pub(crate) struct Positions {
    /// The scene's `output` size; `None` when `--size` replaced it.
    pub(crate) output: Option<FileLoc>,
    pub(crate) texels: Vec<(String, FileLoc)>,
    pub(crate) objects: Vec<(String, FileLoc)>,
}

impl Positions {
    pub(crate) fn of(scene: &Scene, size_overridden: bool) -> Self {
        let at = &scene.locations;
        let output = if size_overridden { None } else { at.output.clone() };
        Positions { output, texels: at.texels.clone(), objects: at.objects.clone() }
    }

    /// `e`, a planning error of object `name` without a position, at the node's name (the
    /// method's knobs and surface that sized the work are in that node).
    pub(crate) fn at_object(&self, name: &str, e: Error) -> Error {
        match (e, self.objects.iter().find(|o| o.0 == name)) {
            (Error::Invalid(msg), Some((_, loc))) => Error::at(loc.clone(), msg),
            (e, _) => e,
        }
    }
}

fn padded_row(w: u32) -> u64 {
    (w as u64 * 16).div_ceil(256) * 256
}

impl Blueprint {
    /// Bytes of the buffer the first output is read back through.
    pub(super) fn readback_bytes(&self) -> u64 {
        padded_row(self.size.0) * self.size.1 as u64
    }

    /// Every texture and every buffer that grows with the scene's values, one by one.
    pub(crate) fn allocations(&self) -> Vec<Allocation> {
        let mut out = Vec::new();
        for (name, decl) in &self.plan.textures {
            let ResourceDecl::Texture { format, size, .. } = decl else { continue };
            let ((w, h), driver) = match size {
                TextureSize::Output => (self.size, Driver::Output),
                TextureSize::Fixed(w, h) => ((*w, *h), Driver::Graph(name.clone())),
            };
            out.push(Allocation {
                what: format!("graph texture `{name}` ({w}x{h} {format:?})"),
                bytes: w as u64 * h as u64 * format.bytes_per_pixel(),
                shape: AllocationKind::Texture2d { size: [w, h], layers: 1 },
                driver,
            });
        }
        for (name, b) in &self.plan.buffers {
            out.push(Allocation {
                what: format!("graph buffer `{name}`"),
                bytes: b.bytes,
                shape: AllocationKind::Buffer { storage: true },
                driver: Driver::Graph(name.clone()),
            });
        }
        out.push(Allocation {
            what: format!("the {}x{} image's readback buffer", self.size.0, self.size.1),
            bytes: self.readback_bytes(),
            shape: AllocationKind::Buffer { storage: false },
            driver: Driver::Output,
        });
        for b in &self.bakes {
            out.extend(b.request.allocations(&b.texel));
        }
        for g in &self.groups {
            out.extend(g.allocations(&self.objects[g.members()[0]], self.size));
        }
        for o in &self.objects {
            for m in &o.methods {
                out.extend(m.allocations(o, self.size));
            }
        }
        out
    }

    /// Checks each allocation against `limits` (`whose`: named in the error), the total against
    /// the budget, then each method's own limits: all before anything is allocated.
    pub fn check_limits(&self, limits: &wgpu::Limits, whose: &str) -> Result<()> {
        match budget::check(&self.allocations(), &self.memory(), limits, self.budget) {
            Some(Failure::Limit(d, msg)) => {
                return Err(self.error_for(Some(&d), format!("{msg} ({whose})"), true))
            }
            Some(Failure::Budget(d, msg)) => return Err(self.error_for(d.as_ref(), msg, false)),
            None => {}
        }
        // A method's own limits, at the node that asks for them (a frame-wide plan's first).
        for o in &self.objects {
            for m in &o.methods {
                m.check_limits(o, limits).map_err(|e| self.positions.at_object(&o.object.name, e))?;
            }
        }
        for g in &self.groups {
            let first = &self.objects[g.members()[0]];
            g.check_limits(first, limits).map_err(|e| self.positions.at_object(&first.object.name, e))?;
        }
        Ok(())
    }

    /// `msg` at the value behind `driver`, with what to change when `hint`.
    fn error_for(&self, driver: Option<&Driver>, msg: String, hint: bool) -> Error {
        let Some(driver) = driver else { return Error::file(&self.scene_path, msg) };
        let find =
            |list: &[(String, FileLoc)], name: &str| list.iter().find(|e| e.0 == name).map(|e| e.1.clone());
        let (loc, what) = match driver {
            Driver::Output => match &self.positions.output {
                Some(loc) => (Some(loc.clone()), "a smaller `output` size"),
                None => {
                    let (w, h) = self.size;
                    let hint = if hint { ": use a smaller --size" } else { "" };
                    return Error::Invalid(format!("the render size {w}x{h} (--size): {msg}{hint}"));
                }
            },
            Driver::Texel(name) => (find(&self.positions.texels, name), "a lower texel `resolution`"),
            Driver::Object(name) => {
                (find(&self.positions.objects, name), "fewer planes, cells or a smaller image")
            }
            Driver::Graph(name) => {
                let hint = if hint { ": make the resource smaller" } else { "" };
                return self.graph.error_at_resource(name, format!("{msg}{hint}"));
            }
        };
        let msg = if hint { format!("{msg}: use {what}") } else { msg };
        match loc {
            Some(loc) => Error::at(loc, msg),
            None => Error::file(&self.scene_path, msg),
        }
    }
}
