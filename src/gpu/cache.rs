//! GPU objects kept across rebuilds of a frame (the preview's hot reload): shader modules by the
//! hash of their expanded source, pipeline layouts by their bindings, pipelines by everything that
//! defines them, baked texels by their request, and hypertexture mesh grids by their mesh and
//! grid. A rebuild asks the cache first, so an edit recompiles or rebakes only what it changed;
//! `stats` counts what was actually made.

use std::collections::{HashMap, HashSet};
use std::hash::{Hash, Hasher};

use crate::bake::Baked;
use crate::hypertexture::mesh::MeshGrid;
use crate::hypertexture::splats::SplatSet;

/// What a build created (not found in the cache).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct CacheStats {
    pub modules: u32,
    pub pipelines: u32,
    pub bakes: u32,
}

#[derive(Clone)]
pub enum Pipeline {
    Compute(wgpu::ComputePipeline),
    Render(wgpu::RenderPipeline),
}

#[derive(Clone)]
pub struct Layout {
    pub groups: Vec<wgpu::BindGroupLayout>,
    pub pipeline: wgpu::PipelineLayout,
}

#[derive(Default)]
pub struct GpuCache {
    modules: HashMap<u64, wgpu::ShaderModule>,
    layouts: HashMap<u64, Layout>,
    pipelines: HashMap<u64, Pipeline>,
    bakes: HashMap<u64, Baked>,
    grids: HashMap<u64, MeshGrid>,
    splats: HashMap<u64, SplatSet>,
    /// Keys used since the last `begin`, so that `retain_used` can drop what a rebuild left behind.
    used: HashSet<u64>,
    pub stats: CacheStats,
}

/// A key from anything printable (the descriptors' fields, in order).
pub fn key(parts: &impl std::fmt::Debug) -> u64 {
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
        self.modules.retain(|k, _| used.contains(k));
        self.layouts.retain(|k, _| used.contains(k));
        self.pipelines.retain(|k, _| used.contains(k));
        self.bakes.retain(|k, _| used.contains(k));
        self.grids.retain(|k, _| used.contains(k));
        self.splats.retain(|k, _| used.contains(k));
    }

    pub fn module(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<wgpu::ShaderModule>,
    ) -> crate::Result<wgpu::ShaderModule> {
        self.used.insert(key);
        if let Some(m) = self.modules.get(&key) {
            return Ok(m.clone());
        }
        let m = make()?;
        self.stats.modules += 1;
        self.modules.insert(key, m.clone());
        Ok(m)
    }

    pub fn layout(&mut self, key: u64, make: impl FnOnce() -> Layout) -> Layout {
        self.used.insert(key);
        self.layouts.entry(key).or_insert_with(make).clone()
    }

    pub fn pipeline(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<Pipeline>,
    ) -> crate::Result<Pipeline> {
        self.used.insert(key);
        if let Some(p) = self.pipelines.get(&key) {
            return Ok(p.clone());
        }
        let p = make()?;
        self.stats.pipelines += 1;
        self.pipelines.insert(key, p.clone());
        Ok(p)
    }

    pub fn bake(&mut self, key: u64, make: impl FnOnce() -> crate::Result<Baked>) -> crate::Result<Baked> {
        self.used.insert(key);
        if let Some(b) = self.bakes.get(&key) {
            return Ok(b.clone());
        }
        let b = make()?;
        self.stats.bakes += 1;
        self.bakes.insert(key, b.clone());
        Ok(b)
    }

    /// A hypertexture mesh object's grid (counted as a bake).
    pub fn grid(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<MeshGrid>,
    ) -> crate::Result<MeshGrid> {
        self.used.insert(key);
        if let Some(g) = self.grids.get(&key) {
            return Ok(g.clone());
        }
        let g = make()?;
        self.stats.bakes += 1;
        self.grids.insert(key, g.clone());
        Ok(g)
    }

    /// A depth-peeled hypertexture object's splat set (counted as a bake).
    pub fn splats(
        &mut self,
        key: u64,
        make: impl FnOnce() -> crate::Result<SplatSet>,
    ) -> crate::Result<SplatSet> {
        self.used.insert(key);
        if let Some(s) = self.splats.get(&key) {
            return Ok(s.clone());
        }
        let s = make()?;
        self.stats.bakes += 1;
        self.splats.insert(key, s.clone());
        Ok(s)
    }
}
