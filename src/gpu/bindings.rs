//! The resources each folder of `wgsl/` binds, as constants `build.rs` makes from the WGSL (a
//! `var<uniform>`, `var<storage>` or handle global of a kernel or of a file it includes):
//! `bindings::view_slices::SLICE_PARAMS` is `"slice_params"`. A method's Rust code binds its
//! inputs by these, so a resource its kernels stop declaring, or a misspelt name, is a build
//! error. Graph files stay data, and kernels on disk may override the built-in ones, so the
//! planner's checks of names at run time stay too.
//!
//! ```
//! assert_eq!(voltex::gpu::bindings::view_slices::SLICE_PARAMS, "slice_params");
//! ```
//!
//! A name the kernels do not declare does not compile:
//!
//! ```compile_fail
//! let _ = voltex::gpu::bindings::view_slices::SLICE_PARAMZ;
//! ```

#![allow(dead_code)] // Every folder's names, whether Rust binds them yet or not.

include!(concat!(env!("OUT_DIR"), "/bindings.rs"));
