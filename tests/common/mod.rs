//! Shared helpers for integration tests: `mod common;` in a test file, then `common::golden::…`.
// Each test binary uses only some helpers.
#![allow(dead_code)]

pub mod golden;

/// Copies a folder tree (tests that edit copies of `wgsl/` and `graphs/`).
pub fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// This checkout (the compiled-in manifest folder).
pub fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the `voltex` binary with `VOLTEX_ROOT` set to this checkout.
pub fn voltex(args: &[&str]) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_voltex"));
    cmd.args(args).env("VOLTEX_ROOT", root());
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    cmd.output().unwrap()
}

/// The standard output of a run that must succeed (else its standard error in the panic).
pub fn ok(out: std::process::Output) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A path as `&str` for command arguments.
pub fn s(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}
