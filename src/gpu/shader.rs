//! WGSL loading: `#include "shared/x.wgsl"` expansion with a line map back to the original files,
//! then naga parsing and validation, so every shader error names `file:line:col` before any
//! pipeline is made.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::error::{Error, FileLoc, Result};
use crate::gpu::sources::{Source, Sources};

/// A validated WGSL kernel: the naga module (handed to wgpu as IR, parsed once), its validation
/// info (used for reflection), and every file it was assembled from (on disk, or
/// `<embedded>/wgsl/...`).
#[derive(Clone)]
pub struct Kernel {
    /// Path relative to the WGSL root, e.g. `view_slices/emit_slices.wgsl`.
    pub(crate) name: String,
    /// The WGSL module after includes, as naga parsed it.
    pub module: naga::Module,
    pub(crate) info: naga::valid::ModuleInfo,
    /// The files the source was read from (the kernel and its includes), to watch for edits.
    pub files: Vec<PathBuf>,
    /// Hash of the expanded source: the GPU module is reused while it is unchanged.
    pub(crate) source_hash: u64,
}

/// Expanded source plus, for each expanded line, the file and line it came from.
#[derive(Default)]
struct Expanded {
    text: String,
    origin: Vec<(usize, usize)>, // (index into files, 1-based line)
    files: Vec<PathBuf>,
    /// The shaders looked up (the kernel and its includes, relative to the WGSL root).
    rels: Vec<String>,
}

fn expand(sources: &Sources, rel: &str, out: &mut Expanded, from: Option<FileLoc>) -> Result<()> {
    out.rels.push(rel.to_string());
    let found = sources.shader(rel).map_err(|e| match &from {
        Some(loc) => Error::at(loc.clone(), format!("cannot include {rel}: {e}")),
        None => e,
    })?;
    let Some(Source { path, text, .. }) = found else {
        return Err(match &from {
            Some(loc) => {
                Error::at(loc.clone(), format!("cannot include {rel}: not found in {}", sources.describe()))
            }
            None => Error::Invalid(format!("shader `{rel}` not found in {}", sources.describe())),
        });
    };
    if out.files.contains(&path) {
        return Ok(()); // each include once: shared files carry no guards
    }
    out.files.push(path.clone());
    let file_index = out.files.len() - 1;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix("#include") {
            let name = rest.trim().trim_matches('"');
            let col = line.len() - trimmed.len() + 1;
            if name.is_empty() || !rest.trim().starts_with('"') {
                return Err(Error::at(
                    FileLoc::new(&path, i + 1, col),
                    "expected #include \"shared/name.wgsl\"",
                ));
            }
            expand(sources, name, out, Some(FileLoc::new(&path, i + 1, col)))?;
            continue;
        }
        out.text.push_str(line);
        out.text.push('\n');
        out.origin.push((file_index, i + 1));
    }
    Ok(())
}

impl Expanded {
    fn locate(&self, line: u32, col: u32) -> FileLoc {
        match self.origin.get((line as usize).saturating_sub(1)) {
            Some(&(file, orig)) => FileLoc::new(&self.files[file], orig, col as usize),
            // Past the last line (an error at the end of the input, after the newline each
            // expanded line ends with): the end of the last line, in the file it came from.
            None => match self.origin.last() {
                Some(&(file, orig)) => {
                    let width = self.text.lines().last().map_or(0, |l| l.chars().count());
                    FileLoc::new(&self.files[file], orig, width + 1)
                }
                None => FileLoc::new(&self.files[0], 1, 1),
            },
        }
    }
}

/// The naga capabilities voltex kernels may use on any adapter it supports.
pub(crate) fn capabilities() -> naga::valid::Capabilities {
    naga::valid::Capabilities::empty()
}

/// Loads, expands and validates `root/rel`, reading only files under the folder `root`.
pub fn load(root: &Path, rel: &str) -> Result<Kernel> {
    load_from(&Sources::folder(root), rel)
}

/// Loads, expands and validates the shader `rel` and its includes, each looked up in `sources`.
pub fn load_from(sources: &Sources, rel: &str) -> Result<Kernel> {
    let mut ex = Expanded::default();
    expand(sources, rel, &mut ex, None)?;
    load_expanded(rel, ex)
}

/// A kernel loaded before, with what its lookups found on disk (see [`load_shared`]).
struct Loaded {
    rels: Vec<String>,
    found: Vec<(PathBuf, Option<(std::time::SystemTime, u64)>)>,
    kernel: Arc<Kernel>,
}

type KernelCache = HashMap<(Sources, String), Loaded>;

/// Like [`load_from`], shared: a kernel loaded before in this process is handed out again while
/// every lookup its expansion made finds the same files with the same modification times and
/// lengths (a `stat` each, no read), so planning an unchanged scene again reads and validates
/// no WGSL. An edited file, or a new one that now shadows another, loads it anew.
pub(crate) fn load_shared(sources: &Sources, rel: &str) -> Result<Arc<Kernel>> {
    static KERNELS: Mutex<Option<KernelCache>> = Mutex::new(None);
    let key = (sources.clone(), rel.to_string());
    let found = |rels: &[String]| rels.iter().flat_map(|r| sources.probe(r)).collect::<Vec<_>>();
    if let Some(l) = KERNELS.lock().unwrap().get_or_insert_with(HashMap::new).get(&key) {
        if found(&l.rels) == l.found {
            return Ok(l.kernel.clone());
        }
    }
    let mut ex = Expanded::default();
    expand(sources, rel, &mut ex, None)?;
    let rels = ex.rels.clone();
    // Stamped before validation: an edit made meanwhile is seen by the next load.
    let stamp = found(&rels);
    let kernel = Arc::new(load_expanded(rel, ex)?);
    let loaded = Loaded { rels, found: stamp, kernel: kernel.clone() };
    KERNELS.lock().unwrap().get_or_insert_with(HashMap::new).insert(key, loaded);
    Ok(kernel)
}

/// The hash of the expanded source of `rel` ([`Kernel::source_hash`] of the kernel it loads):
/// cheap enough for every rebuild to ask whether a kernel changed (see [`load_shared`]).
pub(crate) fn source_hash(sources: &Sources, rel: &str) -> Result<u64> {
    Ok(load_shared(sources, rel)?.source_hash)
}

/// Validates WGSL given as text (tests and tools); `path` is only used in messages.
pub fn load_str(path: &Path, source: &str) -> Result<Kernel> {
    let ex = Expanded {
        text: source.to_string(),
        origin: (1..=source.lines().count()).map(|l| (0, l)).collect(),
        files: vec![path.to_path_buf()],
        rels: Vec::new(),
    };
    load_expanded(&path.display().to_string(), ex)
}

fn load_expanded(name: &str, ex: Expanded) -> Result<Kernel> {
    let start = std::time::Instant::now();
    let kernel = validate(name, ex);
    crate::work::shader_validated(start);
    kernel
}

fn validate(name: &str, ex: Expanded) -> Result<Kernel> {
    let module = naga::front::wgsl::parse_str(&ex.text).map_err(|e| {
        let loc = e.location(&ex.text);
        let (line, col) = loc.map(|l| (l.line_number, l.line_position)).unwrap_or((1, 1));
        Error::at(
            ex.locate(line, col),
            format!("WGSL parse error: {}", first_line(&e.emit_to_string(&ex.text))),
        )
    })?;
    // Before validation, whose set of locations took 512 MiB for `@location(4294967295)`.
    check_locations(&module, &ex, &wgpu::Limits::default())?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities())
        .validate(&module)
        .map_err(|e| {
            let (line, col) =
                e.location(&ex.text).map(|l| (l.line_number, l.line_position)).unwrap_or((1, 1));
            let mut msg = e.as_inner().to_string();
            let mut src: &dyn std::error::Error = e.as_inner();
            while let Some(next) = src.source() {
                msg.push_str(": ");
                msg.push_str(&next.to_string());
                src = next;
            }
            Error::at(ex.locate(line, col), format!("WGSL validation error: {msg}"))
        })?;
    check_limits(&module, &ex)?;
    let source_hash = crate::gpu::cache::key(&ex.text);
    Ok(Kernel { name: name.to_string(), module, info, files: ex.files, source_hash })
}

impl Kernel {
    /// The same kernel with the storage texture `global` declared in `format` (same access and
    /// dimension), re-validated: e.g. a bake writing `rgba8unorm` made to write `rgba32float`,
    /// so its results can be read back at full precision (`voltex export`).
    pub(crate) fn with_storage_format(mut self, global: &str, format: naga::StorageFormat) -> Result<Kernel> {
        let wrong = |what: &str| Error::Invalid(format!("{}: `{global}` {what}", self.name));
        let (_, var) = (self.module.global_variables.iter_mut())
            .find(|(_, g)| g.name.as_deref() == Some(global))
            .ok_or_else(|| wrong("is not a global of this kernel"))?;
        let naga::TypeInner::Image { dim, arrayed, class: naga::ImageClass::Storage { access, .. } } =
            self.module.types[var.ty].inner
        else {
            return Err(wrong("is not a storage texture"));
        };
        let class = naga::ImageClass::Storage { format, access };
        let inner = naga::TypeInner::Image { dim, arrayed, class };
        var.ty = self.module.types.insert(naga::Type { name: None, inner }, naga::Span::UNDEFINED);
        self.info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities())
            .validate(&self.module)
            .map_err(|e| wrong(&format!("cannot be {format:?}: {}", e.as_inner())))?;
        self.source_hash ^= crate::gpu::cache::key(&format!("{global}:{format:?}"));
        Ok(self)
    }
}

/// Most bytes of `var<private>` or `var<function>` memory one variable may take: naga accepts
/// any size, and drivers fail late (or crash) on huge per-invocation arrays.
pub(crate) const MAX_PRIVATE_BYTES: u64 = 64 << 10;

/// Checks naga accepts but a device may not: workgroup sizes, workgroup memory and binding
/// indices against WebGPU's default limits (what every adapter offers), and per-invocation
/// arrays against [`MAX_PRIVATE_BYTES`], each at its WGSL position.
fn check_limits(module: &naga::Module, ex: &Expanded) -> Result<()> {
    let limits = wgpu::Limits::default();
    let at = |span: naga::Span| {
        let l = span.location(&ex.text);
        ex.locate(l.line_number.max(1), l.line_position.max(1))
    };
    let size = |ty: naga::Handle<naga::Type>| module.types[ty].inner.try_size(module.to_ctx()).map(u64::from);
    for ep in module.entry_points.iter().filter(|ep| ep.stage == naga::ShaderStage::Compute) {
        let [x, y, z] = ep.workgroup_size;
        let max = [
            limits.max_compute_workgroup_size_x,
            limits.max_compute_workgroup_size_y,
            limits.max_compute_workgroup_size_z,
        ];
        let total = x as u64 * y as u64 * z as u64;
        let per_axis = [x, y, z].iter().zip(max).any(|(&v, m)| v > m);
        if per_axis || total > limits.max_compute_invocations_per_workgroup as u64 {
            // naga keeps no span for the attribute: the last `@workgroup_size` before the entry point.
            let fn_at = ex.text.find(&format!("fn {}(", ep.name)).unwrap_or(ex.text.len());
            let attr = ex.text[..fn_at].rfind("@workgroup_size").unwrap_or(fn_at);
            let (line, col) = crate::error::line_col(&ex.text, attr);
            return Err(Error::at(
                ex.locate(line as u32, col as u32),
                format!(
                    "entry point `{}`: workgroup size ({x}, {y}, {z}) is beyond the limits of \
                     ({}, {}, {}) and {} invocations in all",
                    ep.name, max[0], max[1], max[2], limits.max_compute_invocations_per_workgroup
                ),
            ));
        }
    }
    let mut workgroup = 0u64;
    for (h, g) in module.global_variables.iter() {
        let name = g.name.as_deref().unwrap_or("?");
        if let Some(b) = &g.binding {
            if b.group >= limits.max_bind_groups || b.binding >= limits.max_bindings_per_bind_group {
                return Err(Error::at(
                    at(module.global_variables.get_span(h)),
                    format!(
                        "`{name}` is at @group({}) @binding({}): groups go up to {} and bindings up to {}",
                        b.group,
                        b.binding,
                        limits.max_bind_groups - 1,
                        limits.max_bindings_per_bind_group - 1
                    ),
                ));
            }
        }
        let Some(bytes) = size(g.ty) else { continue };
        match g.space {
            naga::AddressSpace::WorkGroup => {
                workgroup += bytes;
                if workgroup > limits.max_compute_workgroup_storage_size as u64 {
                    return Err(Error::at(
                        at(module.global_variables.get_span(h)),
                        format!(
                            "var<workgroup> `{name}` brings workgroup memory to {workgroup} bytes: at most {} are allowed",
                            limits.max_compute_workgroup_storage_size
                        ),
                    ));
                }
            }
            naga::AddressSpace::Private if bytes > MAX_PRIVATE_BYTES => {
                return Err(Error::at(
                    at(module.global_variables.get_span(h)),
                    format!("var<private> `{name}` takes {bytes} bytes per invocation: at most {MAX_PRIVATE_BYTES} are allowed"),
                ));
            }
            _ => {}
        }
    }
    let functions =
        module.functions.iter().map(|(_, f)| f).chain(module.entry_points.iter().map(|e| &e.function));
    for f in functions {
        for (h, v) in f.local_variables.iter() {
            let Some(bytes) = size(v.ty) else { continue };
            if bytes > MAX_PRIVATE_BYTES {
                let name = v.name.as_deref().unwrap_or("?");
                return Err(Error::at(
                    at(f.local_variables.get_span(h)),
                    format!("var `{name}` takes {bytes} bytes per invocation: at most {MAX_PRIVATE_BYTES} are allowed"),
                ));
            }
        }
    }
    Ok(())
}

/// Entry points' `@location`s against the limits of their stage and direction: naga accepts any
/// (after a bit set of 512 MiB for `@location(4294967295)`), and wgpu's pipeline fails later.
fn check_locations(module: &naga::Module, ex: &Expanded, limits: &wgpu::Limits) -> Result<()> {
    fn collect(
        module: &naga::Module,
        ty: naga::Handle<naga::Type>,
        b: Option<&naga::Binding>,
        out: &mut Vec<u32>,
    ) {
        match (b, &module.types[ty].inner) {
            (Some(naga::Binding::Location { location, .. }), _) => out.push(*location),
            (None, naga::TypeInner::Struct { members, .. }) => {
                members.iter().for_each(|m| collect(module, m.ty, m.binding.as_ref(), out))
            }
            _ => {}
        }
    }
    for ep in module.entry_points.iter() {
        let (inputs, outputs) = match ep.stage {
            naga::ShaderStage::Vertex => {
                (limits.max_vertex_attributes, limits.max_inter_stage_shader_variables)
            }
            naga::ShaderStage::Fragment => {
                (limits.max_inter_stage_shader_variables, limits.max_color_attachments)
            }
            _ => continue,
        };
        let (mut ins, mut outs) = (Vec::new(), Vec::new());
        for a in &ep.function.arguments {
            collect(module, a.ty, a.binding.as_ref(), &mut ins);
        }
        if let Some(r) = &ep.function.result {
            collect(module, r.ty, r.binding.as_ref(), &mut outs);
        }
        let over = |(list, max, what): (Vec<u32>, u32, &'static str)| {
            list.into_iter().find(|&l| l >= max).map(|l| (l, max, what))
        };
        let bad = [(ins, inputs, "inputs"), (outs, outputs, "outputs")].into_iter().find_map(over);
        if let Some((location, max, what)) = bad {
            // naga keeps no span for the attribute: the `@location(..)` that says it, else the entry point.
            let number = |a: &str| {
                let n = a.trim().trim_end_matches(['u', 'i']);
                n.strip_prefix("0x").map_or_else(|| n.parse().ok(), |h| u64::from_str_radix(h, 16).ok())
            };
            let attr = ex.text.match_indices("@location(").map(|(i, m)| i + m.len()).find(|&i| {
                let arg = &ex.text[i..i + ex.text[i..].find(')').unwrap_or(0)];
                number(arg) == Some(location as u64)
            });
            let at = attr.or_else(|| ex.text.find(&format!("fn {}(", ep.name))).unwrap_or(0);
            let (line, col) = crate::error::line_col(&ex.text, at);
            return Err(Error::at(
                ex.locate(line as u32, col as u32),
                format!(
                    "entry point `{}`: @location({location}) among its {what}: {:?} {what} go up to @location({})",
                    ep.name,
                    ep.stage,
                    max - 1
                ),
            ));
        }
    }
    Ok(())
}

fn first_line(diagnostic: &str) -> String {
    diagnostic.lines().next().unwrap_or("").trim_start_matches("error: ").to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_error_names_the_included_file_and_line() {
        let dir = std::env::temp_dir().join(format!("voltex-shader-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("shared")).unwrap();
        std::fs::write(
            dir.join("shared/a.wgsl"),
            "fn a() -> f32 { return 1.0; }\nfn b() -> f32 { return 1.0 +; }\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("k.wgsl"),
            "// k\n#include \"shared/a.wgsl\"\n@compute @workgroup_size(1) fn main() {}\n",
        )
        .unwrap();
        let err = load(&dir, "k.wgsl").err().unwrap().to_string();
        assert!(err.contains("shared/a.wgsl:2:"), "{err}");
        std::fs::write(dir.join("shared/a.wgsl"), "fn a() -> f32 { return 1.0; }\n").unwrap();
        std::fs::write(dir.join("k.wgsl"), "#include \"shared/a.wgsl\"\nfn c() -> u32 { return a(); }\n")
            .unwrap();
        let err = load(&dir, "k.wgsl").err().unwrap().to_string();
        assert!(err.contains("k.wgsl:2:"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
