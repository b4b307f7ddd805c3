//! Host side of `ShellMarch` (issue 31): a per-pixel compute ray caster through the shell, made
//! for speed at a measured error. Its objects share the Reference's layout (the prisms of every
//! ShellMarch object, their shells concatenated, level 0 of their volumes in one storage buffer:
//! `reference::build`), to which it adds, per prism, whether its map folds, per object an
//! occupancy pyramid of its texel (`bake::occupancy`) for empty-space skipping, per frame the
//! prisms binned into screen tiles (`tiles.rs`), and for the footprint filter the texel's MIP
//! levels in s and t (`filter.rs`).

/// Its scene-file knobs (`knobs.rs`, compiled in the scene layer: `scene::methods`).
pub(crate) use crate::scene::methods::shell_march as knobs;
mod filter;
pub mod march_shell;
mod object;
pub(crate) mod plugin;
mod tiles;

pub use object::{frame_twin_inputs, ShellSet};

use crate::gpu::bindings::counts as C;
use crate::gpu::bindings::shell_march as B;

/// What ShellMarch brings to the render graph.
pub(crate) const CONTRIBUTION: super::Contribution = super::Contribution {
    method: "ShellMarch",
    filters: &["ShellMarch"],
    resources: &[
        B::SHELL_PARAMS,
        B::SHELL_TILES,
        B::SHELL_TILE_PRISMS,
        B::SHELL_BOUNDS,
        B::SHELL_BANDS,
        B::SHELL_PRISMS,
        B::SHELL_OBJECTS,
        B::SHELL_VERTICES,
        B::VERTEX_FRAMES,
        B::TEXEL_ATLAS,
        B::NORMAL_ATLAS,
        B::SHELL_OCCUPANCY,
        B::SHELL_MARCH_STATE,
        B::SHELL_MARCH_COUNTS,
        B::SHELL_FILTERS,
        B::SHELL_MIPS,
        B::SHELL_NORMAL_MIPS,
    ],
    counts: &[C::SHELL_MARCH_DISPATCHES],
    texel_resources: &[B::TEXEL_ATLAS],
    gather: Some(object::gather),
};
