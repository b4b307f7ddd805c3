//! A single compute kernel outside any graph (bakes): loaded, validated and reflected like graph
//! kernels, its globals bound by name from [`Inputs`], pipelines cached per override constants.

use std::borrow::Cow;
use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::gpu::inputs::{override_values, Inputs};
use crate::gpu::reflect::{self, Binding, BindingKind};
use crate::gpu::shader;
use crate::gpu::sources::Sources;
use crate::gpu::GpuContext;

pub(crate) struct ComputeKernel {
    pub(crate) name: String,
    kernel: shader::Kernel,
    bindings: Vec<Binding>,
    bgl: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    pipelines: HashMap<String, wgpu::ComputePipeline>,
    workgroup: [u32; 3],
}

impl ComputeKernel {
    pub(crate) fn load(ctx: &GpuContext, sources: &Sources, name: &str) -> Result<Self> {
        Self::new(ctx, shader::load_from(sources, name)?)
    }

    /// A kernel from validated WGSL (e.g. [`shader::Kernel::with_storage_format`]).
    pub(crate) fn new(ctx: &GpuContext, kernel: shader::Kernel) -> Result<Self> {
        let name = kernel.name.clone();
        let name = name.as_str();
        let bindings = reflect::bindings(&kernel, &["main"])?;
        if bindings.iter().any(|b| b.group != 0) {
            return Err(Error::Invalid(format!("{name}: bake kernels bind everything in @group(0)")));
        }
        let entries: Vec<_> = bindings.iter().map(reflect::layout_entry).collect();
        let bgl = ctx.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(name),
            entries: &entries,
        });
        let layout = ctx.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(name),
            bind_group_layouts: &[Some(&bgl)],
            immediate_size: 0,
        });
        let module = ctx.scoped(name, || {
            ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Naga(Cow::Owned(kernel.module.clone())),
            })
        })?;
        let workgroup = reflect::workgroup_size(&kernel, "main").unwrap_or([1, 1, 1]);
        Ok(Self {
            name: name.to_string(),
            kernel,
            bindings,
            bgl,
            layout,
            module,
            pipelines: HashMap::new(),
            workgroup,
        })
    }

    /// Records a dispatch covering `threads` invocations in its own compute pass.
    pub(crate) fn dispatch(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &Inputs,
        threads: [u32; 3],
    ) -> Result<()> {
        let constants = override_values(&self.kernel, &[inputs]).map_err(|name| {
            Error::Invalid(format!("{}: override `{name}` has no default and no value", self.name))
        })?;
        let key = format!("{constants:?}");
        if !self.pipelines.contains_key(&key) {
            let p = ctx.scoped(&self.name, || {
                ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(&self.name),
                    layout: Some(&self.layout),
                    module: &self.module,
                    entry_point: Some("main"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        zero_initialize_workgroup_memory: true,
                    },
                    cache: None,
                })
            })?;
            self.pipelines.insert(key.clone(), p);
        }
        let mut entries = Vec::new();
        for b in &self.bindings {
            let resource = match b.kind {
                BindingKind::Uniform | BindingKind::Storage { .. } => {
                    inputs.buffers.get(&b.name).map(|x| x.as_entire_binding())
                }
                BindingKind::Texture { .. } | BindingKind::StorageTexture { .. } => {
                    inputs.views.get(&b.name).map(wgpu::BindingResource::TextureView)
                }
                BindingKind::Sampler => inputs.samplers.get(&b.name).map(wgpu::BindingResource::Sampler),
            }
            .ok_or_else(|| Error::Invalid(format!("{}: nothing bound to `{}`", self.name, b.name)))?;
            entries.push(wgpu::BindGroupEntry { binding: b.binding, resource });
        }
        let group = ctx.scoped(&self.name, || {
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&self.name),
                layout: &self.bgl,
                entries: &entries,
            })
        })?;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(&self.name),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipelines[&key]);
        pass.set_bind_group(0, &group, &[]);
        let g: Vec<u32> = (0..3).map(|i| threads[i].div_ceil(self.workgroup[i].max(1))).collect();
        pass.dispatch_workgroups(g[0], g[1], g[2]);
        Ok(())
    }
}
