//! CPU twins of the WGSL kernels (same names, same f32 math) for tests and references.

pub mod bake;
