//! Planning a graph against a scene: instances per pass, kernels loaded and reflected, pass order
//! from reads and writes, and pruning of passes and resources the scene does not need.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::gpu::reflect::{self, Binding};
use crate::gpu::shader::{self, Kernel};
use crate::gpu::sources::Sources;
use crate::graph::{Draw, Graph, Instances, PassDecl, ResourceDecl, Vocabulary};

/// What the planner needs to know of a scene object.
#[derive(Debug, Clone)]
pub struct ObjectInfo {
    pub name: String,
    /// Filters this object matches (e.g. `ViewSlices` for objects drawn by that method).
    pub filters: Vec<&'static str>,
    /// Distance of the object's centre from the camera: instances run back to front.
    pub distance: f64,
    /// Order among instances at the same distance (the chunks of one sweep, back to front).
    pub order: u32,
}

pub struct PlannedPass {
    pub decl: PassDecl,
    pub kernel: Arc<Kernel>,
    pub bindings: Vec<Binding>,
    pub reads: BTreeSet<String>,
    pub writes: BTreeSet<String>,
    /// `None`: once per frame; otherwise the object indices, back to front.
    pub instances: Option<Vec<usize>>,
}

pub struct Plan {
    pub passes: Vec<PlannedPass>,
    /// Graph textures some kept pass uses.
    pub textures: BTreeMap<String, ResourceDecl>,
    /// One line per pruned pass or resource, saying why.
    pub pruned: Vec<String>,
    /// The runtime's names it was planned against.
    pub vocabulary: Vocabulary,
}

/// Plans `graph` for `objects`, its shaders looked up in `sources` (the graph's folder first when
/// the caller put it there: see [`Sources::beside`]), its filters and counts checked against
/// `vocabulary`.
pub fn plan(
    graph: &Graph,
    sources: &Sources,
    objects: &[ObjectInfo],
    vocabulary: &Vocabulary,
) -> Result<Plan> {
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
        let kernel = match kernels.get(decl.shader()) {
            Some(k) => k.clone(),
            None => {
                if sources.shader(decl.shader())?.is_none() {
                    return Err(graph.error_at(
                        decl.shader(),
                        format!("shader `{}` not found in {}", decl.shader(), sources.describe()),
                    ));
                }
                let k = Arc::new(shader::load_from(sources, decl.shader())?);
                kernels.insert(decl.shader().to_string(), k.clone());
                k
            }
        };
        let bindings = reflect::bindings(&kernel, &decl.entry_points())
            .map_err(|e| graph.error_at(decl.name(), format!("pass `{}`: {e}", decl.name())))?;
        let (reads, writes) = accesses(decl, &bindings);
        candidates.push(PlannedPass { decl: decl.clone(), kernel, bindings, reads, writes, instances });
    }
    let ordered = order(graph, candidates)?;
    let mut passes = live(&graph.file.outputs, ordered, &mut pruned);
    passes.shrink_to_fit();
    let used: BTreeSet<&String> = passes.iter().flat_map(|p| p.reads.iter().chain(p.writes.iter())).collect();
    let mut textures = BTreeMap::new();
    for (name, decl) in &graph.file.resources {
        if used.contains(name) {
            textures.insert(name.clone(), decl.clone());
        } else {
            pruned.push(format!("resource {name}: no kept pass uses it"));
        }
    }
    Ok(Plan { passes, textures, pruned, vocabulary: vocabulary.clone() })
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
    /// Distinct kernels (WGSL files) the plan compiles.
    pub fn kernels(&self) -> BTreeSet<&str> {
        self.passes.iter().map(|p| p.decl.shader()).collect()
    }
}

/// Checks a count name against those the runtime provides.
pub fn check_count(graph: &Graph, count: &str, known: &[&str]) -> Result<()> {
    if count.parse::<u32>().is_ok() || known.contains(&count) {
        return Ok(());
    }
    Err(graph.error_at(count, format!("unknown count `{count}`; expected a number or one of {known:?}")))
}

pub fn unknown_resource(graph: &Graph, pass: &str, name: &str) -> Error {
    graph.error_at(
        pass,
        format!(
            "pass `{pass}` uses `{name}`, which is neither a graph resource nor one the runtime provides"
        ),
    )
}
