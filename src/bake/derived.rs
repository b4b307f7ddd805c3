//! Products of a texel's bake that a method needs beside the volume (AxisSlices' slice images):
//! the method's plan asks for one on the texel's [`BakeRequest`](super::BakeRequest), and the
//! bake records it from the finished volume in the same submission, so the bake layer knows no
//! method. Two objects drawing the same texel share one request, and so one product of a kind
//! (see [`BakeRequest::derive`](super::BakeRequest::derive)).

use std::any::Any;
use std::sync::Arc;

use crate::error::Result;
use crate::gpu::budget::{Allocation, Driver};
use crate::gpu::cache::GpuBytes;
use crate::gpu::kernel::ComputeKernel;
use crate::gpu::GpuContext;

/// A product derived from a texel's baked volume. Its `Debug` text is part of the bake's key, so
/// it must show every setting that changes what is made.
pub(crate) trait Derived: std::fmt::Debug + Send + Sync + Any {
    /// Its kernels (under `wgsl/`): checked by `plan`, hashed into the bake's key.
    fn kernels(&self) -> Vec<&'static str>;
    /// Its lines under the bake in `voltex plan`.
    fn describe(&self) -> String;
    /// Its line of GPU memory in `voltex plan`.
    fn memory(&self, texel: &str, resolution: [u32; 3]) -> (String, u64);
    /// Its textures and large buffers, for the checks against the adapter's limits.
    fn allocations(&self, texel: &str, resolution: [u32; 3], driver: &Driver) -> Vec<Allocation>;
    /// Records it from `volume` (the texel, level 0) into `encoder`, with the baker's kernels.
    fn record(
        &self,
        ctx: &GpuContext,
        kernels: &mut Kernels,
        encoder: &mut wgpu::CommandEncoder,
        volume: &wgpu::Texture,
        resolution: [u32; 3],
    ) -> Result<Arc<dyn Made>>;
}

/// What a [`Derived`] made: GPU resources kept with the baked texel.
pub(crate) trait Made: GpuBytes + Send + Sync + Any {}

impl<T: GpuBytes + Send + Sync + Any> Made for T {}

/// The kernels a [`Derived`] runs, loaded by the baker on first use and kept across bakes.
pub(crate) struct Kernels<'a> {
    pub(super) slots: &'a mut Vec<(&'static str, super::Slot)>,
    pub(super) sources: &'a crate::gpu::sources::Sources,
    pub(super) format: wgpu::TextureFormat,
}

impl Kernels<'_> {
    /// The kernel `path` (under `wgsl/`).
    pub(crate) fn get(&mut self, ctx: &GpuContext, path: &'static str) -> Result<&mut ComputeKernel> {
        let i = match self.slots.iter().position(|(p, _)| *p == path) {
            Some(i) => i,
            None => {
                self.slots.push((path, None));
                self.slots.len() - 1
            }
        };
        super::Baker::kernel(&mut self.slots[i].1, ctx, self.sources, path, self.format)
    }
}

/// What a texel's bake derives from its volume: the products its methods asked for.
#[derive(Clone, Debug, Default)]
pub struct Derivations(pub(crate) Vec<Arc<dyn Derived>>);

/// The products of one baked texel, by kind.
#[derive(Clone, Default)]
pub struct MadeProducts(pub(super) Vec<Arc<dyn Made>>);

impl MadeProducts {
    /// The product of kind `T`, if the request asked for one.
    pub fn get<T: Any>(&self) -> Option<&T> {
        self.0.iter().find_map(|m| (m.as_ref() as &dyn Any).downcast_ref::<T>())
    }
}

impl GpuBytes for MadeProducts {
    fn gpu_bytes(&self) -> u64 {
        self.0.iter().map(|m| m.gpu_bytes()).sum()
    }
}
