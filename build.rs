//! Embeds every file under `wgsl/` and `graphs/`, and the presets' scene files
//! (`scenes/presets/*.ron`, for `voltex import --preset`), in the library (`gpu::sources`), so an
//! installed or copied binary renders without the source tree: `$OUT_DIR/embedded.rs` is a table of
//! `("wgsl/shared/types.wgsl", include_str!("/abs/.../wgsl/shared/types.wgsl"))` sorted by path.
//! Hidden files and editor backups (`.x.swp`, `x~`) are left out. Cargo reruns this script when
//! anything under either folder changes (a directory given to `rerun-if-changed` is scanned).
//!
//! It also writes `$OUT_DIR/bindings.rs` (`gpu::bindings`): for each folder of `wgsl/`, one
//! constant per resource its kernels bind (a `var<uniform>`, `var<storage>` or handle global,
//! their includes' too), e.g. `view_slices::SLICE_PARAMS = "slice_params"`, and in `counts` one
//! constant per count the built-in graphs' passes dispatch, repeat or draw by (`dispatch:
//! Threads("prisms", ..)`, `repeat: "reference_dispatches"`), e.g. `counts::PRISMS = "prisms"`.
//! Rust code that binds a resource or sets a count by one of these names no longer compiles when
//! the WGSL or the graph stops using it.

use std::path::{Path, PathBuf};

/// Folders embedded, with the extension their files must have (any where `None`).
const FOLDERS: &[(&str, Option<&str>)] = &[("wgsl", None), ("graphs", None), ("scenes/presets", Some("ron"))];

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    println!("cargo:rerun-if-changed=build.rs");
    let mut files = Vec::new();
    for (folder, ext) in FOLDERS {
        let dir = manifest.join(folder);
        println!("cargo:rerun-if-changed={}", dir.display());
        let mut found = Vec::new();
        collect(&dir, folder, &mut found);
        files
            .extend(found.into_iter().filter(|(rel, _)| ext.is_none_or(|e| rel.ends_with(&format!(".{e}")))));
    }
    files.sort();
    let mut out = String::from("&[\n");
    for (rel, abs) in &files {
        out.push_str(&format!("    ({rel:?}, include_str!({abs:?})),\n"));
    }
    out.push_str("]\n");
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    let dest = out_dir.join("embedded.rs");
    std::fs::write(&dest, out).unwrap_or_else(|e| panic!("cannot write {}: {e}", dest.display()));
    let dest = out_dir.join("bindings.rs");
    let mut bindings = bindings(&manifest.join("wgsl"), &files);
    bindings.push_str(&counts(&files));
    std::fs::write(&dest, bindings).unwrap_or_else(|e| panic!("cannot write {}: {e}", dest.display()));
}

/// The `bindings.rs` module text: per top-level folder of `wgsl/`, the resources its kernels bind.
fn bindings(wgsl: &Path, files: &[(String, String)]) -> String {
    let mut folders: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> =
        Default::default();
    for (rel, _) in files {
        let Some(rest) = rel.strip_prefix("wgsl/") else { continue };
        let Some((folder, _)) = rest.split_once('/') else { continue };
        if !rest.ends_with(".wgsl") || folder == "shared" {
            continue;
        }
        let mut seen = Vec::new();
        let globals = folders.entry(folder.to_string()).or_default();
        globals_of(wgsl, rest, &mut seen, globals);
    }
    let mut out = String::from("// Made by build.rs from the WGSL under wgsl/: do not edit.\n");
    for (folder, globals) in folders {
        out.push_str(&format!(
            "/// Resources bound by the kernels of `wgsl/{folder}/`.\npub mod {folder} {{\n"
        ));
        for g in globals {
            out.push_str(&format!("    /// `{g}`.\n    pub const {}: &str = {g:?};\n", g.to_uppercase()));
        }
        out.push_str("}\n");
    }
    out
}

/// The `counts` module text: every count named in a `dispatch`, `repeat` or `draw: Vertices` of a
/// graph under `graphs/` (quoted names that are not numbers).
fn counts(files: &[(String, String)]) -> String {
    let mut names = std::collections::BTreeSet::new();
    for (rel, abs) in files.iter().filter(|(rel, _)| rel.starts_with("graphs/") && rel.ends_with(".ron")) {
        let text = std::fs::read_to_string(abs).unwrap_or_else(|e| panic!("cannot read {rel}: {e}"));
        for line in text.lines().map(|l| l.split("//").next().unwrap_or("")) {
            let at = ["dispatch:", "repeat:", "Vertices("].iter().find_map(|key| line.find(key));
            let Some(at) = at else { continue };
            for (i, quoted) in line[at..].split('"').enumerate() {
                if i % 2 == 1 && quoted.parse::<u64>().is_err() {
                    names.insert(quoted.to_string());
                }
            }
        }
    }
    let mut out = String::from(
        "/// Counts the built-in graphs' passes dispatch, repeat or draw by.\npub mod counts {\n",
    );
    for n in names {
        out.push_str(&format!("    /// `{n}`.\n    pub const {}: &str = {n:?};\n", n.to_uppercase()));
    }
    out.push_str("}\n");
    out
}

/// The bound globals of the shader `rel` (relative to `wgsl/`) and of its includes, into `out`.
fn globals_of(wgsl: &Path, rel: &str, seen: &mut Vec<String>, out: &mut std::collections::BTreeSet<String>) {
    if seen.iter().any(|s| s == rel) {
        return;
    }
    seen.push(rel.to_string());
    let Ok(text) = std::fs::read_to_string(wgsl.join(rel)) else { return };
    for line in text.lines() {
        if let Some(inc) = line.trim().strip_prefix("#include") {
            globals_of(wgsl, inc.trim().trim_matches('"'), seen, out);
            continue;
        }
        // `@group(g) @binding(b) var<space, access> name: type;` or `var name: type;` at the top.
        let Some(at) = line.find("var") else { continue };
        let before = &line[..at];
        if !(before.is_empty() || before.trim_start().starts_with("@group")) {
            continue;
        }
        let decl = &line[at + 3..];
        let (space, name) = match decl.strip_prefix('<') {
            Some(rest) => match rest.split_once('>') {
                Some((space, name)) => (space.trim(), name),
                None => continue,
            },
            None if decl.starts_with(' ') => ("", decl),
            None => continue,
        };
        if space.starts_with("private") || space.starts_with("workgroup") {
            continue;
        }
        let name: String =
            name.trim_start().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        if !name.is_empty() {
            out.insert(name);
        }
    }
}

/// Whether a file or folder name is left out of the embedded set (tests use the same rule).
fn skipped(name: &str) -> bool {
    name.starts_with('.') || name.ends_with('~')
}

/// Every embedded file under `dir` as (`rel/path` with `/` separators, absolute path).
fn collect(dir: &Path, rel: &str, files: &mut Vec<(String, String)>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            println!("cargo:warning=not embedded (name is not UTF-8): {}", entry.path().display());
            continue;
        };
        if skipped(name) {
            continue;
        }
        let path = entry.path();
        let child = format!("{rel}/{name}");
        if path.is_dir() {
            collect(&path, &child, files);
        } else if let Some(abs) = path.to_str() {
            files.push((child, abs.to_string()));
        } else {
            println!("cargo:warning=not embedded (path is not UTF-8): {}", path.display());
        }
    }
}
