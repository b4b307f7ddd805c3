//! `voltex bench` (view-aligned slicing, the 2002 paper's Table 1) and `voltex bench-hyper`
//! (hypertexture ray marching, the 2009 paper's Figure 11).

use std::path::PathBuf;

use voltex::Result;

use super::parse_size;

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Scenes to measure (default: torus_egg and terrain).
    scenes: Vec<PathBuf>,
    /// Plane counts.
    #[arg(long, value_delimiter = ',', default_values_t = vec![250, 500, 1000])]
    planes: Vec<u32>,
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    size: (u32, u32),
    /// Timed frames per setting (after warm-up); the median is reported.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Plane count of the converged image that errors are measured against.
    #[arg(long, default_value_t = 4000)]
    reference_planes: u32,
}

pub fn run(args: BenchArgs) -> Result<()> {
    let BenchArgs { scenes, planes, size, frames, reference_planes } = args;
    voltex::bench::run(&scenes, &planes, size, frames, reference_planes)
}

#[derive(clap::Args)]
pub struct BenchHyperArgs {
    #[arg(long, value_parser = parse_size, default_value = "512x512")]
    size: (u32, u32),
    /// Timed frames per setting (after warm-up); the median is reported.
    #[arg(long, default_value_t = 3)]
    frames: usize,
    /// Only the first object (sphere).
    #[arg(long)]
    quick: bool,
    /// Only the table of segment strategies (bounds, depth peeling, EWA-style splatting).
    #[arg(long)]
    segments: bool,
}

pub fn run_hyper(args: BenchHyperArgs) -> Result<()> {
    let BenchHyperArgs { size, frames, quick, segments } = args;
    voltex::bench::hyper::run(size, frames, quick, segments)
}
