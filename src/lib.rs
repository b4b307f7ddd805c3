//! voltex: volumetric textures and hypertextures on wgpu.
//!
//! Data flow: scene file → [`scene`] → objects with base surfaces ([`mesh`]) → a [`graph`] of
//! compute and raster passes built from `graphs/*.ron` and `wgsl/*.wgsl`, each [`methods`] module
//! contributing its own → [`render`] → [`io`] (EXR, PNG). The modules form layers that import
//! only downwards (`tests/checks/layers.rs` lists them).

#![deny(missing_docs)]

pub mod bake;
pub mod bench;
pub mod cpu;
pub mod error;
pub(crate) mod fault;
pub mod gpu;
pub mod graph;
pub mod hypertexture;
pub mod input;
pub mod io;
pub mod mesh;
pub mod methods;
pub mod metrics;
pub mod pareto;
pub mod preview;
pub mod progress;
pub mod regress;
pub mod render;
pub mod scene;
pub mod types;
pub mod vdb;
pub(crate) mod work;

pub use error::{Error, FileLoc, Result};

/// The project's root folder, where `wgsl/`, `graphs/` and `scenes/` live: `VOLTEX_ROOT`, else the
/// source tree voltex was built from. Shaders and graphs are read through
/// [`gpu::sources::Sources`], which falls back to the copies built into the binary.
pub fn project_root() -> std::path::PathBuf {
    std::env::var_os("VOLTEX_ROOT")
        .map(Into::into)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")))
}
