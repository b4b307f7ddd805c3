//! Fuzz inputs through the GPU, on the test binary's one device: mutated example scenes (and
//! edits of the default graph and its kernels) that `plan` accepts, rendered at 8x8 or 16x16;
//! and the preview's reload path, headless: a good scene, then mutated versions of it, of its
//! graph and of a kernel written to their files, each followed by a rebuild and a frame.
//!
//! Properties: what `plan` accepts renders (and its EXR is written) or fails with a positioned
//! error, never a GPU error or a lost device; in the reload path, a broken version reports a
//! positioned error and keeps the last good frame, a good one renders, and putting the good files
//! back gives the first frame again, pixel for pixel.
use crate::common::adapter::Expectations;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use super::graphs::{apply, graph_edit, GraphEdit};
use super::hostile::Tree;
use super::root;
use crate::fuzz_support::runner::{accepted, fuzz, kernel_work, GPU};
use crate::fuzz_support::{check_error, mutate, Mutation, NUMBERS};

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use voltex::gpu::cache::GpuCache;
use voltex::gpu::GpuContext;
use voltex::preview::{Outcome, Session};
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::Error;

/// Example scenes cheap enough to render thousands of times on llvmpipe (assets beside them),
/// one or more per method and texel source.
const SCENES: &[&str] = &[
    "scenes/view_slices/flat_box.ron",
    "scenes/view_slices/gltf_dome.ron",
    "scenes/hard_cases/tiny_scene.ron",
    "scenes/hard_cases/zero_heights.ron",
    "scenes/hard_cases/single_slice.ron",
    "scenes/hard_cases/per_pixel_small_triangles.ron",
    "scenes/meyer_neyret/pear_grazing.ron",
    "scenes/meyer_neyret/pear_mesh.ron",
    "scenes/meyer_neyret/heightfield_image.ron",
    "scenes/meyer_neyret/waving_flag.ron",
    "scenes/hypertextures/fig4_identity.ron",
    "scenes/reference/torus_egg.ron",
];

/// The memory budget of the GPU targets' frames: a mutation can ask for a volume of 4 GiB,
/// which `plan` rightly accepts under the default budget, but rendering it here would only
/// measure llvmpipe.
const BUDGET: u64 = 64 << 20;

fn device() -> std::sync::MutexGuard<'static, GpuContext> {
    crate::common::adapter::open(&ADAPTER).expect("an adapter with WebGPU's defaults")
}

fn read(rel: &str) -> (PathBuf, String) {
    let path = root().join(rel);
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

thread_local! {
    /// Failures after `plan` accepted that had a position (allowed, but counted and shown).
    static LATE: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// A failure after `plan` accepted: acceptable only with a position in a file.
fn late(stage: &str, e: Error) -> Result<(), String> {
    match e {
        Error::At { .. } | Error::File { .. } => {
            LATE.with(|l| l.borrow_mut().push(format!("{stage}: {e}")));
            Ok(())
        }
        e => Err(format!("plan accepted, {stage} failed without a position: {e}")),
    }
}

/// Renders scene `text` (as `path`) at `size` the way `voltex render` does, with `graph`.
fn render_case(
    ctx: &GpuContext,
    cache: &mut GpuCache,
    (path, text): (&Path, &str),
    size: u32,
    graph: Option<PathBuf>,
    exr: &Path,
) -> Result<(), String> {
    let scene = match voltex::scene::parse(text, path) {
        Ok(s) => s,
        Err(e) => return check_error(&e, path, text, true),
    };
    let default_graph = graph.is_none();
    let opts = RenderOptions { size: Some((size, size)), budget: Some(BUDGET), graph, ..Default::default() };
    let planned = Blueprint::new(&scene, &opts)
        .and_then(|bp| bp.check_limits(&ctx.limits, "this adapter's limit").map(|()| bp));
    let bp = match planned {
        Ok(bp) => bp,
        // A graph error may be in the graph or a kernel: any position is fine, GPU errors not.
        Err(e) => return check_error(&e, path, text, false),
    };
    cache.begin();
    let mut renderer = match Renderer::with_cache(ctx, bp, cache) {
        Ok(r) => r,
        Err(e) => return late("making the renderer", e),
    };
    cache.retain_used();
    let frame = match renderer.render(ctx) {
        Ok(f) => f,
        Err(e) => return late("the render", e),
    };
    // An edited graph may ask for it (an Rgba16Float target overflows past 65,504), a scene not.
    if default_graph && !frame.image.pixels.iter().flatten().all(|c| c.is_finite()) {
        return Err("plan accepted, the frame has a NaN or infinite pixel".into());
    }
    let metadata = renderer.metadata(ctx, &frame);
    let meta: Vec<(&str, String)> = metadata.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    match voltex::io::exr::write(exr, &frame.image, &meta) {
        Ok(()) => accepted(),
        Err(e) => Err(format!("plan accepted, writing the EXR failed: {e}")),
    }
}

#[test]
fn render_tiny() {
    let tree = Tree::new("render");
    let original = tree.text("frame.ron");
    let cache = RefCell::new(GpuCache::default());
    let exr = tree.dir.join("out.exr");
    // The examples as they are first: each renders, and the pipelines are made before the clock
    // runs (making them all takes seconds on llvmpipe).
    for rel in SCENES {
        let (path, text) = read(rel);
        render_case(&device(), &mut cache.borrow_mut(), (&path, &text), 16, None, &exr).unwrap();
    }
    let graph_edits = prop::option::weighted(0.25, prop::collection::vec(graph_edit(), 1..3));
    // Mostly numbers changed (the text still parses, so the GPU sees it), else any edits.
    let mild = ["0.5", "2", "3", "7", "0.01", "100", "33", "1.5", "0.9", "12"];
    let numbers: Vec<&'static str> = NUMBERS.iter().chain(&mild).copied().collect();
    let number = (any::<Index>(), prop::sample::select(numbers)).prop_map(|(i, n)| Mutation::Number(i, n));
    let mutations = prop_oneof![
        3 => prop::collection::vec(number, 1..3),
        2 => prop::collection::vec(any::<Mutation>(), 0..4),
    ];
    let strategy =
        (prop::sample::select(SCENES), mutations, graph_edits, prop::sample::select(vec![8u32, 16]));
    fuzz("render_tiny", 40, GPU, strategy, |(rel, muts, edits, size)| {
        let (path, text) = read(rel);
        let text = mutate(&text, &muts);
        let ctx = device();
        let Some(edits) = edits else {
            return render_case(&ctx, &mut cache.borrow_mut(), (&path, &text), size, None, &exr);
        };
        let mut graph = original.clone();
        let mut kernel = None;
        for e in &edits {
            kernel = apply(e, &mut graph, &tree).or(kernel);
        }
        let run = || {
            tree.with_file("frame.ron", &graph, || {
                let graph = Some(tree.graph());
                render_case(&ctx, &mut cache.borrow_mut(), (&path, &text), size, graph, &exr)
            })
        };
        match &kernel {
            Some((rel, k)) => tree.with_file(rel, k, run),
            None => run(),
        }
    });
    LATE.with(|l| {
        let l = l.borrow();
        eprintln!("fuzz render_tiny: {} accepted by plan failed later, with a position", l.len());
        for e in l.iter().take(5) {
            eprintln!("  {e}");
        }
    });
}

/// One version written during a reload case.
#[derive(Debug, Clone)]
enum Version {
    Scene(Vec<Mutation>),
    Graph(Vec<GraphEdit>),
    /// A kernel of the graph (by index) mutated token by token.
    Kernel(Index, Vec<Mutation>),
    /// Every file as it was.
    Good,
}

fn version() -> impl Strategy<Value = Version> {
    let muts = || prop::collection::vec(any::<Mutation>(), 1..4);
    prop_oneof![
        4 => muts().prop_map(Version::Scene),
        1 => prop::collection::vec(graph_edit(), 1..3).prop_map(Version::Graph),
        1 => (any::<Index>(), muts()).prop_map(|(k, m)| Version::Kernel(k, m)),
        1 => Just(Version::Good),
    ]
}

/// Scenes without assets (the reload target writes them into a scratch folder).
const RELOAD_SCENES: &[&str] = &[
    "scenes/view_slices/flat_box.ron",
    "scenes/hard_cases/tiny_scene.ron",
    "scenes/meyer_neyret/pear_grazing.ron",
    "scenes/hypertextures/fig4_identity.ron",
    "scenes/reference/torus_egg.ron",
];

/// A reload error's property: not from the GPU, and at a `line:col` inside the file when it
/// names one of `files` with a position.
fn reload_error(msg: &str, files: &[(PathBuf, String)]) -> Result<(), String> {
    if msg.starts_with("GPU") {
        return Err(format!("a GPU error on reload: {msg}"));
    }
    for (path, text) in files {
        let Some(rest) = msg.strip_prefix(&format!("{}:", path.display())) else { continue };
        let mut parts = rest.splitn(3, ':');
        let (Some(line), Some(col)) = (parts.next(), parts.next()) else { continue };
        let (Ok(line), Ok(col)) = (line.parse::<usize>(), col.parse::<usize>()) else { continue };
        let e = Error::at(voltex::error::FileLoc::new(path, line, col), "x");
        return check_error(&e, path, text, true).map_err(|e| format!("{e}: {msg}"));
    }
    Ok(())
}

#[test]
fn preview_reload() {
    let tree = Tree::new("reload");
    let scene_path = tree.dir.join("scene.ron");
    let graph = tree.text("frame.ron");
    let kernels = super::graphs::graph_kernels(&graph);
    let originals: Vec<(String, String)> = kernels.iter().map(|k| (k.clone(), tree.text(k))).collect();
    // torus_egg's texel at 32^3 and its Reference step 10x longer: the reload path does the same
    // whatever the sizes, and its 128^3 bake, then its 0.002 step (130 ms a 16x16 frame here),
    // made its inputs slower than the other scenes' together.
    let bases: Vec<String> = RELOAD_SCENES
        .iter()
        .map(|rel| {
            let text = read(rel).1;
            text.replace("resolution: (128, 128, 128)", "resolution: (32, 32, 32)")
                .replace("step: 0.002", "step: 0.02")
        })
        .collect();
    assert!(bases.iter().all(|b| !b.contains("128, 128, 128") && !b.contains("step: 0.002")));
    let opts = RenderOptions {
        size: Some((16, 16)),
        graph: Some(tree.graph()),
        budget: Some(BUDGET),
        ..Default::default()
    };
    // What each file holds now, so that only changed files are written.
    let disk: RefCell<std::collections::HashMap<PathBuf, String>> = RefCell::default();
    let write = |path: &Path, text: &str| {
        if disk.borrow().get(path).map(String::as_str) != Some(text) {
            std::fs::write(path, text).unwrap();
            disk.borrow_mut().insert(path.to_path_buf(), text.to_string());
        }
    };
    let put_back = |base: &str| {
        write(&scene_path, base);
        write(&tree.graph(), &graph);
        for (rel, text) in &originals {
            write(&tree.dir.join(rel), text);
        }
    };
    put_back(&bases[0]);
    let session = RefCell::new(Session::open(&device(), &scene_path, opts));
    // The first frame of each base scene, to compare with after the good files are put back.
    let firsts: RefCell<Vec<Option<Vec<[u32; 4]>>>> = RefCell::new(vec![None; bases.len()]);
    let strategy = (any::<Index>(), prop::collection::vec(version(), 1..5));
    fuzz("preview_reload", 6, GPU, strategy, |(base, versions)| {
        let ctx = device();
        let s = &mut *session.borrow_mut();
        let b = base.index(bases.len());
        // A frame's bits, so that a NaN pixel (a mutated kernel may draw one) equals itself.
        let frame = |s: &mut Session| match s.render(&ctx) {
            Some(Ok(f)) => Ok(f.image.pixels.iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>()),
            Some(Err(e)) => Err(format!("the last good renderer failed to render: {e}")),
            None => Err("no renderer".to_string()),
        };
        // The good files, and their frame.
        let good = |s: &mut Session, firsts: &mut Vec<Option<Vec<[u32; 4]>>>| {
            put_back(&bases[b]);
            if let Outcome::Failed(e) = s.rebuild(&ctx) {
                return Err(format!("the good files failed to rebuild: {e}"));
            }
            let pixels = frame(s)?;
            match &firsts[b] {
                Some(first) if *first != pixels => {
                    Err("the good files gave another frame than at first".into())
                }
                Some(_) => Ok(pixels),
                None => {
                    firsts[b] = Some(pixels.clone());
                    Ok(pixels)
                }
            }
        };
        let mut last = good(s, &mut firsts.borrow_mut())?;
        for v in &versions {
            // Each version is the good files with one change.
            put_back(&bases[b]);
            let mut files = vec![(scene_path.clone(), bases[b].clone())];
            match v {
                Version::Scene(muts) => {
                    let text = mutate(&bases[b], muts);
                    write(&scene_path, &text);
                    files[0].1 = text;
                }
                Version::Graph(edits) => {
                    let mut g = graph.clone();
                    if let Some((rel, k)) = edits.iter().fold(None, |k, e| apply(e, &mut g, &tree).or(k)) {
                        write(&tree.dir.join(&rel), &k);
                        files.push((tree.dir.join(rel), k));
                    }
                    write(&tree.graph(), &g);
                    files.push((tree.graph(), g));
                }
                Version::Kernel(k, muts) => {
                    let (rel, text) = &originals[k.index(originals.len())];
                    let text = mutate(text, muts);
                    write(&tree.dir.join(rel), &text);
                    files.push((tree.dir.join(rel), text));
                }
                Version::Good => {}
            }
            let mut reload = || match s.rebuild(&ctx) {
                Outcome::Rebuilt(_) => {
                    last = frame(s)?;
                    // Only a kernel of the user's may make NaN or infinite pixels.
                    match last.iter().flatten().all(|&c| f32::from_bits(c).is_finite())
                        || matches!(v, Version::Kernel(..))
                    {
                        true => Ok(()),
                        false => Err("a rebuilt scene drew a NaN or infinite pixel".to_string()),
                    }
                }
                Outcome::Failed(msg) => {
                    reload_error(&msg, &files)?;
                    match frame(s)? == last {
                        true => Ok(()),
                        false => Err(format!("after a failed reload ({msg}) the frame changed")),
                    }
                }
            };
            // A mutated kernel decides its own work (seed 30, input 50,969: an instance count of
            // 16,384 in the slices' indirect draw, 114 s of CPU on llvmpipe).
            match v {
                Version::Kernel(..) => kernel_work(reload)?,
                _ => reload()?,
            }
        }
        good(s, &mut firsts.borrow_mut())?;
        accepted()
    });
}
