//! Device, shader lookup (embedded defaults and folders on disk), loading and validation, reflection, timestamps.

pub mod budget;
pub mod buffers;
pub mod cache;
pub mod context;
pub mod inputs;
pub mod kernel;
pub mod reflect;
pub mod shader;
pub mod sources;
pub mod timing;

pub use context::GpuContext;
pub use inputs::Inputs;
