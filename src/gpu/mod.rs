//! Device, shader lookup (embedded defaults and folders on disk), loading and validation, reflection, timestamps.

pub mod cache;
pub mod context;
pub mod fault;
pub mod kernel;
pub mod reflect;
pub mod shader;
pub mod sources;
pub mod timing;

pub use context::GpuContext;
