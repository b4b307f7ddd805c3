//! The library's public surface stays narrow and documented (docs/src/architecture.md, "Public
//! surface"). An item is `pub` only when a front end (the binary in `src/main.rs` and `src/cli/`,
//! or a test under `tests/`) uses it; the rest is `pub(crate)` or private. A ratchet, read off
//! the source text: the number of `pub` declarations (items and fields) in the library may only
//! go down (lower the limit when you narrow). Every one of them has a `///` doc: src/lib.rs has
//! `#![deny(missing_docs)]`, and this scan also covers what rustc's lint skips, `pub` items of
//! `pub(crate)` modules that front ends reach through a public field or return type (e.g.
//! `gpu::reflect::Binding` in `PlannedPass::bindings`). No GPU, no build: `cargo doc` would need
//! every dependency checked again (minutes on CI's two cores), so rustdoc's own warnings are
//! checked by hand (`cargo doc --no-deps`).

use std::path::Path;

use crate::layers::rust_files;

/// `pub` declarations (not `pub(crate)`) in the library, fields included.
/// (1274: `vdb::voxels`, `GridVoxels` and `vdb::grids` for tests/gpu/volume_exact.rs, which checks the
/// GPU's sparse copy of every grid against the voxels as read; `tiles::composite_tiles_frame`
/// for the compositor's twin test; `Session::replan`, a camera move without a file read, for
/// tests/cli/faults.rs.)
/// (1285: the method plug-ins: `MethodKind` with the command-line names of the registered
/// methods for `--method` and `pareto --methods`, `methods::sweep::SweepValues` for `pareto`'s
/// flags, and `scene`'s re-exports of each method's knobs from its folder.)
/// (1286: `gpu::bindings`, the WGSL resource names made by build.rs, public for the doctest
/// that shows a misspelt one does not compile.)
/// (1301: ShellMarch, issue 31: its knobs (the struct and four fields, read by the tests and
/// the write-back check), its twin for the GPU test (`march_shell`, `folds`, `ShellObject` and
/// its fields, `frame_twin_inputs`, `ShellSet`) and `gpu::bindings::shell_march`.)
/// (1304: the GPU tests' adapter expectations read `GpuContext::info` and `features`; tests
/// bake a texel's derived products (`bake::derived::Derivations`, `MadeProducts::get`, AxisSlices'
/// `slice_images`), which the bake layer no longer names.)
/// (1325: `export --world`, issue 33: `WorldOptions` and `WorldShell` for the command line and
/// the GPU tests, its twin `resample_world` with the texel it samples (`world::texel`),
/// `surface_obj` for `--with-mesh`, `WorldParams` for the layout check, `gpu::bindings::export`,
/// `Staged::bytes` for the file sizes export prints.)
/// (1331: frames in steps for a preview that never blocks, issue 32: `Renderer::begin_steps`,
/// `step` and `read_frame` with `graph::exec::Steps` and its `progress` for the GPU test, and
/// the window's `measure_ui` argument.)
/// (1334: `pareto --supersample` and `--supersample-methods` (`pareto::Args`' two fields, for the
/// command line) and `RenderOptions::knobs` (the command line builds `RenderOptions` by struct
/// update, so every field is public), and `pareto::Args::verbosity` (`pareto -q/-v`).)
/// (1336: `Error::report`, the error with its source line quoted, printed by the command line.)
/// (1337: `bench::Args::verbosity` (`bench -q/-v`); `Prism::sphere` gave way to `Shell::spheres`.)
/// (1345: ShellMarch's footprint filter: the scene-file knobs `filter` and `mip_bias` and their
/// enum `Filter` (public as every knob type, for the scene reference's check), and the GPU struct
/// `ShellFilter` with its four fields (public as every `types` struct, for the layout check).)
/// (1347: `Renderer::render_showing` and `Verbosity::frame_progress`: `render` shows a frame's
/// progress.)
const PUB_DECLARATIONS: usize = 1347;

/// Whether the declaration on line `n` has a `///` doc above its attributes (one-line ones, or
/// multi-line ones from `#[` to `)]`).
fn documented(lines: &[&str], n: usize) -> bool {
    let mut k = n;
    while k > 0 {
        let above = lines[k - 1].trim();
        if above.starts_with("#[") {
            k -= 1;
        } else if above.ends_with(")]") {
            // The end of a multi-line attribute: back to its `#[`.
            while k > 0 && !lines[k - 1].trim().starts_with("#[") {
                k -= 1;
            }
            k = k.saturating_sub(1);
        } else {
            break;
        }
    }
    k > 0 && lines[k - 1].trim_start().starts_with("///")
}

/// (`pub` declarations, of which undocumented, the undocumented ones as `file:line`) in the
/// library's files: `src/` without the binary's `main.rs` and `cli/`.
fn scan() -> (usize, usize, Vec<String>) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let (mut all, mut undocumented, mut list) = (0, 0, Vec::new());
    for file in files {
        let rel = file.strip_prefix(&src).unwrap();
        if rel.starts_with("cli") || rel == Path::new("main.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            if !line.trim_start().starts_with("pub ") {
                continue;
            }
            all += 1;
            // Re-exports carry their item's doc; a module's is its `//!` (rustc checks both).
            let reexport_or_module =
                ["pub use ", "pub mod "].iter().any(|p| line.trim_start().starts_with(p));
            if !reexport_or_module && !documented(&lines, n) {
                undocumented += 1;
                list.push(format!("src/{}:{}", rel.display(), n + 1));
            }
        }
    }
    (all, undocumented, list)
}

#[test]
fn the_public_surface_only_narrows_and_gets_documented() {
    let (all, undocumented, list) = scan();
    assert!(all > 100, "only {all} `pub` declarations found: is the scan broken?");
    assert!(
        all <= PUB_DECLARATIONS,
        "{all} `pub` declarations in the library, more than the {PUB_DECLARATIONS} allowed: make what no front end \
         uses `pub(crate)`, or raise PUB_DECLARATIONS in tests/checks/surface.rs if a front end needs it"
    );
    assert!(
        undocumented == 0,
        "{undocumented} `pub` declarations without a `///` doc (re-exports and modules aside, whose docs rustc \
         checks): document them\n{}",
        list.join("\n")
    );
}

#[test]
fn the_scan_sees_docs_above_attributes() {
    let doc = ["/// Doc.", "#[derive(Debug)]", "#[serde(", "    deny_unknown_fields", ")]", "pub struct A;"];
    assert!(documented(&doc, 5));
    assert!(!documented(&doc[1..], 4));
    assert!(!documented(&["pub x: f32,"], 0));
    assert!(documented(&["    /// Width.", "    pub width: u32,"], 1));
}
