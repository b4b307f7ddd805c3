//! `voltex pareto`: speed against error over each method's quality knobs.

use std::path::PathBuf;

use voltex::render::MethodKind;
use voltex::Result;

use super::parse_size;

/// `voltex pareto`'s arguments (see `voltex::pareto::Args`).
#[derive(clap::Args)]
pub struct ParetoCmd {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
    scene: PathBuf,
    #[arg(long, value_parser = parse_size, default_value = "256x256")]
    size: (u32, u32),
    /// Timed frames per setting (after warm-up); medians are reported.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Output folder (default: out/pareto/<scene name>).
    #[arg(short = 'o', long, visible_alias = "output")]
    out: Option<PathBuf>,
    /// What errors are measured against: `reference`, `view-slices:PLANES` or
    /// `ray-march:STEP[:SHADOWS]` (SHADOWS as in --ray-shadows, e.g. ray-march:0.0005:rays).
    #[arg(long, default_value = "reference")]
    truth: voltex::pareto::TruthSource,
    /// Methods to sweep (ray-march: the step of every hypertexture object; default: those
    /// each method's plug-in sweeps by default, view-slices and reference).
    #[arg(long, value_delimiter = ',', value_parser = super::method_parser(false))]
    methods: Vec<MethodKind>,
    /// ViewSlices plane counts (each with the trivial reject on and off).
    #[arg(long, value_delimiter = ',', default_values_t = voltex::methods::sweep::SWEEP_PLANES)]
    planes: Vec<u32>,
    /// Also sweep ViewSlices with `lod: Auto` (planes and texel MIP level from the size on
    /// screen), each plane count its most planes.
    #[arg(long)]
    lod: bool,
    /// Reference ray steps, as multiples of the default step.
    #[arg(long, value_delimiter = ',', default_values_t = voltex::methods::sweep::DEFAULT_STEP_FACTORS)]
    steps: Vec<f64>,
    /// AxisSlices criteria: d (voxels) = p (pixels) = each value.
    #[arg(long, value_delimiter = ',', default_values_t = voltex::methods::sweep::DEFAULT_CRITERIA)]
    criteria: Vec<f64>,
    /// RayMarch steps (world units).
    #[arg(long, value_delimiter = ',', default_values_t = voltex::methods::sweep::DEFAULT_RAY_STEPS)]
    ray_steps: Vec<f64>,
    /// RayMarch segment strategies, each swept over every step: bounds, depth-peeling (4 passes),
    /// splatting (16 slabs).
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["bounds"])]
    ray_segments: Vec<SegmentsArg>,
    /// RayMarch with an adaptive stride: STEP:MAX_STEP pairs (world units), e.g.
    /// 0.002:0.03,0.002:0.06 (default: none).
    #[arg(long, value_delimiter = ',', value_parser = parse_adaptive)]
    ray_adaptive: Vec<(f64, f64)>,
    /// RayMarch shadows, each swept over every step: none (Phong), rays (shadow rays), volume:N
    /// (a light volume of resolution N), e.g. none,rays,volume:32,volume:64 (default: each
    /// object's own shading).
    #[arg(long, value_delimiter = ',', value_parser = super::parse_shadows)]
    ray_shadows: Vec<super::ShadowsArg>,
    /// CSV files of other renderers' renders of the same scene (tools/peers/: renderer,setting,
    /// samples,seconds,threads,version,rmse,rel_rmse,flip), shown beside voltex's methods in
    /// the tables and the chart.
    #[arg(long, num_args = 1..)]
    peers: Vec<PathBuf>,
    /// Render the truth with N x N samples per pixel, averaged: each pixel the mean over its
    /// area (the truth of methods that filter by the pixel's footprint).
    #[arg(long, default_value_t = 1)]
    supersample: u32,
    /// Render every swept setting with N x N samples per pixel, averaged.
    #[arg(long, default_value_t = 1)]
    supersample_methods: u32,
    /// Print no progress on stderr, only errors (the report still goes to stdout).
    #[arg(short, long)]
    quiet: bool,
    /// Keep every setting's result line above the progress bar on a terminal (without one,
    /// every line is printed anyway).
    #[arg(short, long, conflicts_with = "quiet")]
    verbose: bool,
}

fn parse_adaptive(s: &str) -> std::result::Result<(f64, f64), String> {
    let bad = || format!("`{s}`: expected STEP:MAX_STEP, positive world units with MAX_STEP >= STEP");
    let (step, max) = s.split_once(':').ok_or_else(bad)?;
    let value = |v: &str| v.trim().parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0);
    match (value(step), value(max)) {
        (Some(step), Some(max)) if max >= step => Ok((step, max)),
        _ => Err(bad()),
    }
}

/// RayMarch segment strategies `pareto` sweeps (with their default passes, slabs and grid).
#[derive(clap::ValueEnum, Clone, Copy)]
enum SegmentsArg {
    Bounds,
    DepthPeeling,
    Splatting,
}

fn segments(s: SegmentsArg) -> voltex::scene::Segments {
    match s {
        SegmentsArg::Bounds => voltex::scene::Segments::Bounds,
        SegmentsArg::DepthPeeling => voltex::scene::Segments::DepthPeeling {
            passes: voltex::scene::DEFAULT_PEEL_PASSES,
            splat_grid: voltex::scene::DEFAULT_SPLAT_GRID,
        },
        SegmentsArg::Splatting => voltex::scene::Segments::Splatting {
            slabs: voltex::scene::DEFAULT_SPLAT_SLABS,
            splat_grid: voltex::scene::DEFAULT_SPLAT_GRID,
        },
    }
}

pub fn run(p: ParetoCmd) -> Result<()> {
    voltex::pareto::run(&voltex::pareto::Args {
        scene: p.scene,
        frames: p.frames,
        out: p.out,
        truth: p.truth,
        methods: if p.methods.is_empty() {
            MethodKind::all().filter(|k| k.swept_by_default()).collect()
        } else {
            p.methods
        },
        sweep: voltex::methods::sweep::SweepValues {
            size: p.size,
            planes: p.planes,
            lod: p.lod,
            steps: p.steps,
            criteria: p.criteria,
            ray_steps: p.ray_steps,
            ray_segments: p.ray_segments.into_iter().map(segments).collect(),
            ray_adaptive: p.ray_adaptive,
            ray_shadows: p.ray_shadows.into_iter().map(|s| s.0).collect(),
        },
        peers: p.peers,
        supersample: p.supersample,
        supersample_methods: p.supersample_methods,
        verbosity: voltex::progress::Verbosity::from_flags(p.quiet, p.verbose),
    })
}
