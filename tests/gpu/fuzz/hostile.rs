//! The hostile inputs of issue 19 as fuzz targets, through what `voltex plan` does: special
//! files wherever a path is read, counts near and beyond the budgets, graph values and WGSL
//! beyond the device's limits, lenient parsing (unknown fields, duplicate keys, invalid UTF-8)
//! and node names that EXR metadata cannot hold.
//!
//! Property: each input is accepted or fails with an error naming its file (and `line:col`
//! where it is about the file's content); no panic; within the runner's bounds on time and
//! memory per input.

use super::{files, root};
use crate::fuzz_support::check_error;
use crate::fuzz_support::ron_items;
use crate::fuzz_support::runner::{accepted, fuzz, LARGE, SMALL};
use crate::fuzz_support::special::{self, grid_obj, Special};

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::render::{Blueprint, MethodKind, RenderOptions};
use voltex::Error;

const FLAT: &str = "scenes/view_slices/flat_box.ron";
const PLANE: &str = "Plane(size: (2.0, 2.0), cells: (4, 4))";

fn example(rel: &str) -> (PathBuf, String) {
    let path = root().join(rel);
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

/// `text` with `from` (which must be there) replaced once by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} is not in the example");
    text.replacen(from, to, 1)
}

/// What `voltex plan` does with scene text claiming to be `path`: parse and check, plan, check
/// the allocations against the limits every adapter offers. `Ok(None)`: rejected as it should
/// be (the error property holds); `Err`: a broken property.
fn planned(path: &Path, text: &str, opts: &RenderOptions) -> Result<Option<Blueprint>, String> {
    let scene = match voltex::scene::parse(text, path) {
        Ok(s) => s,
        Err(e) => return check_error(&e, path, text, true).map(|()| None),
    };
    let limits = voltex::gpu::budget::plan_limits();
    match Blueprint::new(&scene, opts)
        .and_then(|bp| bp.check_limits(&limits, "the plan's limit").map(|()| bp))
    {
        Ok(bp) => Ok(Some(bp)),
        Err(e) => check_error(&e, path, text, false).map(|()| None),
    }
}

/// A fixture: the project's WGSL tree and default graph copied into a scratch folder, so that a
/// case can edit a kernel (found beside the graph, or as the only source) and restore it.
pub(super) struct Tree {
    pub(super) dir: special::Scratch,
}

impl Tree {
    pub(super) fn new(name: &str) -> Self {
        let dir = special::scratch(name);
        crate::common::copy_dir(&root().join("wgsl"), &dir);
        std::fs::copy(root().join("graphs/frame.ron"), dir.join("frame.ron")).unwrap();
        Tree { dir }
    }

    pub(super) fn graph(&self) -> PathBuf {
        self.dir.join("frame.ron")
    }

    /// Runs `f` with `rel` (under the tree) holding `bytes`, then puts the original back (or
    /// removes the file if there was none).
    pub(super) fn with_file<T>(&self, rel: &str, bytes: impl AsRef<[u8]>, f: impl FnOnce() -> T) -> T {
        let path = self.dir.join(rel);
        let original = std::fs::read(&path).ok();
        std::fs::write(&path, bytes).unwrap();
        let out = f();
        match original {
            Some(o) => std::fs::write(&path, o).unwrap(),
            None => std::fs::remove_file(&path).unwrap(),
        }
        out
    }

    pub(super) fn text(&self, rel: &str) -> String {
        std::fs::read_to_string(self.dir.join(rel)).unwrap()
    }
}

/// `line` (modulo the line count) of `text` with `insert` put before it.
fn insert_line(text: &str, line: &Index, insert: &str) -> String {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let k = line.index(lines.len() + 1);
    let mut before = lines[..k].concat();
    if !before.is_empty() && !before.ends_with('\n') {
        before.push('\n');
    }
    format!("{before}{insert}\n{}", lines[k..].concat())
}

// ---------------------------------------------------------------------------------------------
// Special files wherever a path is read.

/// Where a path is read.
#[derive(Debug, Clone, Copy)]
enum Slot {
    Scene,
    /// A mesh opened directly as a scene (`voltex plan x.glb`).
    Asset,
    Graph,
    /// `#include` in a graph kernel (beside the graph).
    GraphInclude,
    /// `#include` in a bake kernel.
    BakeInclude,
    Surface,
    MeshTexel,
    SoftObject,
    HeightImage,
    HeightScale,
    ShapeImage,
    Slices,
}

const SLOTS: [Slot; 12] = [
    Slot::Scene,
    Slot::Asset,
    Slot::Graph,
    Slot::GraphInclude,
    Slot::BakeInclude,
    Slot::Surface,
    Slot::MeshTexel,
    Slot::SoftObject,
    Slot::HeightImage,
    Slot::HeightScale,
    Slot::ShapeImage,
    Slot::Slices,
];

const EXTS: &[&str] = &["ron", "wgsl", "obj", "glb", "gltf", "png", "exr"];
/// Kernels that flat_box's frame runs (an include in a pruned pass is never read).
const GRAPH_KERNELS: &[&str] = &["composite.wgsl", "view_slices/draw_slices.wgsl"];
const BAKE_KERNELS: &[&str] = &[
    "bake/bake_implicit.wgsl",
    "bake/bake_heightfield.wgsl",
    "bake/bake_height_image.wgsl",
    "bake/bake_mesh_grid.wgsl",
    "bake/bake_mesh_texel.wgsl",
    "bake/bake_hypertexture.wgsl",
    "ray_march/bake_transfer.wgsl",
    "axis_slices/bake_axis_slices.wgsl",
];

impl Slot {
    fn exts(self) -> &'static [&'static str] {
        match self {
            Slot::Scene | Slot::Graph => &["ron"],
            Slot::GraphInclude | Slot::BakeInclude => &["wgsl"],
            Slot::Asset | Slot::Surface | Slot::SoftObject => &["obj", "glb", "gltf"],
            Slot::MeshTexel => &["obj", "glb"],
            Slot::HeightImage | Slot::HeightScale | Slot::ShapeImage => &["png", "exr"],
            Slot::Slices => &["stack", "png"],
        }
    }
}

/// One special-file case: the file, and the result with the scene text it came through.
fn special_case(tree: &Tree, slot: Slot, kind: Special, ext: &Index, at: &Index) -> Result<(), String> {
    let sp = tree.dir.join("sp");
    let ext = slot.exts()[ext.index(slot.exts().len())];
    let file = match (slot, ext) {
        (_, "stack") => sp.join(format!("stack_{}", kind.name())),
        _ => sp.join(format!("{}.{ext}", kind.name())),
    };
    let quoted = format!("\"{}\"", file.display());
    let scene = |rel: &str, from: &str, to: &str| {
        let (path, text) = example(rel);
        (path, edit(&text, from, to))
    };
    let (path, text) = match slot {
        Slot::Scene | Slot::Asset => (file.clone(), String::new()),
        Slot::Graph | Slot::GraphInclude | Slot::BakeInclude => example(FLAT),
        Slot::Surface => scene(FLAT, PLANE, &format!("Obj(path: {quoted})")),
        Slot::MeshTexel => scene("scenes/meyer_neyret/pear_mesh.ron", "\"pear.obj\"", &quoted),
        Slot::SoftObject => scene("scenes/hypertextures/fig11_cube.ron", "\"meshes/cube.obj\"", &quoted),
        Slot::HeightImage => scene("scenes/meyer_neyret/heightfield_image.ron", "\"cobbles.png\"", &quoted),
        Slot::HeightScale => scene(
            FLAT,
            "height: (length: 0.5)",
            &format!("height: (length: 0.5, scale: Texture(path: {quoted}))"),
        ),
        Slot::ShapeImage => scene(
            "scenes/hypertextures/fig4_identity.ron",
            "shape: Curve([(0.0, 0.0, 1.0), (1.0, 1.0, 1.0)])",
            &format!("shape: Image(path: {quoted})"),
        ),
        Slot::Slices => scene(
            FLAT,
            "source: Constant(color: (0.8, 0.6, 0.4), opacity: 0.5)",
            &format!("source: Slices(dir: {quoted})"),
        ),
    };
    let include = format!("#include \"sp/{}.wgsl\"", kind.name());
    let result: voltex::Result<()> = match slot {
        Slot::Scene | Slot::Asset => voltex::scene::load(&file).map(drop),
        Slot::Graph => planned_err(&path, &text, Some(&file)),
        Slot::GraphInclude => {
            let rel = GRAPH_KERNELS[at.index(GRAPH_KERNELS.len())];
            let kernel = insert_line(&tree.text(rel), at, &include);
            tree.with_file(rel, &kernel, || planned_err(&path, &text, Some(&tree.graph())))
        }
        Slot::BakeInclude => {
            let rel = BAKE_KERNELS[at.index(BAKE_KERNELS.len())];
            let kernel = insert_line(&tree.text(rel), at, &include);
            let sources = voltex::gpu::sources::Sources::folder(&tree.dir);
            tree.with_file(rel, &kernel, || voltex::gpu::shader::load_from(&sources, rel).map(drop))
        }
        _ => planned_err(&path, &text, None),
    };
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    match result {
        Ok(()) if kind == Special::Empty => accepted(),
        Ok(()) => Err(format!("{} as {slot:?} was accepted", file.display())),
        Err(e) => {
            let shown = e.to_string();
            if !shown.contains(&name) {
                return Err(format!("the error does not name {name}: {shown}"));
            }
            check_error(&e, &path, &text, false)
        }
    }
}

/// The error of [`planned`] as a `voltex::Result` (its property checked by the caller).
fn planned_err(path: &Path, text: &str, graph: Option<&Path>) -> voltex::Result<()> {
    let scene = voltex::scene::parse(text, path)?;
    let opts = RenderOptions { graph: graph.map(Path::to_path_buf), ..Default::default() };
    let bp = Blueprint::new(&scene, &opts)?;
    bp.check_limits(&voltex::gpu::budget::plan_limits(), "the plan's limit")
}

#[test]
fn special_files() {
    let tree = Tree::new("special");
    let sp = tree.dir.join("sp");
    std::fs::create_dir_all(&sp).unwrap();
    special::populate(&sp, EXTS);
    let strategy = (
        prop::sample::select(SLOTS.to_vec()),
        prop::sample::select(special::ALL.to_vec()),
        any::<Index>(),
        any::<Index>(),
    );
    fuzz("special_files", 300, SMALL, strategy, |(slot, kind, ext, at)| {
        special_case(&tree, slot, kind, &ext, &at)
    });
}

// ---------------------------------------------------------------------------------------------
// Counts that drive work, near and beyond the budgets.

/// A count: near one of `points` (within ±2), or anywhere in `1..=max`.
fn near(points: &'static [u64], max: u64) -> impl Strategy<Value = u64> {
    prop_oneof![
        3 => (prop::sample::select(points), -2i64..=2).prop_map(|(p, d)| (p as i64 + d).max(0) as u64),
        1 => 1..=max,
    ]
}

/// Face counts of the OBJ files, written once before the target runs.
const FACES: &[u64] = &[1, 1000, 1 << 20, (1 << 21) + 2];

#[derive(Debug, Clone)]
enum Count {
    /// Copies of flat_box's node, each a Plane of `cells` x `cells`.
    Copies {
        nodes: u64,
        cells: u64,
    },
    Cells(u64, u64),
    Segments {
        torus: bool,
        around: u64,
        along: u64,
    },
    /// An `Implicit` texel of `shapes` spheres (or metaballs in one `Metaballs`).
    Shapes {
        shapes: u64,
        metaballs: bool,
        resolution: u64,
    },
    /// An OBJ of `faces` triangles as the surface, or as a `Mesh` texel's pattern.
    Faces {
        faces: u64,
        texel: bool,
        resolution: u64,
    },
    Resolution([u64; 3]),
    Output(u64, u64),
    Planes(u64),
}

fn count() -> impl Strategy<Value = Count> {
    const NODES: &[u64] = &[1, 64, 1024, 2000, 10_000];
    const CELLS: &[u64] = &[1, 32, 1024, 1448, 2048, 4096, 16_384, 65_536];
    const SEGMENTS: &[u64] = &[3, 1024, 1448, 4096, 65_536];
    const SHAPES: &[u64] = &[1, 256, 1000, 4096, 10_000];
    const RES: &[u64] = &[1, 2, 64, 256, 1024, 1025, 4096];
    const SIZES: &[u64] = &[1, 16, 4096, 16_384, 65_536];
    const PLANES: &[u64] = &[1, 256, 4096, 16_384, 1 << 20];

    prop_oneof![
        (near(NODES, 20_000), near(&[1, 4, 32, 45, 46], 64))
            .prop_map(|(nodes, cells)| Count::Copies { nodes, cells }),
        (near(CELLS, 1 << 17), near(CELLS, 1 << 17)).prop_map(|(a, b)| Count::Cells(a, b)),
        (any::<bool>(), near(SEGMENTS, 1 << 17), near(SEGMENTS, 1 << 17))
            .prop_map(|(torus, around, along)| Count::Segments { torus, around, along }),
        (near(SHAPES, 20_000), any::<bool>(), near(RES, 2048))
            .prop_map(|(shapes, metaballs, resolution)| Count::Shapes { shapes, metaballs, resolution }),
        (prop::sample::select(FACES), any::<bool>(), near(RES, 2048))
            .prop_map(|(faces, texel, resolution)| Count::Faces { faces, texel, resolution }),
        [near(RES, 4096), near(RES, 4096), near(RES, 4096)].prop_map(Count::Resolution),
        (near(SIZES, 1 << 17), near(SIZES, 1 << 17)).prop_map(|(w, h)| Count::Output(w, h)),
        near(PLANES, 1 << 21).prop_map(Count::Planes),
    ]
}

/// The scene text of a count (and the scene it claims to be).
fn count_scene(c: &Count, objs: &Path) -> (PathBuf, String) {
    let (flat_path, flat) = example(FLAT);
    let text = match *c {
        Count::Copies { nodes, cells } => {
            let start = flat.find("    nodes: [").unwrap();
            let node = format!(
                "(name: \"n{{}}\", surface: Plane(size: (2.0, 2.0), cells: ({cells}, {cells})), texel: \"fog\"),\n"
            );
            let all: String = (0..nodes).map(|i| node.replace("{}", &i.to_string())).collect();
            format!("{}    nodes: [\n{all}],\n)\n", &flat[..start])
        }
        Count::Cells(a, b) => edit(&flat, "cells: (4, 4)", &format!("cells: ({a}, {b})")),
        Count::Segments { torus, around, along } => {
            let surface = match torus {
                true => format!("Torus(major: 1.0, minor: 0.3, segments: ({around}, {along}))"),
                false => format!("Sphere(radius: 1.0, segments: ({around}, {along}))"),
            };
            edit(&flat, PLANE, &surface)
        }
        Count::Shapes { shapes, metaballs, resolution } => {
            let (path, pear) = example("scenes/meyer_neyret/pear_grazing.ron");
            let at = |i: u64, k: u64| 0.1 + 0.8 * ((i * k) % 101) as f64 / 101.0;
            let list: String = match metaballs {
                true => {
                    let balls: Vec<String> = (0..shapes)
                        .map(|i| {
                            format!("(center: ({}, {}, {}), radius: 0.05)", at(i, 37), at(i, 61), at(i, 17))
                        })
                        .collect();
                    format!(
                        "Metaballs(balls: [{}], threshold: 0.5, color: (0.7, 0.6, 0.2)),",
                        balls.join(", ")
                    )
                }
                false => (0..shapes)
                    .map(|i| {
                        format!(
                            "Sphere(center: ({}, {}, {}), radius: 0.05, color: (0.7, 0.6, 0.2)),\n",
                            at(i, 37),
                            at(i, 61),
                            at(i, 17)
                        )
                    })
                    .collect(),
            };
            let start = pear.find("source: Implicit(shapes: [").unwrap();
            let end = start + pear[start..].find("]),").unwrap();
            let text = format!("{}source: Implicit(shapes: [{list}{}", &pear[..start], &pear[end..]);
            let r = resolution;
            return (path, edit(&text, "resolution: (64, 64, 64)", &format!("resolution: ({r}, {r}, {r})")));
        }
        Count::Faces { faces, texel, resolution } => {
            let obj = objs.join(format!("faces{faces}.obj"));
            let quoted = format!("\"{}\"", obj.display());
            if texel {
                let (path, pear) = example("scenes/meyer_neyret/pear_mesh.ron");
                let r = resolution;
                let text = edit(&pear, "\"pear.obj\"", &quoted);
                return (
                    path,
                    edit(&text, "resolution: (64, 64, 64)", &format!("resolution: ({r}, {r}, {r})")),
                );
            }
            edit(&flat, PLANE, &format!("Obj(path: {quoted})"))
        }
        Count::Resolution([x, y, z]) => {
            edit(&flat, "resolution: (8, 8, 8)", &format!("resolution: ({x}, {y}, {z})"))
        }
        Count::Output(w, h) => {
            edit(&flat, "output: (width: 128, height: 128)", &format!("output: (width: {w}, height: {h})"))
        }
        Count::Planes(n) => edit(&flat, "planes: 256", &format!("planes: {n}")),
    };
    (flat_path, text)
}

#[test]
fn counts() {
    let objs = special::scratch("counts");
    for faces in FACES {
        std::fs::write(objs.join(format!("faces{faces}.obj")), grid_obj(*faces as usize)).unwrap();
    }
    let methods = prop::option::of(prop::sample::select(vec![
        MethodKind::ViewSlices,
        MethodKind::AxisSlices,
        MethodKind::Reference,
    ]));
    fuzz("counts", 40, LARGE, (count(), methods), |(c, method)| {
        let (path, text) = count_scene(&c, &objs);
        let opts = RenderOptions { method, ..Default::default() };
        match planned(&path, &text, &opts)? {
            Some(_) => accepted(),
            None => Ok(()),
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Graph values and kernels beyond the device's limits.

/// One edit of the default graph or of one of its kernels (written beside it).
#[derive(Debug, Clone)]
pub(super) enum GraphEdit {
    /// The `n`-th `clear:` value replaced.
    Clear(Index, &'static str),
    Format(Index, &'static str),
    /// The `n`-th `size: Output` replaced.
    Size(Index, &'static str),
    /// The `n`-th `depth: (resource: "..."` naming another resource.
    Depth(Index, Index),
    /// The `n`-th `targets: [` list's first target repeated.
    Targets(Index, usize),
    /// Another resource added to the outputs.
    Output(Index),
    /// A kernel's first `@workgroup_size(...)` replaced.
    Workgroup(Index, [&'static str; 3]),
    /// A declaration put before line `at` of a kernel.
    Declare(Index, Index, String),
    /// A function variable put at the start of the kernel's entry point.
    Local(Index, String),
}

const CLEARS: &[&str] = &[
    "Depth(NaN)",
    "Depth(inf)",
    "Depth(-1.0)",
    "Depth(2.0)",
    "Depth(0.5)",
    "Color(NaN, 0.0, 0.0, 1.0)",
    "Color(inf, 0.0, 0.0, 1.0)",
    "Color(1e39, 0.0, 0.0, 0.0)",
    "Color(0.0, 0.0, 0.0, 0.0)",
];
const FORMATS: &[&str] = &[
    "Depth32Float",
    "Depth24Plus",
    "Rgba16Float",
    "Rgba8Unorm",
    "R32Float",
    "Rgba32Float",
    "Bgra8Unorm",
    "R32Uint",
];
const SIZES: &[&str] =
    &["Fixed(1, 1)", "Fixed(16384, 16384)", "Fixed(16385, 1)", "Fixed(0, 4)", "Fixed(8192, 8192)"];
const WORKGROUP: &[&str] =
    &["0", "1", "64", "256", "257", "1024", "65535", "65536", "4294967295", "4294967296", "-1"];
const LENGTHS: &[&str] = &["1", "4096", "4097", "16384", "100000000", "268435456", "4294967295"];

fn declaration() -> impl Strategy<Value = String> {
    let n = || prop::sample::select(LENGTHS);
    prop_oneof![
        n().prop_map(|n| format!("var<private> fuzz_p: array<vec4<f32>, {n}>;")),
        n().prop_map(|n| format!("var<workgroup> fuzz_w: array<f32, {n}>;")),
        (n(), n()).prop_map(|(n, m)| format!("var<private> fuzz_n: array<array<vec4<f32>, {n}>, {m}>;")),
        n().prop_map(|n| format!("struct FuzzS {{ a: array<f32, {n}>, }}\nvar<private> fuzz_s: FuzzS;")),
        (n(), n()).prop_map(|(n, m)| format!(
            "var<workgroup> fuzz_a: array<f32, {n}>;\nvar<workgroup> fuzz_b: array<f32, {m}>;"
        )),
    ]
}

pub(super) fn graph_edit() -> impl Strategy<Value = GraphEdit> {
    let i = any::<Index>;
    prop_oneof![
        (i(), prop::sample::select(CLEARS)).prop_map(|(n, v)| GraphEdit::Clear(n, v)),
        (i(), prop::sample::select(FORMATS)).prop_map(|(n, v)| GraphEdit::Format(n, v)),
        (i(), prop::sample::select(SIZES)).prop_map(|(n, v)| GraphEdit::Size(n, v)),
        (i(), i()).prop_map(|(n, r)| GraphEdit::Depth(n, r)),
        (i(), prop::sample::select(vec![2usize, 8, 9, 100, 100_000]))
            .prop_map(|(n, k)| GraphEdit::Targets(n, k)),
        i().prop_map(GraphEdit::Output),
        (
            i(),
            [
                prop::sample::select(WORKGROUP),
                prop::sample::select(WORKGROUP),
                prop::sample::select(WORKGROUP)
            ]
        )
            .prop_map(|(k, w)| GraphEdit::Workgroup(k, w)),
        (i(), i(), declaration()).prop_map(|(k, at, d)| GraphEdit::Declare(k, at, d)),
        (i(), prop::sample::select(LENGTHS))
            .prop_map(|(k, n)| GraphEdit::Local(k, format!("var fuzz_l: array<vec4<f32>, {n}>;"))),
    ]
}

/// Offsets of `needle` in `text`.
fn find_all(text: &str, needle: &str) -> Vec<usize> {
    text.match_indices(needle).map(|(i, _)| i).collect()
}

/// The value starting at `start`: up to the first `,` or closing bracket outside brackets.
fn value_end(text: &str, start: usize) -> usize {
    let mut depth = 0i32;
    for (i, c) in text[start..].char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' if depth == 0 => return start + i,
            ')' | ']' => depth -= 1,
            ',' if depth == 0 => return start + i,
            _ => {}
        }
    }
    text.len()
}

/// `graph` with the value after the `n`-th `key` replaced by `value`.
fn replace_value(graph: &str, key: &str, n: &Index, value: &str) -> String {
    let at = find_all(graph, key);
    if at.is_empty() {
        return graph.to_string();
    }
    let start = at[n.index(at.len())] + key.len();
    let end = value_end(graph, start);
    format!("{}{value}{}", &graph[..start], &graph[end..])
}

/// The kernels the default graph names, in its order.
pub(super) fn graph_kernels(graph: &str) -> Vec<String> {
    let mut k: Vec<String> =
        graph.split("shader: \"").skip(1).map(|s| s[..s.find('"').unwrap()].to_string()).collect();
    k.dedup();
    k
}

/// Applies `e` to the graph text, or returns the kernel (relative path) and its new text.
pub(super) fn apply(e: &GraphEdit, graph: &mut String, tree: &Tree) -> Option<(String, String)> {
    let resources: Vec<String> = graph
        .split("        \"")
        .skip(1)
        .filter_map(|s| s.find("\": Texture").map(|i| s[..i].to_string()))
        .collect();
    let kernels = graph_kernels(graph);
    let kernel = |k: &Index| kernels[k.index(kernels.len())].clone();
    match e {
        GraphEdit::Clear(n, v) => *graph = replace_value(graph, "clear: ", n, v),
        GraphEdit::Format(n, v) => *graph = replace_value(graph, "format: ", n, v),
        GraphEdit::Size(n, v) => *graph = replace_value(graph, "size: ", n, v),
        GraphEdit::Depth(n, r) => {
            let name = format!("\"{}\"", resources[r.index(resources.len())]);
            *graph = replace_value(graph, "depth: (resource: ", n, &name);
        }
        GraphEdit::Targets(n, k) => {
            let at = find_all(graph, "targets: [");
            if let Some(&a) = at.get(n.index(at.len().max(1))) {
                let start = a + "targets: [".len();
                let end = value_end(graph, start);
                let first = graph[start..end].to_string();
                let list = vec![first; *k].join(", ");
                *graph = format!("{}{list}{}", &graph[..start], &graph[end..]);
            }
        }
        GraphEdit::Output(r) => {
            let name = &resources[r.index(resources.len())];
            *graph = graph.replacen("outputs: [", &format!("outputs: [\"{name}\", "), 1);
        }
        GraphEdit::Workgroup(k, [x, y, z]) => {
            let rel = kernel(k);
            let text = tree.text(&rel);
            let start = text.find("@workgroup_size(")?;
            let end = start + text[start..].find(')')? + 1;
            return Some((rel, format!("{}@workgroup_size({x}, {y}, {z}){}", &text[..start], &text[end..])));
        }
        GraphEdit::Declare(k, at, d) => {
            let rel = kernel(k);
            return Some((rel.clone(), insert_line(&tree.text(&rel), at, d)));
        }
        GraphEdit::Local(k, d) => {
            let rel = kernel(k);
            let text = tree.text(&rel);
            let entry = text.find("\nfn main(").or_else(|| text.find("\nfn vs_main("))?;
            let body = entry + text[entry..].find("{\n")? + 2;
            return Some((rel, format!("{}    {d}\n{}", &text[..body], &text[body..])));
        }
    }
    None
}

/// Scenes that keep different parts of the default graph (and so compile different kernels).
const GRAPH_SCENES: &[&str] = &[
    FLAT,
    "scenes/meyer_neyret/pear_grazing.ron",
    "scenes/reference/torus_egg.ron",
    "scenes/hypertextures/fig4_identity.ron",
];

#[test]
fn graph_values() {
    let tree = Tree::new("graph-values");
    let original = tree.text("frame.ron");
    let strategy = (prop::sample::select(GRAPH_SCENES), prop::collection::vec(graph_edit(), 1..4));
    fuzz("graph_values", 300, SMALL, strategy, |(scene, edits)| {
        let mut graph = original.clone();
        let mut kernel = None;
        for e in &edits {
            if let Some(k) = apply(e, &mut graph, &tree) {
                kernel = Some(k);
            }
        }
        let (path, text) = example(scene);
        let graph_path = tree.graph();
        let run = || {
            tree.with_file("frame.ron", &graph, || {
                let scene = voltex::scene::parse(&text, &path).unwrap();
                let opts = RenderOptions {
                    graph: Some(graph_path.clone()),
                    size: Some((16, 16)),
                    ..Default::default()
                };
                Blueprint::new(&scene, &opts)
                    .and_then(|bp| bp.check_limits(&voltex::gpu::budget::plan_limits(), "the plan's limit"))
            })
        };
        let result = match &kernel {
            Some((rel, k)) => tree.with_file(rel, k, run),
            None => run(),
        };
        match result {
            Ok(()) => accepted(),
            // Everything about the graph or a kernel is positioned in that file.
            Err(e) => {
                let (file, text) = match (&e, &kernel) {
                    (Error::At { loc, .. }, Some((rel, k))) if loc.path == tree.dir.join(rel) => {
                        (tree.dir.join(rel), k)
                    }
                    _ => (graph_path.clone(), &graph),
                };
                check_error(&e, &file, text, true)
            }
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Lenient parsing.

/// Every example scene and graph with its text.
fn examples() -> Vec<(PathBuf, String)> {
    let mut paths = files(&root().join("scenes"), "ron");
    paths.extend(files(&root().join("graphs"), "ron"));
    paths.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

fn is_graph(path: &Path) -> bool {
    path.parent().is_some_and(|d| d.ends_with("graphs"))
}

/// Parses `text` as the scene or graph `path` is; `Ok(true)`: accepted; `Ok(false)`: a parse
/// error with its position (checked strictly).
fn parses(path: &Path, text: &str) -> Result<bool, String> {
    let result = match is_graph(path) {
        true => voltex::graph::Graph::parse(path, text.to_string()).map(drop),
        false => voltex::scene::parse(text, path).map(drop),
    };
    match result {
        Ok(()) => Ok(true),
        Err(e) => check_error(&e, path, text, true).map(|()| false),
    }
}

#[test]
fn unknown_fields() {
    let all = examples();
    let strategy = (any::<Index>(), any::<Index>(), any::<bool>());
    fuzz("unknown_fields", 400, SMALL, strategy, |(file, at, before_close)| {
        let (path, text) = &all[file.index(all.len())];
        let open = ron_items::openings(text);
        let k = open[at.index(open.len())];
        // Right after `(`, or as the last field before its `)`: both must be refused.
        let text = match before_close {
            false => format!("{}fuzz_unknown: 0, {}", &text[..k], &text[k..]),
            true => {
                let end = ron_items::closing(text, k);
                let inside = text[k..end].trim_end();
                let sep = if inside.is_empty() || inside.ends_with(',') { "" } else { ", " };
                format!("{}{sep}fuzz_unknown: 0{}", &text[..end], &text[end..])
            }
        };
        match parses(path, &text)? {
            true => Err(format!("an unknown field was accepted:\n{text}")),
            false => Ok(()),
        }
    });
}

#[test]
fn duplicate_keys() {
    let all = examples();
    fuzz("duplicate_keys", 400, SMALL, (any::<Index>(), any::<Index>()), |(file, at)| {
        let (path, text) = &all[file.index(all.len())];
        let items = ron_items::items(text);
        let item = items[at.index(items.len())];
        let text = ron_items::duplicate(text, item);
        match parses(path, &text)? {
            true => Err(format!("a duplicate key was accepted:\n{text}")),
            false => Ok(()),
        }
    });
}

/// Bytes that are not UTF-8 (alone, or cut short), and where they go.
const BAD_UTF8: &[&[u8]] =
    &[b"\xff", b"\x80", b"\xc3\x28", b"\xe2\x82", b"\xed\xa0\x80", b"\xf8\x88\x80\x80\x80", b"\xc0\xaf"];

/// Invalid UTF-8 at a random offset of a scene, graph, kernel, include or OBJ file, read from
/// disk: the error names the file and the line of the first bad byte.
#[test]
fn invalid_utf8() {
    let tree = Tree::new("utf8");
    let scenes = files(&root().join("scenes"), "ron");
    let objs = files(&root().join("scenes"), "obj");
    let kernels = files(&root().join("wgsl"), "wgsl");
    let strategy = (0..4u8, any::<Index>(), any::<Index>(), prop::sample::select(BAD_UTF8), any::<bool>());
    fuzz("invalid_utf8", 300, SMALL, strategy, |(kind, file, at, bad, overwrite)| {
        let (source, rel) = match kind {
            0 => (scenes[file.index(scenes.len())].clone(), "scene.ron".to_string()),
            1 => (root().join("graphs/frame.ron"), "frame.ron".to_string()),
            2 => {
                let k = &kernels[file.index(kernels.len())];
                (k.clone(), k.strip_prefix(root().join("wgsl")).unwrap().display().to_string())
            }
            _ => (objs[file.index(objs.len())].clone(), "mesh.obj".to_string()),
        };
        let mut bytes = std::fs::read(&source).unwrap();
        let k = at.index(bytes.len() + 1);
        let end = if overwrite { (k + bad.len()).min(bytes.len()) } else { k };
        bytes.splice(k..end, bad.iter().copied());
        let valid = match std::str::from_utf8(&bytes) {
            Ok(_) => return Ok(()),
            Err(e) => e.valid_up_to(),
        };
        let line = bytes[..valid].iter().filter(|&&b| b == b'\n').count() + 1;
        let path = tree.dir.join(&rel);
        let result = tree.with_file(&rel, &bytes, || match kind {
            0 => voltex::scene::load(&path).map(drop),
            1 => voltex::graph::Graph::load(&path).map(drop),
            2 => {
                let sources = voltex::gpu::sources::Sources::folder(&tree.dir);
                voltex::gpu::shader::load_from(&sources, &rel).map(drop)
            }
            _ => voltex::mesh::load(&path).map(drop),
        });
        match result {
            Err(Error::At { loc, message }) if loc.path == path && loc.line == line => {
                match message.contains("UTF-8") {
                    true => Ok(()),
                    false => Err(format!("{}: {message}", loc)),
                }
            }
            Err(e) => Err(format!("expected an error at {}:{line}: {e}", path.display())),
            Ok(()) => Err("invalid UTF-8 was accepted".into()),
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Late failures: node names that EXR metadata cannot hold.

fn node_name() -> impl Strategy<Value = String> {
    let char = prop_oneof![
        4 => prop::char::range('a', 'z'),
        2 => prop::char::range('\u{a0}', '\u{ff}'),
        1 => prop::char::range('\u{80}', '\u{9f}'),
        1 => prop::sample::select(vec!['漢', '🎉', '\u{301}', '\u{0}', '"', '\\', ' ', '\u{ffff}', '\u{100}']),
    ];
    prop_oneof![
        prop::collection::vec(char, 0..300).prop_map(|c| c.into_iter().collect()),
        (
            prop::sample::select(vec!['n', 'é', 'ÿ', '漢']),
            prop::sample::select(vec![1usize, 120, 121, 240, 241, 242, 255, 256])
        )
            .prop_map(|(c, n)| std::iter::repeat_n(c, n).collect()),
    ]
}

#[test]
fn node_names() {
    let dir = special::scratch("names");
    let (path, flat) = example(FLAT);
    fuzz("node_names", 300, SMALL, node_name(), |name| {
        let escaped = name.replace('\\', "\\\\").replace('"', "\\\"");
        let text = edit(&flat, "name: \"box\"", &format!("name: \"{escaped}\""));
        let opts = RenderOptions { size: Some((16, 16)), ..Default::default() };
        if planned(&path, &text, &opts)?.is_none() {
            return Ok(());
        }
        // What `render` writes last: the EXR with the object's name in its metadata.
        let image = voltex::io::Image::new(1, 1);
        let key = format!("voltex_object_{name}");
        match voltex::io::exr::write(&dir.join("x.exr"), &image, &[(&key, "ViewSlices".into())]) {
            Ok(()) => accepted(),
            Err(e) => Err(format!("plan accepted the name {name:?}, the EXR cannot hold it: {e}")),
        }
    });
}
