//! The library's top-level modules form layers that only import downwards (DESIGN.md, "Layout"):
//! every `crate::MODULE` path in `src/` (grouped `crate::{..}` imports included) must name a
//! module of a lower layer than the file's own. A new top-level module must be placed in
//! `LAYERS`; an import that points upwards or sideways fails with the file that makes it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Lowest first. Modules of one layer may not import each other.
const LAYERS: &[&[&str]] = &[
    // Errors, fault injection, the Pod structs shared with WGSL, progress on stderr, work counters.
    &["error", "fault", "progress", "types", "work"],
    // Bounded reads of user files (every reader above uses them).
    &["input"],
    // Device, shader sources, reflection, caches; file formats; meshes, shells, BVHs; OpenVDB grids.
    &["gpu", "io", "mesh", "vdb"],
    // Render graphs; image metrics; scene files (no GPU), with the methods' knobs files (see
    // `is_knobs_file`).
    &["graph", "metrics", "scene"],
    // CPU twins shared by several methods.
    &["cpu"],
    // The hypertexture model (packing, mesh grids, splat sets).
    &["hypertexture"],
    // Texel bakes.
    &["bake"],
    // One folder per method.
    &["methods"],
    // Scene -> plan -> frame.
    &["render"],
    // Front ends of the library.
    &["pareto", "preview", "regress"],
    &["bench"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// Every `.rs` file under `dir`, recursively (also used by `surface.rs`).
pub(crate) fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The layered module a path below `crate::` belongs to: its first segment.
fn module_of(path: &str) -> String {
    let first = path.trim().split("::").next().unwrap_or("");
    first.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).next().unwrap_or("").to_string()
}

/// Layered modules a source text names through `crate::`.
fn imports(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (at, _) in text.match_indices("crate::") {
        let rest = &text[at + "crate::".len()..];
        let names: Vec<String> = if let Some(group) = rest.strip_prefix('{') {
            // `crate::{a::b, c}`: each item at depth 0.
            let end = group.find('}').unwrap_or(group.len());
            group[..end].split(',').map(module_of).collect()
        } else {
            let end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':' || c == '$'));
            vec![module_of(&rest[..end.unwrap_or(rest.len())])]
        };
        out.extend(names.into_iter().filter(|n| !n.is_empty()));
    }
    out
}

/// A method's knobs file, `methods/<method>/knobs.rs`: compiled in the scene layer
/// (`scene::methods`, by `#[path]`), so it may import only what the scene layer may.
fn is_knobs_file(rel: &Path) -> bool {
    let parts: Vec<String> = rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    parts.first().map(String::as_str) == Some("methods")
        && parts.last().map(String::as_str) == Some("knobs.rs")
        && parts.len() == 3
}

#[test]
fn modules_import_only_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    // `pub mod` or `pub(crate) mod`: internal modules are layered too.
    let modules: Vec<&str> = lib
        .lines()
        .filter(|l| !l.trim().starts_with("//"))
        .filter_map(|l| l.split_once("mod ")?.1.strip_suffix(';'))
        .collect();
    for m in &modules {
        assert!(layer_of(m).is_some(), "module `{m}` is in no layer of tests/checks/layers.rs: place it");
    }
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut wrong: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut edges = 0;
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let first = rel.components().next().unwrap().as_os_str().to_string_lossy();
        let module = if is_knobs_file(rel) { "scene" } else { first.trim_end_matches(".rs") };
        // The binary (main.rs, cli/) sits above the library.
        let Some(own) = layer_of(module) else { continue };
        let text = std::fs::read_to_string(file).unwrap();
        if is_knobs_file(rel) && text.contains("super::") {
            // Only `crate::` paths are scanned: a knobs file reaching its method by `super::`
            // would hide an upward import.
            wrong.entry("scene -> super::".into()).or_default().push(rel.display().to_string());
        }
        for target in imports(&text) {
            let Some(layer) = layer_of(&target) else { continue };
            if target == module {
                continue;
            }
            edges += 1;
            if layer >= own {
                wrong.entry(format!("{module} -> {target}")).or_default().push(rel.display().to_string());
            }
        }
    }
    assert!(edges > 100, "only {edges} imports found: is the scan broken?");
    let listing: Vec<String> = wrong.iter().map(|(e, f)| format!("{e} ({})", f.join(", "))).collect();
    assert!(listing.is_empty(), "imports that do not point to a lower layer:\n{}", listing.join("\n"));
}

#[test]
fn the_scan_sees_grouped_and_nested_imports() {
    let text =
        "use crate::gpu::{GpuContext, Inputs};\nuse crate::{Error, io::png};\nlet x = crate::render::f();";
    assert_eq!(imports(text), ["gpu", "Error", "io", "render"]);
    let grouped = "use crate::{scene::methods::Draws, methods::plan};";
    assert_eq!(imports(grouped), ["scene", "methods"]);
    assert!(is_knobs_file(Path::new("methods/view_slices/knobs.rs")));
    assert!(!is_knobs_file(Path::new("methods/view_slices/deep/knobs.rs")));
}

/// The graph core and the renderer reach methods only through `methods::REGISTRY` and the
/// `MethodPlan` trait: no file of theirs names a method's module, plan type or object filter.
#[test]
fn graph_and_render_name_no_method() {
    let mut names: Vec<String> = Vec::new();
    for c in voltex::methods::REGISTRY {
        names.extend(c.filters.iter().map(|f| format!("\"{f}\"")));
    }
    for module in ["view_slices", "axis_slices", "reference", "ray_march", "base_surface"] {
        names.push(format!("methods::{module}"));
    }
    names.extend(
        ["ViewSlicesPlan", "AxisPlan", "ReferencePlan", "ReferenceSet", "RayMarchPlan", "BaseSurfacePlan"]
            .map(String::from),
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&root.join("graph"), &mut files);
    rust_files(&root.join("render"), &mut files);
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for name in names.iter().filter(|name| code.contains(name.as_str())) {
                found.push(format!("{}:{}: {name}", f.display(), n + 1));
            }
        }
    }
    assert!(found.is_empty(), "graph/ or render/ names a method:\n{}", found.join("\n"));
}
