//! GPU tests (software Vulkan is enough): the methods against their CPU twins, analytic answers and the Reference; bakes, scenes, hard cases, pareto, regress and the fuzz corpus through the library. One binary, so they share one device.

#[path = "../common/mod.rs"]
mod common;
#[path = "../fuzz_support/mod.rs"]
mod fuzz_support;

mod animation;
mod aov;
mod axis_slices;
mod bake_stack;
mod export;
mod export_world;
mod fuzz;
mod gpu_slicing;
mod graph_data;
mod hard_cases;
mod height_precision;
mod hypertexture;
mod hypertexture_mesh;
mod hypertexture_points;
mod hypertexture_segments;
mod hypertexture_splatting;
mod hypertexture_texel;
mod light_volume;
mod mesh_texel;
mod pareto;
mod preview_draft;
mod reference;
mod regress;
mod render_scenes;
mod shell_march;
mod stepped_frames;
mod texel_bakes;
mod texel_shadow;
mod tile_compositor;
mod view_slices_lod;
mod volume;
mod volume_exact;
