//! Host side of each method. Now: view-aligned prism slicing, the reference ray caster, and the opaque base surface.

pub mod axis_slices;
pub mod reference;
pub mod shell;
pub mod view_slices;
