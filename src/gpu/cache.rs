//! GPU objects kept across rebuilds of a frame (the preview's hot reload): shader modules by the
//! hash of their expanded source, pipeline layouts by their bindings, pipelines by everything that
//! defines them, and bakes (texels, hypertexture mesh grids, splat sets: any type) by their
//! request and the source of the kernels that make them. A rebuild asks the cache first, so an
//! edit recompiles or rebakes only what it changed; `stats` counts what was actually made. What a
//! rebuild left unused is kept for a few builds, bakes up to a byte cap (the preview's
//! [`GpuCache::with_stale_bytes`]), so that undoing an edit finds what it had before.

use std::any::{Any, TypeId};
use std::collections::HashMap;
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

/// Builds an entry no build used is kept for (modules and pipelines: small; bakes also count
/// against the stale-byte cap).
const STALE_BUILDS: u64 = 8;

/// GPU memory of a cached value, for the cap on what the cache keeps unused.
pub(crate) trait GpuBytes {
    fn gpu_bytes(&self) -> u64;
}

impl GpuBytes for wgpu::Buffer {
    fn gpu_bytes(&self) -> u64 {
        self.size()
    }
}

impl GpuBytes for wgpu::Texture {
    fn gpu_bytes(&self) -> u64 {
        let block = self.format().block_copy_size(None).unwrap_or(4) as u64;
        let volume = self.dimension() == wgpu::TextureDimension::D3;
        (0..self.mip_level_count())
            .map(|m| {
                let layers = if volume {
                    (self.depth_or_array_layers() >> m).max(1)
                } else {
                    self.depth_or_array_layers()
                };
                (self.width() >> m).max(1) as u64 * (self.height() >> m).max(1) as u64 * layers as u64 * block
            })
            .sum()
    }
}

impl<T: GpuBytes> GpuBytes for Option<T> {
    fn gpu_bytes(&self) -> u64 {
        self.as_ref().map_or(0, T::gpu_bytes)
    }
}

/// Copies an entry's value (see [`Entry::copy`]).
type CopyValue = fn(&(dyn Any + Send)) -> Box<dyn Any + Send>;

struct Entry {
    value: Box<dyn Any + Send>,
    /// Copies `value` (a handle: wgpu's objects are shared, not duplicated), for
    /// [`GpuCache::share`]; `None` for what [`GpuCache::put`] keeps (not `Clone`).
    copy: Option<CopyValue>,
    /// GPU bytes of a bake; 0 for modules, layouts and pipelines.
    bytes: u64,
    /// The build that last used it.
    used: u64,
}

/// Shader modules, pipelines and bakes kept across builds (the preview's rebuilds, a bench's
/// settings), keyed by type and content hash, so that an unchanged part is not made again.
#[derive(Default)]
pub struct GpuCache {
    entries: HashMap<Slot, Entry>,
    /// The current build (counted by `begin`).
    build: u64,
    /// Most GPU bytes of bakes the last build did not use that `retain_used` keeps (default 0:
    /// it keeps nothing unused).
    stale_bytes: u64,
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
    /// A cache that keeps up to `bytes` of bakes a build left unused (newest first, for at most
    /// a few builds), beyond the frame's own memory: the preview's, where an edit is often undone.
    pub(crate) fn with_stale_bytes(bytes: u64) -> Self {
        GpuCache { stale_bytes: bytes, ..Default::default() }
    }

    /// Changes how many bytes of unused bakes `retain_used` keeps (see [`GpuCache::with_stale_bytes`]).
    pub(crate) fn set_stale_bytes(&mut self, bytes: u64) {
        self.stale_bytes = bytes;
    }

    /// A new cache holding this one's modules, layouts, pipelines and bakes (shared handles on
    /// the same device), with its settings: another session of the same scene (the preview's
    /// reference view) finds them instead of baking and compiling again.
    pub(crate) fn share(&self) -> GpuCache {
        let entries = (self.entries.iter())
            .filter_map(|(slot, e)| {
                let copy = e.copy?;
                Some((*slot, Entry { value: copy(e.value.as_ref()), copy: e.copy, bytes: e.bytes, used: 0 }))
            })
            .collect();
        GpuCache { entries, stale_bytes: self.stale_bytes, ..Default::default() }
    }

    /// Drops every entry (made on a device that was lost), keeping the settings.
    pub(crate) fn clear(&mut self) {
        self.entries.clear();
    }

    /// Starts a build: counts from zero and records which entries it uses.
    pub fn begin(&mut self) {
        self.stats = CacheStats::default();
        self.build += 1;
    }

    /// After a successful build: drops the entries it did not use, except the most recently used
    /// of them within the stale-byte cap and a few builds (the last good frame holds its own
    /// handles, so nothing it draws with goes away).
    pub fn retain_used(&mut self) {
        let build = self.build;
        let mut stale: Vec<(u64, Slot)> =
            self.entries.iter().filter(|(_, e)| e.used != build).map(|(k, e)| (e.used, *k)).collect();
        stale.sort_by_key(|s| std::cmp::Reverse(s.0));
        let mut kept = 0;
        for (used, slot) in stale {
            let bytes = self.entries[&slot].bytes;
            if self.stale_bytes > 0 && build - used < STALE_BUILDS && kept + bytes <= self.stale_bytes {
                kept += bytes;
            } else {
                self.entries.remove(&slot);
            }
        }
    }

    /// The entry of type `T` under `key`, made (and counted) if absent; `bytes` sizes a new one.
    fn get_or_make<T: Clone + Send + 'static>(
        &mut self,
        key: u64,
        made: Made,
        make: impl FnOnce() -> crate::Result<T>,
        bytes: impl FnOnce(&T) -> u64,
    ) -> crate::Result<T> {
        let slot = (TypeId::of::<T>(), key);
        if let Some(e) = self.entries.get_mut(&slot) {
            if let Some(v) = e.value.downcast_ref::<T>() {
                e.used = self.build;
                return Ok(v.clone());
            }
        }
        let v = make()?;
        match made {
            Made::Module => self.stats.modules += 1,
            Made::Pipeline => self.stats.pipelines += 1,
            Made::Bake => self.stats.bakes += 1,
            Made::Layout => {}
        }
        let copy: CopyValue = |v| Box::new(v.downcast_ref::<T>().expect("the entry's own type").clone());
        let entry =
            Entry { value: Box::new(v.clone()), copy: Some(copy), bytes: bytes(&v), used: self.build };
        self.entries.insert(slot, entry);
        Ok(v)
    }

    pub(crate) fn module(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<wgpu::ShaderModule>,
    ) -> crate::Result<wgpu::ShaderModule> {
        self.get_or_make(key, Made::Module, make, |_| 0)
    }

    pub(crate) fn layout(&mut self, key: u64, make: impl FnOnce() -> Layout) -> Layout {
        self.get_or_make(key, Made::Layout, || Ok(make()), |_| 0).expect("making a layout cannot fail")
    }

    pub(crate) fn pipeline(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<Pipeline>,
    ) -> crate::Result<Pipeline> {
        self.get_or_make(key, Made::Pipeline, make, |_| 0)
    }

    /// Takes the value of type `T` kept under `key` out of the cache: a helper used mutably while
    /// the cache is (the baker and its kernels); [`GpuCache::put`] gives it back.
    pub(crate) fn take<T: Send + 'static>(&mut self, key: u64) -> Option<T> {
        let e = self.entries.remove(&(TypeId::of::<T>(), key))?;
        e.value.downcast::<T>().ok().map(|v| *v)
    }

    /// Keeps `value` under `key`, used by this build.
    pub(crate) fn put<T: Send + 'static>(&mut self, key: u64, value: T) {
        let entry = Entry { value: Box::new(value), copy: None, bytes: 0, used: self.build };
        self.entries.insert((TypeId::of::<T>(), key), entry);
    }

    /// A bake of any kind (a texel, a mesh grid, a splat set), counted in `stats.bakes`.
    pub(crate) fn bake<T: Clone + Send + GpuBytes + 'static>(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<T>,
    ) -> crate::Result<T> {
        self.get_or_make(key, Made::Bake, make, T::gpu_bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Debug, PartialEq)]
    struct Fake(u64);

    impl GpuBytes for Fake {
        fn gpu_bytes(&self) -> u64 {
            self.0
        }
    }

    /// A build that bakes `sizes` (keys = sizes); returns how many it had to make.
    fn build(cache: &mut GpuCache, sizes: &[u64]) -> u32 {
        cache.begin();
        for &n in sizes {
            assert_eq!(cache.bake(n, || Ok(Fake(n))).unwrap(), Fake(n));
        }
        cache.retain_used();
        cache.stats.bakes
    }

    #[test]
    fn by_default_what_a_build_left_unused_is_dropped() {
        let mut cache = GpuCache::default();
        assert_eq!(build(&mut cache, &[10, 20]), 2);
        assert_eq!(build(&mut cache, &[10, 30]), 1);
        assert_eq!(build(&mut cache, &[10, 20]), 1, "20 was dropped by the second build");
    }

    #[test]
    fn unused_bakes_are_kept_newest_first_within_the_cap() {
        let mut cache = GpuCache::with_stale_bytes(100);
        assert_eq!(build(&mut cache, &[60]), 1);
        assert_eq!(build(&mut cache, &[50]), 1);
        // 50 (newest unused) fits the cap; 60 more would not: dropped.
        assert_eq!(build(&mut cache, &[1]), 1);
        assert_eq!(build(&mut cache, &[50]), 0, "the undo finds 50");
        assert_eq!(build(&mut cache, &[60]), 1, "60 was over the cap");
        // An entry used by the current build never counts against the cap.
        assert_eq!(build(&mut cache, &[500]), 1);
        assert_eq!(build(&mut cache, &[500]), 0);
    }

    #[test]
    fn a_shared_cache_finds_the_bakes_and_keeps_what_put_holds_to_itself() {
        let mut cache = GpuCache::with_stale_bytes(100);
        build(&mut cache, &[10, 20]);
        cache.put(5, String::from("the baker"));
        let mut shared = cache.share();
        assert_eq!(build(&mut shared, &[10, 20, 30]), 1, "only 30 is baked again");
        assert_eq!(shared.take::<String>(5), None, "`put` values are not copied");
        assert_eq!(cache.take::<String>(5).as_deref(), Some("the baker"));
        assert_eq!(build(&mut cache, &[10, 20]), 0, "the first cache keeps its own");
    }

    #[test]
    fn unused_entries_go_after_a_few_builds() {
        let mut cache = GpuCache::with_stale_bytes(1 << 30);
        build(&mut cache, &[7]);
        for k in 0..STALE_BUILDS {
            build(&mut cache, &[100 + k]);
        }
        assert_eq!(build(&mut cache, &[7]), 1, "7 went after {STALE_BUILDS} builds without it");
        assert_eq!(build(&mut cache, &[100 + STALE_BUILDS - 1]), 0, "the newest are still there");
    }
}
