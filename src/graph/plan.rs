//! Planning a graph against a scene: instances per pass, kernels loaded and reflected, pass order
//! from reads and writes, and pruning of passes and resources the scene does not need.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::gpu::reflect::{self, Binding};
use crate::gpu::shader::{self, Kernel};
use crate::gpu::sources::Sources;
use crate::graph::expr::Expr;
use crate::graph::{
    BufferClear, Draw, Format, Graph, Instances, PassDecl, ResourceDecl, TextureSize, Value, Vocabulary,
};

/// What the planner needs to know of a scene object.
#[derive(Debug, Clone)]
pub struct ObjectInfo {
    /// The object's name in the scene.
    pub name: String,
    /// Filters this object matches (e.g. `ViewSlices` for objects drawn by that method).
    pub filters: Vec<&'static str>,
    /// Distance of the object's centre from the camera: instances run back to front.
    pub distance: f64,
    /// Order among instances at the same distance (the chunks of one sweep, back to front).
    pub order: u32,
}

/// A pass of the plan: its declaration, kernel, bindings and what it reads and writes.
pub struct PlannedPass {
    /// The pass as the graph file declares it.
    pub decl: PassDecl,
    pub(crate) kernel: Arc<Kernel>,
    /// The WGSL globals it binds, as reflection found them.
    pub bindings: Vec<Binding>,
    /// Resources it reads.
    pub reads: BTreeSet<String>,
    /// Resources it writes.
    pub writes: BTreeSet<String>,
    /// `None`: once per frame; otherwise the object indices, back to front.
    pub instances: Option<Vec<usize>>,
}

/// A graph buffer some kept pass uses, sized for the frame.
#[derive(Debug, Clone)]
pub struct PlannedBuffer {
    /// Size in bytes.
    pub bytes: u64,
    /// Zeroed every frame before the first pass that uses it.
    pub clear: bool,
    /// Some pass draws with it as indirect arguments.
    pub(crate) indirect: bool,
}

/// A graph planned against a scene: the kept passes in order and the resources they use.
pub struct Plan {
    /// The kept passes, in execution order.
    pub passes: Vec<PlannedPass>,
    /// Graph textures some kept pass uses.
    pub textures: BTreeMap<String, ResourceDecl>,
    /// Graph buffers some kept pass uses.
    pub buffers: BTreeMap<String, PlannedBuffer>,
    /// Graph parameters some kept pass uses.
    pub parameters: BTreeMap<String, Value>,
    /// One line per pruned pass or resource, saying why.
    pub pruned: Vec<String>,
    /// The runtime's names it was planned against.
    pub(crate) vocabulary: Vocabulary,
}

/// Counts known for the whole frame when the graph is planned: graph buffers are sized by them.
pub(crate) const FRAME_COUNTS: &[&str] =
    &[crate::gpu::bindings::counts::WIDTH, crate::gpu::bindings::counts::HEIGHT];

/// Plans `graph` for `objects` and an output of `size` pixels, its shaders looked up in `sources`
/// (the graph's folder first when the caller put it there: see [`Sources::beside`]), its filters
/// and counts checked against `vocabulary`, whose resource names its own resources may not take.
/// A first output that is a texture is read back as the frame's image (what a render writes):
/// it must be Rgba32Float or R32Float and of the frame's size, which the readback found only
/// after the GPU work. A buffer output (a debug or benchmark graph) is left to what reads it.
pub(crate) fn check_image_output(graph: &Graph, size: (u32, u32)) -> Result<()> {
    let Some(first) = graph.file.outputs.first() else { return Ok(()) };
    let Some(ResourceDecl::Texture { format, size: texture_size, .. }) = graph.file.resources.get(first)
    else {
        return Ok(());
    };
    let extent = match texture_size {
        TextureSize::Output => size,
        TextureSize::Fixed(w, h) => (*w, *h),
    };
    let msg = if !matches!(format, Format::Rgba32Float | Format::R32Float) {
        format!("output `{first}` is {format:?}: the first output is read back as the image, from an Rgba32Float or R32Float texture")
    } else if extent != size {
        format!(
            "output `{first}` is {}x{}: the first output is read back as the image, at the frame's size {}x{}",
            extent.0, extent.1, size.0, size.1
        )
    } else {
        return Ok(());
    };
    Err(graph.error_at_output(first, msg))
}

/// The targets of a raster pass must have one size (at the frame's `size`): wgpu refuses
/// differing attachments only when the frame is recorded.
fn check_target_sizes(graph: &Graph, decl: &PassDecl, size: (u32, u32)) -> Result<()> {
    let PassDecl::Raster { targets, depth, .. } = decl else { return Ok(()) };
    let extent = |name: &str| match graph.file.resources.get(name) {
        Some(ResourceDecl::Texture { size: TextureSize::Fixed(w, h), .. }) => Some((*w, *h)),
        Some(ResourceDecl::Texture { .. }) => Some(size),
        _ => None,
    };
    let colour = targets.iter().map(|t| (&t.resource, "targets"));
    let mut first: Option<(&String, (u32, u32))> = None;
    for (name, field) in colour.chain(depth.iter().map(|d| (&d.resource, "depth"))) {
        let Some(e) = extent(name) else { continue };
        match first {
            None => first = Some((name, e)),
            Some((f, (w, h))) if (w, h) != e => {
                let msg = format!(
                    "pass `{}`: target `{name}` is {}x{} but target `{f}` is {w}x{h}: the targets of a raster pass \
                     must have one size",
                    decl.name(),
                    e.0,
                    e.1
                );
                return Err(graph.error_in_pass(decl.name(), field, name, msg));
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// Plans `graph` for the scene's `objects` at `size`: instances per pass, kernels loaded and
/// reflected, passes ordered by reads and writes, and what no output needs pruned; errors at the
/// graph's `file:line:col`.
pub fn plan(
    graph: &Graph,
    sources: &Sources,
    objects: &[ObjectInfo],
    size: (u32, u32),
    vocabulary: &Vocabulary,
) -> Result<Plan> {
    if let Some(n) = graph.file.resources.keys().find(|n| vocabulary.resources.contains(&n.as_str())) {
        return Err(graph
            .error_at_resource(n, format!("resource `{n}` is one the runtime provides: pick another name")));
    }
    let sizes = buffer_sizes(graph, size, vocabulary)?;
    let mut kernels: BTreeMap<String, Arc<Kernel>> = BTreeMap::new();
    let mut candidates = Vec::new();
    let mut pruned = Vec::new();
    for decl in &graph.file.passes {
        super::exec::check_counts(graph, decl, &vocabulary.counts)?;
        let instances = match decl.instances() {
            Instances::Frame => None,
            Instances::Objects(filter) => {
                if !vocabulary.filters.contains(&filter.as_str()) {
                    return Err(graph.error_at(
                        filter,
                        format!("unknown object filter `{filter}`; expected one of {:?}", vocabulary.filters),
                    ));
                }
                let mut ids: Vec<usize> =
                    (0..objects.len()).filter(|&i| objects[i].filters.contains(&filter.as_str())).collect();
                if ids.is_empty() {
                    pruned.push(format!("pass {}: no object matches {filter}", decl.name()));
                    continue;
                }
                ids.sort_by(|&a, &b| {
                    let (a, b) = (&objects[a], &objects[b]);
                    b.distance.total_cmp(&a.distance).then(a.order.cmp(&b.order))
                });
                Some(ids)
            }
        };
        check_target_sizes(graph, decl, size)?;
        let kernel = match kernels.get(decl.shader()) {
            Some(k) => k.clone(),
            None => {
                if !sources.has_shader(decl.shader()) {
                    return Err(graph.error_at(
                        decl.shader(),
                        format!("shader `{}` not found in {}", decl.shader(), sources.describe()),
                    ));
                }
                let k = shader::load_shared(sources, decl.shader())?;
                kernels.insert(decl.shader().to_string(), k.clone());
                k
            }
        };
        let bindings = reflect::bindings(&kernel, &decl.entry_points())
            .map_err(|e| graph.error_at(decl.name(), format!("pass `{}`: {e}", decl.name())))?;
        check_fragment_outputs(graph, decl, &kernel)?;
        let (reads, writes) = accesses(decl, &bindings);
        candidates.push(PlannedPass { decl: decl.clone(), kernel, bindings, reads, writes, instances });
    }
    let ordered = order(graph, candidates)?;
    let mut passes = live(&graph.file.outputs, ordered, &mut pruned);
    // An output no kept pass writes was never allocated: say so here rather than let the
    // readback fail after the GPU work.
    for out in &graph.file.outputs {
        if !passes.iter().any(|p| p.writes.contains(out)) {
            let why: Vec<&str> =
                pruned.iter().filter(|p| p.starts_with("pass ")).take(4).map(String::as_str).collect();
            let why = if why.is_empty() {
                "no pass writes it".to_string()
            } else {
                format!("pruned: {}", why.join("; "))
            };
            return Err(graph.error_at_output(
                out,
                format!("output `{out}` is written by no pass kept for this scene ({why}): draw an object the passes \
                         that write it match, or render with another graph"),
            ));
        }
    }
    passes.shrink_to_fit();
    let used: BTreeSet<&String> = passes.iter().flat_map(|p| p.reads.iter().chain(p.writes.iter())).collect();
    let mut textures = BTreeMap::new();
    let mut buffers = BTreeMap::new();
    let mut parameters = BTreeMap::new();
    for (name, decl) in &graph.file.resources {
        if !used.contains(name) {
            pruned.push(format!("resource {name}: no kept pass uses it"));
            continue;
        }
        match decl {
            ResourceDecl::Texture { .. } => {
                textures.insert(name.clone(), decl.clone());
            }
            ResourceDecl::Buffer { clear, .. } => {
                let indirect = passes.iter().any(|p| match &p.decl {
                    PassDecl::Raster { draw: Draw::Indirect(b), .. } => b == name,
                    PassDecl::Raster { draw: Draw::DepthSorted { whole, per_plane }, .. } => {
                        whole == name || per_plane == name
                    }
                    _ => false,
                });
                let bytes = sizes[name];
                buffers.insert(
                    name.clone(),
                    PlannedBuffer { bytes, clear: *clear == Some(BufferClear::Zero), indirect },
                );
            }
            ResourceDecl::Parameter(v) => {
                parameters.insert(name.clone(), *v);
            }
        }
    }
    for p in &passes {
        for b in &p.bindings {
            if let Some(decl) = graph.file.resources.get(&b.name) {
                check_binding(graph, p, b, decl, sizes.get(&b.name).copied())?;
            }
        }
    }
    Ok(Plan { passes, textures, buffers, parameters, pruned, vocabulary: vocabulary.clone() })
}

/// A colour target's channels must all come from the fragment output at its location (wgpu
/// refuses the pipeline otherwise, after the bakes): an Rgba target needs a `vec4<f32>`, an
/// R32Float one any float output. A target the fragment does not write is left as the draw finds it.
fn check_fragment_outputs(graph: &Graph, decl: &PassDecl, kernel: &Kernel) -> Result<()> {
    let PassDecl::Raster { targets, fragment, .. } = decl else { return Ok(()) };
    let module = &kernel.module;
    let Some(ep) =
        module.entry_points.iter().find(|e| e.stage == naga::ShaderStage::Fragment && e.name == *fragment)
    else {
        return Ok(());
    };
    let Some(result) = &ep.function.result else { return Ok(()) };
    let mut outputs: Vec<(u32, naga::Handle<naga::Type>)> = Vec::new();
    match (&result.binding, &module.types[result.ty].inner) {
        (Some(naga::Binding::Location { location, .. }), _) => outputs.push((*location, result.ty)),
        (None, naga::TypeInner::Struct { members, .. }) => {
            for m in members {
                if let Some(naga::Binding::Location { location, .. }) = m.binding {
                    outputs.push((location, m.ty));
                }
            }
        }
        _ => {}
    }
    for (i, target) in targets.iter().enumerate() {
        let Some(ResourceDecl::Texture { format, .. }) = graph.file.resources.get(&target.resource) else {
            continue;
        };
        let Some(&(_, ty)) = outputs.iter().find(|(l, _)| *l as usize == i) else { continue };
        let (channels, scalar) = match &module.types[ty].inner {
            naga::TypeInner::Scalar(s) => (1, Some(*s)),
            naga::TypeInner::Vector { size, scalar } => (*size as usize, Some(*scalar)),
            _ => (0, None),
        };
        let needs = if *format == Format::R32Float { 1 } else { 4 };
        if scalar.is_some_and(|s| s.kind == naga::ScalarKind::Float) && channels >= needs {
            continue;
        }
        let msg = format!(
            "pass `{}`: target `{}` is {format:?} ({needs} channel{}), but `{fragment}` writes @location({i}) as {}: \
             the output must have at least the target's channels, as floats",
            decl.name(),
            target.resource,
            if needs == 1 { "" } else { "s" },
            wgsl_type(module, ty)
        );
        return Err(graph.error_in_pass(decl.name(), "targets", &target.resource, msg));
    }
    Ok(())
}

/// The byte size of every graph buffer for an output of `size`: an error at the expression for an
/// unknown or per-object count, at the declaration for a size of zero.
fn buffer_sizes(graph: &Graph, (w, h): (u32, u32), vocabulary: &Vocabulary) -> Result<BTreeMap<String, u64>> {
    let mut out = BTreeMap::new();
    for (name, decl) in &graph.file.resources {
        let ResourceDecl::Buffer { size, .. } = decl else { continue };
        let (text, unit) = size.expr();
        let at = |e: crate::graph::expr::ExprError| {
            graph.error_in_literal(name, text, e.offset, format!("buffer `{name}`: {}", e.message))
        };
        let expr = Expr::parse(text).map_err(at)?;
        for (n, offset) in expr.names() {
            if !FRAME_COUNTS.contains(&n) {
                let why = if vocabulary.counts.contains(&n) {
                    format!("`{n}` is counted per object; a graph buffer is sized for the frame")
                } else {
                    format!("unknown count `{n}`")
                };
                return Err(at(crate::graph::expr::ExprError {
                    offset,
                    message: format!("{why}: a size is numbers and {FRAME_COUNTS:?} joined by `*` and `+`"),
                }));
            }
        }
        let units = expr
            .eval(|n| match n {
                "width" => Some(w as u64),
                "height" => Some(h as u64),
                _ => None,
            })
            .map_err(at)?;
        let bytes = units.checked_mul(unit).ok_or_else(|| {
            graph.error_at_resource(
                name,
                format!("buffer `{name}`: `{text}` x {unit} bytes overflows 64 bits"),
            )
        })?;
        if bytes == 0 {
            return Err(graph.error_at_resource(
                name,
                format!("buffer `{name}` is 0 bytes (`{text}` = 0 at {w}x{h}): a buffer needs at least 4"),
            ));
        }
        out.insert(name.clone(), bytes);
    }
    Ok(out)
}

/// Checks a WGSL global bound to a graph resource: a texture to a texture, a buffer to a storage
/// buffer at least as large as the WGSL type, a parameter to a `var<uniform>` of its type.
fn check_binding(
    graph: &Graph,
    pass: &PlannedPass,
    b: &Binding,
    decl: &ResourceDecl,
    bytes: Option<u64>,
) -> Result<()> {
    use reflect::BindingKind as K;
    let module = &pass.kernel.module;
    let var = module
        .global_variables
        .iter()
        .map(|(_, v)| v)
        .find(|v| v.binding.as_ref().is_some_and(|r| r.group == b.group && r.binding == b.binding));
    let ty = var.map(|v| wgsl_type(module, v.ty)).unwrap_or_default();
    let shader = pass.decl.shader();
    let name = &b.name;
    let wrong = |what: &str| {
        graph.error_at_resource(
            name,
            format!(
                "`{name}` is a graph {what}, but {shader} (pass `{}`) declares `{name}` as {} `{ty}`",
                pass.decl.name(),
                describe_kind(&b.kind)
            ),
        )
    };
    match decl {
        ResourceDecl::Texture { format, .. } => {
            // wgpu refuses these only when the texture or bind group is made; here they have a
            // position in the graph.
            let found = format.wgpu();
            let needs = match b.kind {
                K::StorageTexture { format: want, .. } if want != found => format!("{want:?}"),
                K::Texture { depth, .. } if depth != found.is_depth_stencil_format() => {
                    if depth { "Depth32Float" } else { "a colour format" }.to_string()
                }
                K::Texture { .. } | K::StorageTexture { .. } => return Ok(()),
                _ => return Err(wrong("texture")),
            };
            return Err(graph.error_at_resource(
                name,
                format!(
                    "texture `{name}` is {format:?}, but {shader} (pass `{}`) binds it as {}, which needs {needs}",
                    pass.decl.name(),
                    describe_kind(&b.kind)
                ),
            ));
        }
        ResourceDecl::Buffer { .. } => {
            if !matches!(b.kind, K::Storage { .. }) {
                return Err(wrong("buffer: bind it as `var<storage, read>` or `var<storage, read_write>`"));
            }
            let need = var.map_or(0, |v| module.types[v.ty].inner.size(module.to_ctx()) as u64);
            let have = bytes.unwrap_or(0);
            if have < need {
                return Err(graph.error_at_resource(
                    name,
                    format!(
                        "buffer `{name}` is {have} bytes, but {shader} (pass `{}`) reads it as `{ty}`, at least {need} bytes",
                        pass.decl.name()
                    ),
                ));
            }
        }
        ResourceDecl::Parameter(v) => {
            if !matches!(b.kind, K::Uniform) {
                return Err(wrong("parameter: bind it as `var<uniform>`"));
            }
            if ty != v.wgsl_type() {
                return Err(graph.error_at_resource(
                    name,
                    format!(
                        "parameter `{name}` is declared {} (`{}`), but {shader} (pass `{}`) declares `var<uniform> {name}: {ty}`",
                        match v {
                            Value::F32(_) => "F32",
                            Value::U32(_) => "U32",
                            Value::I32(_) => "I32",
                            Value::Vec4(..) => "Vec4",
                        },
                        v.wgsl_type(),
                        pass.decl.name()
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn describe_kind(kind: &reflect::BindingKind) -> &'static str {
    use reflect::BindingKind as K;
    match kind {
        K::Uniform => "`var<uniform>`",
        K::Storage { read_only: true } => "`var<storage, read>`",
        K::Storage { read_only: false } => "`var<storage, read_write>`",
        K::Texture { depth: false, .. } => "a texture",
        K::Texture { depth: true, .. } => "a depth texture",
        K::StorageTexture { .. } => "a storage texture",
        K::Sampler => "a sampler",
    }
}

/// A WGSL spelling of a naga type, for messages and parameter checks.
fn wgsl_type(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    let scalar = |s: &naga::Scalar| match (s.kind, s.width) {
        (naga::ScalarKind::Float, 4) => "f32".to_string(),
        (naga::ScalarKind::Uint, 4) => "u32".to_string(),
        (naga::ScalarKind::Sint, 4) => "i32".to_string(),
        (naga::ScalarKind::Bool, _) => "bool".to_string(),
        (k, w) => format!("{k:?}{}", w * 8),
    };
    let t = &module.types[ty];
    match &t.inner {
        naga::TypeInner::Scalar(s) => scalar(s),
        naga::TypeInner::Atomic(s) => format!("atomic<{}>", scalar(s)),
        naga::TypeInner::Vector { size, scalar: s } => format!("vec{}<{}>", *size as u8, scalar(s)),
        naga::TypeInner::Matrix { columns, rows, scalar: s } => {
            format!("mat{}x{}<{}>", *columns as u8, *rows as u8, scalar(s))
        }
        naga::TypeInner::Array { base, size, .. } => match size {
            naga::ArraySize::Constant(n) => format!("array<{}, {n}>", wgsl_type(module, *base)),
            _ => format!("array<{}>", wgsl_type(module, *base)),
        },
        _ => t.name.clone().unwrap_or_else(|| format!("{:?}", t.inner)),
    }
}

/// Checks the graph buffers of a plan against an adapter's limits (`voltex plan` has no adapter:
/// the executor calls this).
pub(crate) fn check_buffer_limits(graph: &Graph, plan: &Plan, limits: &wgpu::Limits) -> Result<()> {
    let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    for (name, b) in &plan.buffers {
        if b.bytes > max {
            return Err(graph.error_at_resource(
                name,
                format!(
                    "buffer `{name}` is {} bytes, beyond this adapter's max storage buffer binding size of {max} bytes",
                    b.bytes
                ),
            ));
        }
    }
    Ok(())
}

/// Resources a pass reads and writes: from reflection, render targets, indirect arguments and clears.
fn accesses(decl: &PassDecl, bindings: &[Binding]) -> (BTreeSet<String>, BTreeSet<String>) {
    let mut reads = BTreeSet::new();
    let mut writes = BTreeSet::new();
    for b in bindings {
        if b.kind.writes() {
            writes.insert(b.name.clone());
        }
        if !matches!(b.kind, reflect::BindingKind::StorageTexture { write_only: true, .. }) {
            reads.insert(b.name.clone());
        }
    }
    match decl {
        PassDecl::Compute { clear, .. } => writes.extend(clear.iter().cloned()),
        PassDecl::Raster { targets, depth, draw, .. } => {
            for t in targets {
                writes.insert(t.resource.clone());
                if t.blend != crate::graph::Blend::Replace {
                    reads.insert(t.resource.clone());
                }
            }
            if let Some(d) = depth {
                reads.insert(d.resource.clone());
                if d.write {
                    writes.insert(d.resource.clone());
                }
            }
            match draw {
                Draw::Indirect(buf) => {
                    reads.insert(buf.clone());
                }
                Draw::DepthSorted { whole, per_plane } => {
                    reads.insert(whole.clone());
                    reads.insert(per_plane.clone());
                }
                Draw::Vertices(_) => {}
            }
        }
    }
    (reads, writes)
}

/// Orders passes so that every reader of a resource runs after its writers; writers of the same
/// resource keep their declaration order (blending passes) unless reads and writes already order
/// them the other way. Ties keep declaration order.
fn order(graph: &Graph, passes: Vec<PlannedPass>) -> Result<Vec<PlannedPass>> {
    let n = passes.len();
    let mut deps: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for j in 0..n {
        for i in 0..n {
            let reads_result = i != j
                && passes[i]
                    .writes
                    .iter()
                    .any(|r| passes[j].reads.contains(r) && !passes[j].writes.contains(r));
            if reads_result {
                deps[j].insert(i);
            }
        }
    }
    // Declaration order among writers of a resource is a preference: an edge that would close a
    // cycle (e.g. a blending pass declared before the pass whose depth it reads) is left out.
    for j in 0..n {
        for i in 0..j {
            let writes_together = passes[i].writes.iter().any(|r| passes[j].writes.contains(r));
            if writes_together && !reaches(&deps, i, j) {
                deps[j].insert(i);
            }
        }
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    while order.len() < n {
        let next = (0..n).find(|&j| !done[j] && deps[j].iter().all(|&i| done[i]));
        match next {
            Some(j) => {
                done[j] = true;
                order.push(j);
            }
            None => {
                // Name only the passes on a cycle, not those merely waiting for one.
                let stuck: Vec<&str> = (0..n)
                    .filter(|&j| !done[j] && deps[j].iter().any(|&i| reaches(&deps, i, j)))
                    .map(|j| passes[j].decl.name())
                    .collect();
                return Err(graph.error_at(
                    stuck[0],
                    format!("passes {stuck:?} depend on each other through their reads and writes"),
                ));
            }
        }
    }
    let mut slots: Vec<Option<PlannedPass>> = passes.into_iter().map(Some).collect();
    Ok(order.into_iter().map(|j| slots[j].take().unwrap()).collect())
}

/// Whether pass `to` depends, directly or not, on pass `from` (`to` == `from` counts).
fn reaches(deps: &[BTreeSet<usize>], to: usize, from: usize) -> bool {
    let mut seen = vec![false; deps.len()];
    let mut stack = vec![to];
    while let Some(k) = stack.pop() {
        if k == from {
            return true;
        }
        if !std::mem::replace(&mut seen[k], true) {
            stack.extend(deps[k].iter().copied());
        }
    }
    false
}

/// Keeps the passes that contribute to an output, walking back from the outputs.
fn live(outputs: &[String], passes: Vec<PlannedPass>, pruned: &mut Vec<String>) -> Vec<PlannedPass> {
    let mut needed: BTreeSet<String> = outputs.iter().cloned().collect();
    let mut keep = vec![false; passes.len()];
    for (i, p) in passes.iter().enumerate().rev() {
        if p.writes.iter().any(|w| needed.contains(w)) {
            keep[i] = true;
            needed.extend(p.reads.iter().cloned());
        }
    }
    passes
        .into_iter()
        .zip(keep)
        .filter_map(|(p, k)| {
            if !k {
                pruned.push(format!("pass {}: nothing it writes reaches an output", p.decl.name()));
            }
            k.then_some(p)
        })
        .collect()
}

impl Plan {
    /// Whether `name` is a graph resource (texture, buffer or parameter) the plan allocates.
    pub(crate) fn declares(&self, name: &str) -> bool {
        self.textures.contains_key(name)
            || self.buffers.contains_key(name)
            || self.parameters.contains_key(name)
    }

    /// Distinct kernels (WGSL files) the plan compiles.
    pub fn kernels(&self) -> BTreeSet<&str> {
        self.passes.iter().map(|p| p.decl.shader()).collect()
    }
}

/// Checks a count name against those the runtime provides.
pub(crate) fn check_count(graph: &Graph, count: &str, known: &[&str]) -> Result<()> {
    if count.parse::<u32>().is_ok() || known.contains(&count) {
        return Ok(());
    }
    Err(graph.error_at(count, format!("unknown count `{count}`; expected a number or one of {known:?}")))
}

pub(crate) fn unknown_resource(graph: &Graph, pass: &str, name: &str) -> Error {
    graph.error_at(
        pass,
        format!(
            "pass `{pass}` uses `{name}`, which is neither a graph resource nor one the runtime provides"
        ),
    )
}
