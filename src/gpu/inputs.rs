//! What one graph instance (the frame, or one object) brings to the passes that run for it:
//! buffers, texture views and samplers bound by name, counts, and `override` constant values.

use std::collections::HashMap;

/// Resources, counts and override constants of one instance: the frame, or one object.
#[derive(Default)]
pub struct Inputs {
    /// Storage and uniform buffers by the name kernels bind them.
    pub buffers: HashMap<String, wgpu::Buffer>,
    pub(crate) views: HashMap<String, wgpu::TextureView>,
    pub(crate) samplers: HashMap<String, wgpu::Sampler>,
    pub(crate) counts: HashMap<String, u32>,
    /// Values for WGSL `override` constants, by name.
    pub(crate) constants: Vec<(String, f64)>,
    /// View depth of each plane of a slice sweep, back to front: draws of instances whose depth
    /// ranges overlap are interleaved plane by plane (`Draw::DepthSorted`).
    pub(crate) plane_depths: Vec<f64>,
}

/// Values of a kernel's `override` constants, looked up by name in `sources` (first match wins);
/// the name of one without a default that no source sets as the error.
pub(crate) fn override_values<'a>(
    kernel: &crate::gpu::shader::Kernel,
    sources: &[&'a Inputs],
) -> std::result::Result<Vec<(&'a str, f64)>, String> {
    let mut out = Vec::new();
    for (name, has_default) in crate::gpu::reflect::overrides(kernel) {
        match sources.iter().flat_map(|s| &s.constants).find(|(n, _)| *n == name) {
            Some((n, v)) => out.push((n.as_str(), *v)),
            None if !has_default => return Err(name),
            None => {}
        }
    }
    Ok(out)
}
