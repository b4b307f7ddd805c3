//! Host side of each method. Now: view-aligned prism slicing, and the opaque base surface.

pub mod shell;
pub mod view_slices;
