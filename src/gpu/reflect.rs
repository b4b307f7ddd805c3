//! Reflection of WGSL globals with naga: names, groups, bindings and access of every resource an
//! entry point uses, so the render graph binds resources by name and builds layouts itself.

use crate::error::{Error, Result};
use crate::gpu::shader::Kernel;

/// What kind of resource a WGSL global is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum BindingKind {
    Uniform,
    Storage {
        read_only: bool,
    },
    /// `filtered`: sampled through a sampler somewhere in the module (else only loaded, which
    /// also accepts unfilterable formats such as Rgba32Float).
    Texture {
        dim: wgpu::TextureViewDimension,
        depth: bool,
        filtered: bool,
    },
    StorageTexture {
        dim: wgpu::TextureViewDimension,
        format: wgpu::TextureFormat,
        write_only: bool,
    },
    Sampler,
}

impl BindingKind {
    /// Whether a pass with this binding writes the bound resource (for pass ordering).
    pub(crate) fn writes(&self) -> bool {
        matches!(self, BindingKind::Storage { read_only: false } | BindingKind::StorageTexture { .. })
    }
}

/// A WGSL global a pass binds, as reflection finds it: its name, group, binding and kind.
#[derive(Clone, Debug)]
pub struct Binding {
    /// The global's name, which graph resources are bound by.
    pub name: String,
    pub(crate) group: u32,
    /// Its `@binding` index.
    pub binding: u32,
    pub(crate) kind: BindingKind,
    pub(crate) visibility: wgpu::ShaderStages,
}

/// Bindings used by the given entry points, merged across stages, sorted by (group, binding).
pub(crate) fn bindings(kernel: &Kernel, entry_points: &[&str]) -> Result<Vec<Binding>> {
    let module = &kernel.module;
    let sampled = sampled_globals(module);
    let mut out: Vec<Binding> = Vec::new();
    for ep_name in entry_points {
        let (index, ep) = module
            .entry_points
            .iter()
            .enumerate()
            .find(|(_, e)| e.name == *ep_name)
            .ok_or_else(|| Error::Invalid(format!("{}: no entry point `{ep_name}`", kernel.name)))?;
        let stage = match ep.stage {
            naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
            _ => wgpu::ShaderStages::COMPUTE,
        };
        let uses = kernel.info.get_entry_point(index);
        for (handle, var) in module.global_variables.iter() {
            let Some(rb) = &var.binding else { continue };
            if uses[handle].is_empty() {
                continue;
            }
            let name = var.name.clone().unwrap_or_default();
            if let Some(b) = out.iter_mut().find(|b| b.group == rb.group && b.binding == rb.binding) {
                b.visibility |= stage;
                continue;
            }
            let kind = kind_of(module, var, sampled.contains(&handle))
                .map_err(|m| Error::Invalid(format!("{}: `{name}`: {m}", kernel.name)))?;
            out.push(Binding { name, group: rb.group, binding: rb.binding, kind, visibility: stage });
        }
    }
    out.sort_by_key(|b| (b.group, b.binding));
    Ok(out)
}

/// Globals used as the image of a sampling expression.
fn sampled_globals(module: &naga::Module) -> Vec<naga::Handle<naga::GlobalVariable>> {
    let functions =
        module.functions.iter().map(|(_, f)| f).chain(module.entry_points.iter().map(|e| &e.function));
    let mut out = Vec::new();
    for f in functions {
        for (_, e) in f.expressions.iter() {
            if let naga::Expression::ImageSample { image, .. } = e {
                if let naga::Expression::GlobalVariable(g) = f.expressions[*image] {
                    out.push(g);
                }
            }
        }
    }
    out
}

fn kind_of(module: &naga::Module, var: &naga::GlobalVariable, filtered: bool) -> Result<BindingKind, String> {
    Ok(match var.space {
        naga::AddressSpace::Uniform => BindingKind::Uniform,
        naga::AddressSpace::Storage { access } => {
            BindingKind::Storage { read_only: !access.contains(naga::StorageAccess::STORE) }
        }
        naga::AddressSpace::Handle => match &module.types[var.ty].inner {
            naga::TypeInner::Sampler { .. } => BindingKind::Sampler,
            naga::TypeInner::Image { dim, arrayed, class } => {
                let dim = view_dim(*dim, *arrayed);
                match class {
                    naga::ImageClass::Sampled { .. } => BindingKind::Texture { dim, depth: false, filtered },
                    naga::ImageClass::Depth { .. } => BindingKind::Texture { dim, depth: true, filtered },
                    naga::ImageClass::Storage { format, access } => BindingKind::StorageTexture {
                        dim,
                        format: texture_format(*format)?,
                        write_only: !access.contains(naga::StorageAccess::LOAD),
                    },
                    naga::ImageClass::External => return Err("external textures are not supported".into()),
                }
            }
            other => return Err(format!("unsupported handle type {other:?}")),
        },
        other => return Err(format!("unsupported address space {other:?}")),
    })
}

fn view_dim(dim: naga::ImageDimension, arrayed: bool) -> wgpu::TextureViewDimension {
    use wgpu::TextureViewDimension as V;
    match (dim, arrayed) {
        (naga::ImageDimension::D1, _) => V::D1,
        (naga::ImageDimension::D2, false) => V::D2,
        (naga::ImageDimension::D2, true) => V::D2Array,
        (naga::ImageDimension::D3, _) => V::D3,
        (naga::ImageDimension::Cube, false) => V::Cube,
        (naga::ImageDimension::Cube, true) => V::CubeArray,
    }
}

fn texture_format(f: naga::StorageFormat) -> Result<wgpu::TextureFormat, String> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Ok(match f {
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::Rgba8Snorm => T::Rgba8Snorm,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba32Float => T::Rgba32Float,
        S::R32Float => T::R32Float,
        S::R32Uint => T::R32Uint,
        S::Rg32Float => T::Rg32Float,
        other => return Err(format!("storage format {other:?} is not supported by voltex")),
    })
}

/// The bind group layout entry of a reflected binding.
pub(crate) fn layout_entry(b: &Binding) -> wgpu::BindGroupLayoutEntry {
    let ty = match &b.kind {
        BindingKind::Uniform => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        BindingKind::Storage { read_only } => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: *read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        BindingKind::Texture { dim, depth, filtered } => wgpu::BindingType::Texture {
            sample_type: if *depth {
                wgpu::TextureSampleType::Depth
            } else {
                wgpu::TextureSampleType::Float { filterable: *filtered }
            },
            view_dimension: *dim,
            multisampled: false,
        },
        BindingKind::StorageTexture { dim, format, write_only } => wgpu::BindingType::StorageTexture {
            access: if *write_only {
                wgpu::StorageTextureAccess::WriteOnly
            } else {
                wgpu::StorageTextureAccess::ReadWrite
            },
            format: *format,
            view_dimension: *dim,
        },
        BindingKind::Sampler => wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
    };
    wgpu::BindGroupLayoutEntry { binding: b.binding, visibility: b.visibility, ty, count: None }
}

/// Names of the `override` constants a module declares, with whether each has a default.
pub(crate) fn overrides(kernel: &Kernel) -> Vec<(String, bool)> {
    kernel
        .module
        .overrides
        .iter()
        .filter_map(|(_, o)| o.name.clone().map(|n| (n, o.init.is_some())))
        .collect()
}

/// Workgroup size of a compute entry point.
pub(crate) fn workgroup_size(kernel: &Kernel, entry_point: &str) -> Option<[u32; 3]> {
    kernel.module.entry_points.iter().find(|e| e.name == entry_point).map(|e| e.workgroup_size)
}

/// The values of `kernel`'s `const name: array<u32, N>`, or `None` where it has no such
/// constant. For tables a kernel indexes by a varying index: uploaded into a storage buffer
/// instead (llvmpipe copies a const array indexed so into every invocation's private memory).
pub(crate) fn const_u32_array(kernel: &Kernel, name: &str) -> Option<Vec<u32>> {
    let module = &kernel.module;
    let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name))?;
    let naga::Expression::Compose { components, .. } = &module.global_expressions[c.init] else {
        return None;
    };
    components
        .iter()
        .map(|&h| match module.global_expressions[h] {
            naga::Expression::Literal(naga::Literal::U32(v)) => Some(v),
            _ => None,
        })
        .collect()
}
