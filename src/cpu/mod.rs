//! CPU twins of the kernels whose math matters; tests run both on the same inputs.

pub mod bake;
pub mod bake_hypertexture;
pub mod bake_mesh_grid;
pub mod bake_mesh_texel;
pub mod bake_point_grid;
pub mod bake_splats;
pub mod bake_transfer;
pub(crate) mod decoded_texel;
pub(crate) mod flood_point_grid;
pub mod hypertexture;
pub mod mip_layers;
pub mod noise_simplex;
pub mod prism_map;
pub mod shadow_texel;
