//! Checks that need no GPU: the book, the module layers, the twin list, shared struct layouts, scene and graph errors, image I/O and metrics, the library's public surface.

#[path = "../common/mod.rs"]
mod common;

mod adapters;
mod aov;
mod docs;
mod graph_errors;
mod io_metrics;
mod layers;
mod method_names;
mod names;
mod scene_errors;
mod strict;
mod surface;
mod truth;
mod twins;
mod types_layout;
mod write_back;
