//! `voltex bench` (view-aligned slicing, the 2002 paper's Table 1) and `voltex bench-hyper`
//! (hypertexture ray marching, the 2009 paper's Figure 11).

use std::path::PathBuf;

use voltex::Result;

use super::{parse_size, CompositorArg};

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
    /// Write every table row as JSON (adapter, date, knobs, times, errors, cost model).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Measure the adapter's blended fill rate, texture sample rate and noise rate in the same
    /// run and print each setting's share of the blend limit.
    #[arg(long)]
    limits: bool,
    /// Write the last timed frame of every setting as a Chrome/Perfetto trace (per-pass GPU times).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Compositors to measure, each on every setting: `raster` (blended draws), `tiles` (binned
    /// into screen tiles, composited front to back by compute).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = vec![CompositorArg::Raster])]
    compositor: Vec<CompositorArg>,
    /// Print no progress on stderr, only errors (the tables still go to stdout).
    #[arg(short, long)]
    quiet: bool,
    /// Keep every setting's result line above the progress bar on a terminal (without one,
    /// every line is printed anyway).
    #[arg(short, long, conflicts_with = "quiet")]
    verbose: bool,
}

pub fn run(args: BenchArgs) -> Result<()> {
    voltex::bench::run(&voltex::bench::Args {
        verbosity: voltex::progress::Verbosity::from_flags(args.quiet, args.verbose),
        compositors: args.compositor.into_iter().map(Into::into).collect(),
        scenes: args.scenes,
        planes: args.planes,
        size: args.size,
        frames: args.frames,
        reference_planes: args.reference_planes,
        json: args.json,
        limits: args.limits,
        trace: args.trace,
    })
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
    /// Only the table of shadows on the Figure 11 scenes (Phong, shadow rays, light volumes).
    #[arg(long)]
    shadows: bool,
    /// Step of the converged renders that errors are measured against (world units).
    #[arg(long, default_value_t = 0.001)]
    truth_step: f64,
    /// Write every table row as JSON (adapter, date, knobs, times, errors, cost model).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write the last timed frame of every setting as a Chrome/Perfetto trace (per-pass GPU times).
    #[arg(long)]
    trace: Option<PathBuf>,
}

pub fn run_hyper(args: BenchHyperArgs) -> Result<()> {
    let BenchHyperArgs { size, frames, quick, segments, shadows, truth_step, json, trace } = args;
    if !(truth_step.is_finite() && truth_step > 0.0) {
        return Err(voltex::Error::Invalid(format!(
            "--truth-step {truth_step}: expected a positive world length"
        )));
    }
    voltex::bench::hyper::run(&voltex::bench::hyper::Args {
        size,
        frames,
        quick,
        segments,
        shadows,
        truth_step,
        json,
        trace,
    })
}
