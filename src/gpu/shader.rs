//! WGSL loading: `#include "shared/x.wgsl"` expansion with a line map back to the original files,
//! then naga parsing and validation, so every shader error names `file:line:col` before any
//! pipeline is made.

use std::path::{Path, PathBuf};

use crate::error::{Error, FileLoc, Result};
use crate::gpu::sources::{Source, Sources};

/// A validated WGSL kernel: the naga module (handed to wgpu as IR, parsed once), its validation
/// info (used for reflection), and every file it was assembled from (on disk, or
/// `<embedded>/wgsl/...`).
pub struct Kernel {
    /// Path relative to the WGSL root, e.g. `view_slices/emit_slices.wgsl`.
    pub name: String,
    pub module: naga::Module,
    pub info: naga::valid::ModuleInfo,
    pub files: Vec<PathBuf>,
    /// Hash of the expanded source: the GPU module is reused while it is unchanged.
    pub source_hash: u64,
}

/// Expanded source plus, for each expanded line, the file and line it came from.
struct Expanded {
    text: String,
    origin: Vec<(usize, usize)>, // (index into files, 1-based line)
    files: Vec<PathBuf>,
}

fn expand(sources: &Sources, rel: &str, out: &mut Expanded, from: Option<FileLoc>) -> Result<()> {
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
        let (file, orig) =
            self.origin.get((line as usize).saturating_sub(1)).copied().unwrap_or((0, line as usize));
        FileLoc::new(&self.files[file], orig, col as usize)
    }
}

/// The naga capabilities voltex kernels may use on any adapter it supports.
pub fn capabilities() -> naga::valid::Capabilities {
    naga::valid::Capabilities::empty()
}

/// Loads, expands and validates `root/rel`, reading only files under the folder `root`.
pub fn load(root: &Path, rel: &str) -> Result<Kernel> {
    load_from(&Sources::folder(root), rel)
}

/// Loads, expands and validates the shader `rel` and its includes, each looked up in `sources`.
pub fn load_from(sources: &Sources, rel: &str) -> Result<Kernel> {
    let mut ex = Expanded { text: String::new(), origin: Vec::new(), files: Vec::new() };
    expand(sources, rel, &mut ex, None)?;
    load_expanded(rel, ex)
}

/// Validates WGSL given as text (tests and tools); `path` is only used in messages.
pub fn load_str(path: &Path, source: &str) -> Result<Kernel> {
    let ex = Expanded {
        text: source.to_string(),
        origin: (1..=source.lines().count()).map(|l| (0, l)).collect(),
        files: vec![path.to_path_buf()],
    };
    load_expanded(&path.display().to_string(), ex)
}

fn load_expanded(name: &str, ex: Expanded) -> Result<Kernel> {
    let module = naga::front::wgsl::parse_str(&ex.text).map_err(|e| {
        let loc = e.location(&ex.text);
        let (line, col) = loc.map(|l| (l.line_number, l.line_position)).unwrap_or((1, 1));
        Error::at(
            ex.locate(line, col),
            format!("WGSL parse error: {}", first_line(&e.emit_to_string(&ex.text))),
        )
    })?;
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
    let source_hash = crate::gpu::cache::key(&ex.text);
    Ok(Kernel { name: name.to_string(), module, info, files: ex.files, source_hash })
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
