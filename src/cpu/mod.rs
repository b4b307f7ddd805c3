//! CPU twins of kernels whose math matters (f32 mirroring WGSL unless stated).

pub mod slice_prisms;
