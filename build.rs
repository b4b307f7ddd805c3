//! Embeds every file under `wgsl/` and `graphs/` in the library (`gpu::sources`), so an installed
//! or copied binary renders without the source tree: `$OUT_DIR/embedded.rs` is a table of
//! `("wgsl/shared/types.wgsl", include_str!("/abs/.../wgsl/shared/types.wgsl"))` sorted by path.
//! Hidden files and editor backups (`.x.swp`, `x~`) are left out. Cargo reruns this script when
//! anything under either folder changes (a directory given to `rerun-if-changed` is scanned).

use std::path::{Path, PathBuf};

const FOLDERS: &[&str] = &["wgsl", "graphs"];

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    println!("cargo:rerun-if-changed=build.rs");
    let mut files = Vec::new();
    for folder in FOLDERS {
        let dir = manifest.join(folder);
        println!("cargo:rerun-if-changed={}", dir.display());
        collect(&dir, folder, &mut files);
    }
    files.sort();
    let mut out = String::from("&[\n");
    for (rel, abs) in &files {
        out.push_str(&format!("    ({rel:?}, include_str!({abs:?})),\n"));
    }
    out.push_str("]\n");
    let dest = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR")).join("embedded.rs");
    std::fs::write(&dest, out).unwrap_or_else(|e| panic!("cannot write {}: {e}", dest.display()));
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
