//! Host side of each method: view-aligned prism slicing, the reference ray caster, hypertexture ray
//! marching, and the opaque base surface.

pub mod axis_slices;
pub mod ray_march;
pub mod reference;
pub mod view_slices;
