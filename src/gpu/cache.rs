//! GPU objects kept across rebuilds of a frame (the preview's hot reload): shader modules by the
//! hash of their expanded source, pipeline layouts by their bindings, pipelines by everything that
//! defines them, and bakes (texels, hypertexture mesh grids, splat sets: any type) by their
//! request and the source of the kernels that make them. A rebuild asks the cache first, so an edit recompiles or rebakes only what it changed;
//! `stats` counts what was actually made.

use std::any::{Any, TypeId};
use std::collections::{HashMap, HashSet};
use std::hash::{Hash, Hasher};

/// What a build created (not found in the cache).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct CacheStats {
    /// Shader modules compiled.
    pub modules: u32,
    /// Pipelines created.
    pub pipelines: u32,
    /// Texels baked.
    pub bakes: u32,
}

#[derive(Clone)]
pub(crate) enum Pipeline {
    Compute(wgpu::ComputePipeline),
    Render(wgpu::RenderPipeline),
}

#[derive(Clone)]
pub(crate) struct Layout {
    pub(crate) groups: Vec<wgpu::BindGroupLayout>,
    pub(crate) pipeline: wgpu::PipelineLayout,
}

/// Entries by their type and key.
type Slot = (TypeId, u64);

/// Shader modules, pipelines and bakes kept across builds (the preview's rebuilds, a bench's
/// settings), keyed by type and content hash, so that an unchanged part is not made again.
#[derive(Default)]
pub struct GpuCache {
    entries: HashMap<Slot, Box<dyn Any + Send>>,
    /// Entries used since the last `begin`, so that `retain_used` can drop what a rebuild left behind.
    used: HashSet<Slot>,
    /// What the current build created.
    pub stats: CacheStats,
}

/// Which count of `CacheStats` making an entry adds to.
#[derive(Clone, Copy)]
enum Made {
    Module,
    Layout,
    Pipeline,
    Bake,
}

/// A key from anything printable (the descriptors' fields, in order).
pub(crate) fn key(parts: &impl std::fmt::Debug) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    format!("{parts:?}").hash(&mut h);
    h.finish()
}

impl GpuCache {
    /// Starts a build: counts from zero and records which entries it uses.
    pub fn begin(&mut self) {
        self.stats = CacheStats::default();
        self.used.clear();
    }

    /// After a successful build: drops the entries it did not use (the last good frame holds its
    /// own handles, so nothing it draws with goes away).
    pub fn retain_used(&mut self) {
        let used = &self.used;
        self.entries.retain(|k, _| used.contains(k));
    }

    /// The entry of type `T` under `key`, made (and counted) if absent.
    fn get_or_make<T: Clone + Send + 'static>(
        &mut self,
        key: u64,
        made: Made,
        make: impl FnOnce() -> crate::Result<T>,
    ) -> crate::Result<T> {
        let slot = (TypeId::of::<T>(), key);
        self.used.insert(slot);
        if let Some(v) = self.entries.get(&slot).and_then(|v| v.downcast_ref::<T>()) {
            return Ok(v.clone());
        }
        let v = make()?;
        match made {
            Made::Module => self.stats.modules += 1,
            Made::Pipeline => self.stats.pipelines += 1,
            Made::Bake => self.stats.bakes += 1,
            Made::Layout => {}
        }
        self.entries.insert(slot, Box::new(v.clone()));
        Ok(v)
    }

    pub(crate) fn module(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<wgpu::ShaderModule>,
    ) -> crate::Result<wgpu::ShaderModule> {
        self.get_or_make(key, Made::Module, make)
    }

    pub(crate) fn layout(&mut self, key: u64, make: impl FnOnce() -> Layout) -> Layout {
        self.get_or_make(key, Made::Layout, || Ok(make())).expect("making a layout cannot fail")
    }

    pub(crate) fn pipeline(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<Pipeline>,
    ) -> crate::Result<Pipeline> {
        self.get_or_make(key, Made::Pipeline, make)
    }

    /// Takes the value of type `T` kept under `key` out of the cache: a helper used mutably while
    /// the cache is (the baker and its kernels); [`GpuCache::put`] gives it back.
    pub(crate) fn take<T: Send + 'static>(&mut self, key: u64) -> Option<T> {
        let v = self.entries.remove(&(TypeId::of::<T>(), key))?;
        v.downcast::<T>().ok().map(|v| *v)
    }

    /// Keeps `value` under `key`, used by this build.
    pub(crate) fn put<T: Send + 'static>(&mut self, key: u64, value: T) {
        let slot = (TypeId::of::<T>(), key);
        self.used.insert(slot);
        self.entries.insert(slot, Box::new(value));
    }

    /// A bake of any kind (a texel, a mesh grid, a splat set), counted in `stats.bakes`.
    pub(crate) fn bake<T: Clone + Send + 'static>(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<T>,
    ) -> crate::Result<T> {
        self.get_or_make(key, Made::Bake, make)
    }
}
