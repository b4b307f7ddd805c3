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
