//! Device, shader lookup (embedded defaults and folders on disk), loading and validation, reflection, timestamps.

pub mod bindings;
pub mod budget;
pub(crate) mod buffers;
pub mod cache;
pub(crate) mod context;
pub(crate) mod inputs;
pub(crate) mod kernel;
pub mod readback;
pub(crate) mod reflect;
pub mod shader;
pub mod sources;
pub mod timing;

pub use context::GpuContext;
pub use inputs::Inputs;
