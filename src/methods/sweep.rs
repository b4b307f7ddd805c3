//! What `voltex pareto` asks of each method: the values its command line gives, and the points
//! a method's plug-in makes of them ([`MethodPlugin::sweep`](super::plugin::MethodPlugin::sweep)).

use super::options::RenderOptions;
use crate::scene::{Segments, Shadows};

/// Default plane counts of the `ViewSlices` sweep.
pub const SWEEP_PLANES: [u32; 8] = [16, 32, 64, 128, 256, 512, 1024, 2048];
/// Default ray steps of the `Reference` sweep, as multiples of its default step.
/// (2x, half the truth's cost, would double the sweep's time; pass it with `--steps` if wanted.)
pub const DEFAULT_STEP_FACTORS: [f64; 4] = [4.0, 8.0, 16.0, 32.0];
/// Default `AxisSlices` criteria swept: `d = p` = each value (smaller: more slices).
pub const DEFAULT_CRITERIA: [f64; 6] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0];
/// Default `RayMarch` steps swept (world units): the paper's HQ (0.002) and IE (0.015) among them.
pub const DEFAULT_RAY_STEPS: [f64; 5] = [0.002, 0.004, 0.008, 0.015, 0.03];

/// The sweep's values from the command line (each method reads its own).
#[derive(Debug, Clone)]
pub struct SweepValues {
    /// Render size in pixels (width, height).
    pub size: (u32, u32),
    /// `ViewSlices` plane counts (each with the trivial reject on and off).
    pub planes: Vec<u32>,
    /// `ViewSlices` with `lod: Auto` too, each plane count its most planes (trivial reject on).
    pub lod: bool,
    /// `Reference` steps as multiples of the default step.
    pub steps: Vec<f64>,
    /// `AxisSlices` criteria, `d = p` (voxels and pixels).
    pub criteria: Vec<f64>,
    /// `RayMarch` steps (world units).
    pub ray_steps: Vec<f64>,
    /// `RayMarch` segment strategies, each swept over every step.
    pub ray_segments: Vec<Segments>,
    /// `RayMarch` with an adaptive stride: `(step, max_step)` pairs (world units).
    pub ray_adaptive: Vec<(f64, f64)>,
    /// `RayMarch` shadows, each swept over every step (`None`: Phong without shadows); empty:
    /// each object's own.
    pub ray_shadows: Vec<Option<Shadows>>,
}

/// What a method's sweep may know of the scene.
pub(crate) struct SweepScene {
    /// The scene has hypertexture or volume objects.
    pub(crate) has_hypertextures: bool,
    /// The truth's default ray step over the scene's objects (`Ok(None)`: no object has one),
    /// or why it could not be planned.
    pub(crate) truth_step: std::result::Result<Option<f64>, String>,
}

/// One point of a sweep: a description of the knobs and the options that apply them.
#[derive(Debug, Clone)]
pub(crate) struct SweepPoint {
    /// The knobs, e.g. `planes=64 reject=on` (no commas: it is a CSV field).
    pub(crate) knobs: String,
    /// A short name for the chart, e.g. `64` (`64 no-reject` with the trivial reject off).
    pub(crate) tag: String,
    /// The options that render it (the size included).
    pub(crate) options: RenderOptions,
}

/// The values without repeats, in their first order.
pub(crate) fn unique<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut out = Vec::new();
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}
