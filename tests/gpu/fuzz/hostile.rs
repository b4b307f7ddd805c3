//! Hostile inputs of issue 19 through what `voltex plan` does: special files wherever a path is
//! read, and counts that drive work near and beyond the budgets; with the helpers the other
//! hostile targets share (`graphs`, `parsing`, `gpu_paths`).
//!
//! Property: each input is accepted or fails with an error naming its file (and `line:col`
//! where it is about the file's content); no panic; within the runner's bounds on time and
//! memory per input.

use super::root;
use crate::fuzz_support::check_error;
use crate::fuzz_support::runner::{accepted, fuzz, LARGE, SMALL};
use crate::fuzz_support::special::{self, grid_obj, Special};

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::render::{Blueprint, MethodKind, RenderOptions};

pub(super) const FLAT: &str = "scenes/view_slices/flat_box.ron";
const PLANE: &str = "Plane(size: (2.0, 2.0), cells: (4, 4))";

pub(super) fn example(rel: &str) -> (PathBuf, String) {
    let path = root().join(rel);
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

/// `text` with `from` (which must be there) replaced once by `to`.
pub(super) fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} is not in the example");
    text.replacen(from, to, 1)
}

/// What `voltex plan` does with scene text claiming to be `path`: parse and check, plan, check
/// the allocations against the limits every adapter offers. `Ok(None)`: rejected as it should
/// be (the error property holds); `Err`: a broken property.
pub(super) fn planned(path: &Path, text: &str, opts: &RenderOptions) -> Result<Option<Blueprint>, String> {
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
pub(super) fn insert_line(text: &str, line: &Index, insert: &str) -> String {
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
    "bake/bake_transfer.wgsl",
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
        MethodKind::named("ViewSlices").unwrap(),
        MethodKind::named("AxisSlices").unwrap(),
        MethodKind::named("Reference").unwrap(),
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
