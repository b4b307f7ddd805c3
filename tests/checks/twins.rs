//! DESIGN.md convention 2: every kernel whose math matters has a CPU twin of the same name, and
//! the kernels without one are listed here with the reason. A kernel is a WGSL file under `wgsl/`
//! (any depth, `wgsl/shared/` includes excluded) with an `@compute`, `@vertex` or `@fragment`
//! entry point; its twin is a `pub fn <file stem>` anywhere under `src/` in a module whose `//!`
//! doc calls it a twin. A twin must also be compared with its kernel: a GPU test (a file under
//! `tests/gpu/`) calls it, or calls the twin function `COMPARED_THROUGH` names for it. No GPU
//! needed.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Kernels without a CPU twin of their name, and why. Kept true by the test below: a kernel that
/// gains a twin or disappears must leave the list.
const NO_TWIN: &[(&str, &str)] = &[
    (
        "begin_segments",
        "depth peeling's first step (each pixel's start, no boundaries yet): the twin \
         `peel_segments` (src/methods/ray_march/peel_segments.rs) returns a pixel's boundaries after this step \
         and every peel, compared with both kernels' output in tests/gpu/hypertexture_segments.rs",
    ),
    (
        "resolve_splats",
        "splatting's second step (slabs composited front to back): the twin `splat_segments` \
         (src/methods/ray_march/splat_segments.rs) returns the resolved pixel of both steps, compared in \
         tests/gpu/hypertexture_splatting.rs",
    ),
    (
        "probe_hypertexture",
        "test probe, no math of its own: evaluates the functions of wgsl/shared/hypertexture.wgsl \
         at given points so that tests/gpu/hypertexture.rs compares them with src/cpu/hypertexture.rs",
    ),
    (
        "bench_simplex",
        "benchmark only (`voltex bench-hyper` times it): loops over simplex3 of \
         wgsl/shared/simplex.wgsl, whose twin is `simplex3` in src/cpu/noise_simplex.rs",
    ),
    (
        "scan_axis_slices",
        "bookkeeping: an exclusive prefix sum (wgsl/shared/scan.wgsl, as scan_plane_offsets, \
         which has a twin) of per-prism vertex counts; tests/gpu/axis_slices.rs checks that every \
         vertex counted is drawn",
    ),
    (
        "scan_axis_layers",
        "bookkeeping: an exclusive prefix sum (wgsl/shared/scan.wgsl) of per-layer triangle \
         counts; tests/gpu/axis_slices.rs checks that grouping draws the same image",
    ),
    (
        "group_axis_slices",
        "bookkeeping: copies emitted triangles into their slice image's group, no arithmetic on \
         them; tests/gpu/axis_slices.rs checks that grouping by slice image draws the same image",
    ),
    (
        "composite",
        "raster: blends the premultiplied accumulation over the background (one line); checked \
         by the golden images (tests/gpu/render_scenes.rs, voltex regress)",
    ),
    (
        "resolve_depth",
        "raster: turns the nearest opaque hit (1 / z bits) into z, one line; checked against \
         analytic depths (a floor, a slab's top, a sphere) in tests/gpu/aov.rs",
    ),
    (
        "resolve_transmittance",
        "raster: 1 - alpha of the frame, one line; checked against a constant slab's \
         transmittance in tests/gpu/aov.rs",
    ),
    (
        "composite_ray_march",
        "raster: blends the march state the ray_march twin computes over the frame (one line); \
         checked by the golden images",
    ),
    (
        "composite_volume",
        "raster: blends the march state the march_volume twin computes over the frame (one line); \
         checked by tests/gpu/volume.rs's analytic transmittance and the golden images",
    ),
    (
        "composite_reference",
        "raster: copies the trace_reference layer (premultiplied-over blending by the pipeline); \
         checked by tests/gpu/reference.rs and the golden images",
    ),
    (
        "composite_shell_march",
        "raster: copies the march_shell layer (premultiplied-over blending by the pipeline); \
         checked by tests/gpu/shell_march.rs and the golden images",
    ),
    (
        "blend_tiles",
        "raster: copies the layer composite_tiles made (premultiplied-over blending by the \
         pipeline); checked against the raster compositor's image in tests/gpu/tile_compositor.rs",
    ),
    (
        "draw_base",
        "raster: draws the opaque base surface with depth, lit two-sided by ambient plus Lambert \
         (one line); checked by the golden images",
    ),
    (
        "draw_slices",
        "raster: draws what emit_slices produced (checked against its twin in \
         tests/gpu/gpu_slicing.rs) with trilinear sampling and the step-corrected opacity; checked \
         by the golden images",
    ),
    (
        "draw_axis_slices",
        "raster: draws what emit_axis_slices produced (checked against its twin in \
         tests/gpu/axis_slices.rs) from the slice images bake_axis_slices made; checked by the \
         golden images",
    ),
    (
        "draw_slice_coverage",
        "debug view: counts the slice polygons covering each pixel (additive white), no math",
    ),
    (
        "bench_fill",
        "benchmark only (`voltex bench --limits` times it): layers of squares blended with one 3D \
         texture fetch each, full-screen for a fill rate, small for a per-triangle cost; its output \
         is never read",
    ),
    (
        "bench_texture",
        "benchmark only (`voltex bench --limits` times it): sums trilinear 3D texture samples, a \
         sample rate; its output is never read",
    ),
    (
        "layer_texel_volume",
        "a copy of the volume into f16 layers, no arithmetic: level 0 of the layers equals the \
         volume in tests/gpu/view_slices_lod.rs (`texel_layers_match_their_twin`)",
    ),
    (
        "present",
        "preview window only: shows an image already computed (filmic tonemap, sRGB, difference \
         heat map, overlay text); no headless output goes through it",
    ),
];

/// Kernels whose twin a GPU test reaches through another twin function, which the test calls:
/// (kernel, that function, how). Kept true by the test below.
const COMPARED_THROUGH: &[(&str, &str, &str)] = &[
    (
        "scan_plane_offsets",
        "plane_draws",
        "the per-plane draw arguments the scan writes, against the twin's scan of the twin's counts \
         (tests/gpu/gpu_slicing.rs)",
    ),
    (
        "flood_point_grid",
        "bake_point_grid",
        "the point grid's twin floods with it as the kernels do; the flooded grid is compared \
         (tests/gpu/hypertexture_points.rs)",
    ),
    (
        "composite_tiles",
        "composite_tiles_frame",
        "the twin over the lists a rendered frame's kernels filled (tests/gpu/tile_compositor.rs)",
    ),
    ("bake_hypertexture", "bake_hypertexture_voxel", "voxel by voxel (tests/gpu/hypertexture_texel.rs)"),
    ("bake_height_image", "bake_height_image_voxel", "voxel by voxel (tests/gpu/axis_slices.rs)"),
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, ext, out);
        } else if path.extension().is_some_and(|e| e == ext) {
            out.push(path);
        }
    }
}

/// The text without `//` comments.
fn code(text: &str) -> String {
    text.lines().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n")
}

/// Kernel stems (file names without `.wgsl`) and their paths.
fn kernels() -> BTreeMap<String, PathBuf> {
    let wgsl = root().join("wgsl");
    let mut paths = Vec::new();
    files(&wgsl, "wgsl", &mut paths);
    let mut kernels = BTreeMap::new();
    for path in paths {
        if path.strip_prefix(&wgsl).unwrap().starts_with("shared") {
            continue;
        }
        let text = code(&std::fs::read_to_string(&path).unwrap());
        if ["@compute", "@vertex", "@fragment"].iter().any(|e| text.contains(e)) {
            let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
            if let Some(other) = kernels.insert(stem.clone(), path.clone()) {
                panic!("two kernels named {stem}: {} and {}", other.display(), path.display());
            }
        }
    }
    kernels
}

/// Names of the `pub fn`s (any visibility qualifier) in the twin modules under `src/`.
fn twin_functions() -> BTreeSet<String> {
    let mut paths = Vec::new();
    files(&root().join("src"), "rs", &mut paths);
    let mut names = BTreeSet::new();
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap();
        // A twin module says so in its module doc (host code such as `methods::ray_march`'s
        // `bake_mesh_grid`, which dispatches the kernel, does not count).
        let doc: String = text.lines().filter(|l| l.trim_start().starts_with("//!")).collect();
        if !doc.to_lowercase().contains("twin") {
            continue;
        }
        for line in code(&text).lines() {
            let line = line.trim_start();
            let Some(rest) = line.strip_prefix("pub") else { continue };
            let rest = match rest.strip_prefix('(') {
                Some(r) => r.split_once(')').map_or("", |(_, r)| r),
                None => rest,
            };
            if let Some(rest) = rest.trim_start().strip_prefix("fn ") {
                let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                names.insert(name);
            }
        }
    }
    names
}

#[test]
fn every_kernel_has_a_twin_of_its_name_or_a_listed_reason() {
    let kernels = kernels();
    assert!(kernels.len() >= 20, "found only {} kernels under wgsl/", kernels.len());
    let twins = twin_functions();
    let listed: BTreeMap<&str, &str> = NO_TWIN.iter().copied().collect();
    assert_eq!(listed.len(), NO_TWIN.len(), "a kernel listed twice in NO_TWIN");
    let mut problems = Vec::new();
    for (stem, path) in &kernels {
        let twin = twins.contains(stem);
        match (twin, listed.get(stem.as_str())) {
            (true, Some(_)) => {
                problems.push(format!("{stem} has a twin `pub fn {stem}` now: remove it from NO_TWIN"))
            }
            (false, None) => problems.push(format!(
                "{} has no CPU twin `pub fn {stem}` under src/ and is not in NO_TWIN",
                path.display()
            )),
            (false, Some(reason)) if reason.trim().is_empty() => {
                problems.push(format!("{stem}: empty reason in NO_TWIN"))
            }
            _ => {}
        }
    }
    for stem in listed.keys() {
        if !kernels.contains_key(*stem) {
            problems.push(format!("NO_TWIN lists {stem}, which is no kernel under wgsl/"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Whether `code` calls function `name` (`name(` not preceded by an identifier character, nor
/// by `fn `).
fn calls(code: &str, name: &str) -> bool {
    let pattern = format!("{name}(");
    code.match_indices(&pattern).any(|(at, _)| {
        let before = &code[..at];
        let prev = before.chars().next_back();
        !prev.is_some_and(|c| c.is_alphanumeric() || c == '_') && !before.ends_with("fn ")
    })
}

#[test]
fn every_twin_is_compared_with_its_kernel_in_a_gpu_test() {
    let mut paths = Vec::new();
    files(&root().join("tests/gpu"), "rs", &mut paths);
    let gpu_tests: Vec<String> = paths.iter().map(|p| code(&std::fs::read_to_string(p).unwrap())).collect();
    let called = |name: &str| gpu_tests.iter().any(|c| calls(c, name));
    let twins = twin_functions();
    let through: BTreeMap<&str, &str> = COMPARED_THROUGH.iter().map(|(k, f, _)| (*k, *f)).collect();
    let mut problems = Vec::new();
    let mut compared = 0;
    for stem in kernels().keys().filter(|k| twins.contains(*k)) {
        let by = through.get(stem.as_str()).copied().unwrap_or(stem);
        if called(by) {
            compared += 1;
        } else {
            problems.push(format!(
                "the twin of {stem} is compared in no GPU test: no file under tests/gpu/ calls `{by}(`"
            ));
        }
        if through.contains_key(stem.as_str()) && called(stem) {
            problems.push(format!("a GPU test calls `{stem}(` itself now: remove it from COMPARED_THROUGH"));
        }
    }
    for kernel in through.keys() {
        if !twins.contains(*kernel) {
            problems.push(format!("COMPARED_THROUGH lists {kernel}, which has no twin"));
        }
    }
    assert!(compared >= 25, "only {compared} twins found compared: is the scan broken?");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
