//! Tests through the `voltex` binary: command-line errors, fault injection, an installed (copied) binary, the preview window under Xvfb.

#[path = "../common/mod.rs"]
mod common;

mod assets;
mod bench_json;
mod cli_errors;
mod export;
mod farm;
mod faults;
mod first_hour;
mod hostile_files;
mod install;
mod maxima;
mod method_plugin;
mod pareto;
mod presets;
mod preview_input;
mod preview_latency;
mod preview_window;
mod tutorial;
mod volumes;
