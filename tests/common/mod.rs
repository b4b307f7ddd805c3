//! Shared helpers for integration tests: `mod common;` in a test file, then `common::golden::…`.
// Each test binary uses only some helpers.
#![allow(dead_code)]

pub mod golden;
