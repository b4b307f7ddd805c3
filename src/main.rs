//! The `voltex` command line: render, preview, regress, pareto, plan, info, bench, bench-hyper.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use voltex::gpu::cache::GpuCache;
use voltex::gpu::GpuContext;
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::{io, scene, Result};

#[derive(Parser)]
#[command(name = "voltex", version, about = "Volumetric textures and hypertextures on wgpu")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone, Default)]
struct Overrides {
    /// Output size, e.g. 128x128 (default: the scene's).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Plane count for every ViewSlices object (default: the scene's).
    #[arg(long)]
    planes: Option<u32>,
    /// Turn the bounding-sphere trivial reject off (for measurement).
    #[arg(long)]
    no_trivial_reject: bool,
    /// Render graph file (default: graphs/frame.ron).
    #[arg(long)]
    graph: Option<PathBuf>,
    /// Render every textured object with this method (its lighting mode is kept).
    #[arg(long, value_enum)]
    method: Option<MethodArg>,
    /// Render N x N samples per pixel and average them (anti-aliasing; e.g. 2 or 4).
    #[arg(long)]
    supersample: Option<u32>,
    /// Ray step (world units) for Reference and RayMarch objects (default: the scene's, else half
    /// a voxel for Reference).
    #[arg(long, allow_negative_numbers = true)]
    step: Option<f64>,
    /// Time of the frame in seconds (animated hypertextures; default: the scene's `time`).
    #[arg(long, allow_negative_numbers = true)]
    time: Option<f64>,
    /// AxisSlices criteria for every AxisSlices object: `D,P` (slice depth in voxels, apparent
    /// slice distance in pixels) or one value for both (default: the scene's).
    #[arg(long, value_parser = parse_criteria)]
    criteria: Option<(f64, f64)>,
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum ViewArg {
    Image,
    Reference,
    Difference,
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum MethodArg {
    ViewSlices,
    Reference,
    AxisSlices,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless to EXR (linear, with metadata) and a tonemapped PNG.
    Render {
        scene: PathBuf,
        /// Output EXR (default: out/<scene name>.exr); the PNG goes beside it. With --frames, the
        /// first frame's path: frame N is written as <stem>_NNNN.exr beside it.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Render frames A to B (inclusive) of an animation, at time N / fps for frame N.
        #[arg(long, value_parser = parse_frames, conflicts_with = "time")]
        frames: Option<(u32, u32)>,
        /// Frames per second of --frames.
        #[arg(long, default_value_t = 24.0, requires = "frames")]
        fps: f64,
        #[command(flatten)]
        overrides: Overrides,
    },
    /// Bake texels on the GPU and write each as a slice stack: OUT/<texel>/slice_000.png onwards
    /// (RGBA, premultiplied, the scene's first light baked in), readable as `Slices(dir: ..)`.
    Bake {
        scene: PathBuf,
        /// Texels to bake (default: every texel of the scene).
        #[arg(long = "texel")]
        texels: Vec<String>,
        /// Output folder (default: out/bake/<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Compare two EXR images: FLIP, relative RMSE, largest difference and non-finite pixels;
    /// optionally write a FLIP heat map (no GPU needed).
    Compare {
        actual: PathBuf,
        reference: PathBuf,
        /// Write the FLIP error heat map here (PNG).
        #[arg(long)]
        diff: Option<PathBuf>,
    },
    /// Print the bakes, passes, pipelines and GPU memory a scene will use (no GPU needed).
    Plan {
        scene: PathBuf,
        #[command(flatten)]
        overrides: Overrides,
    },
    /// Open a window showing the scene, redrawn whenever the scene, its files, a graph or a kernel
    /// changes (keys and mouse: see the overlay and the README).
    Preview {
        scene: PathBuf,
        #[command(flatten)]
        overrides: Overrides,
        /// Write each newly shown frame, as presented, to DIR/frame-N.png.
        #[arg(long)]
        record: Option<PathBuf>,
        /// Close the window after this many seconds.
        #[arg(long)]
        quit_after: Option<f64>,
        /// The view to start in (keys 1, 2, 3 switch).
        #[arg(long, value_enum, default_value = "image")]
        view: ViewArg,
    },
    /// Render every scene under a folder and compare it with its reference image (<stem>.ref.exr).
    Regress(voltex::regress::Args),
    /// Print the adapter, backend, driver, the features voltex uses and limits.
    Info,
    /// Benchmark view-aligned slicing (the 2002 paper's Table 1 set-up) with GPU timestamps.
    Bench {
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
    },
    /// Benchmark hypertexture ray marching (the 2009 paper's Figure 11 set-up): frame times and
    /// the share of noise evaluation.
    BenchHyper {
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
    },
    /// Speed against error: sweep each method's quality knobs, time every setting with GPU
    /// timestamps, measure its error against a truth image, write pareto.csv and pareto.svg.
    Pareto(ParetoCmd),
}

/// `voltex pareto`'s arguments (see `voltex::pareto::Args`).
#[derive(clap::Args)]
struct ParetoCmd {
    scene: PathBuf,
    #[arg(long, value_parser = parse_size, default_value = "256x256")]
    size: (u32, u32),
    /// Timed frames per setting (after warm-up); medians are reported.
    #[arg(long, default_value_t = 5)]
    frames: usize,
    /// Output folder (default: out/pareto/<scene name>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// What errors are measured against: `reference`, `view-slices:PLANES` or `ray-march:STEP`.
    #[arg(long, default_value = "reference")]
    truth: voltex::pareto::Truth,
    /// Methods to sweep (ray-march: the step of every hypertexture object).
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["view-slices", "reference"])]
    methods: Vec<SweepArg>,
    /// ViewSlices plane counts (each with the trivial reject on and off).
    #[arg(long, value_delimiter = ',', default_values_t = voltex::pareto::DEFAULT_PLANES)]
    planes: Vec<u32>,
    /// Reference ray steps, as multiples of the default step.
    #[arg(long, value_delimiter = ',', default_values_t = voltex::pareto::DEFAULT_STEP_FACTORS)]
    steps: Vec<f64>,
    /// AxisSlices criteria: d (voxels) = p (pixels) = each value.
    #[arg(long, value_delimiter = ',', default_values_t = voltex::pareto::DEFAULT_CRITERIA)]
    criteria: Vec<f64>,
    /// RayMarch steps (world units).
    #[arg(long, value_delimiter = ',', default_values_t = voltex::pareto::DEFAULT_RAY_STEPS)]
    ray_steps: Vec<f64>,
    /// RayMarch segment strategies, each swept over every step: bounds, depth-peeling (4 passes),
    /// splatting (16 slabs).
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["bounds"])]
    ray_segments: Vec<SegmentsArg>,
    /// RayMarch with an adaptive stride: STEP:MAX_STEP pairs (world units), e.g.
    /// 0.002:0.03,0.002:0.06 (default: none).
    #[arg(long, value_delimiter = ',', value_parser = parse_adaptive)]
    ray_adaptive: Vec<(f64, f64)>,
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

fn parse_criteria(s: &str) -> std::result::Result<(f64, f64), String> {
    let value = |v: &str| {
        let bad = || "expected D,P or one value for both, each in (0, 1024]".to_string();
        v.trim().parse::<f64>().ok().filter(|v| *v > 0.0 && *v <= 1024.0).ok_or_else(bad)
    };
    match s.split_once(',') {
        Some((d, p)) => Ok((value(d)?, value(p)?)),
        None => value(s).map(|v| (v, v)),
    }
}

fn parse_frames(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || "expected A..B, frame numbers with A <= B <= 99999, e.g. 0..47".to_string();
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a > b || b > 99_999 {
        return Err(bad());
    }
    Ok((a, b))
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WIDTHxHEIGHT, e.g. 512x512")?;
    let w: u32 = w.parse().map_err(|_| "expected WIDTHxHEIGHT, e.g. 512x512")?;
    let h: u32 = h.parse().map_err(|_| "expected WIDTHxHEIGHT, e.g. 512x512")?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err("expected a size between 1x1 and 16384x16384".into());
    }
    Ok((w, h))
}

impl Overrides {
    fn options(&self) -> Result<RenderOptions> {
        if let Some(p) = self.planes {
            if p == 0 || p > voltex::scene::MAX_PLANES {
                return Err(voltex::Error::Invalid(format!(
                    "--planes {p}: expected a plane count in 1..={}",
                    voltex::scene::MAX_PLANES
                )));
            }
        }
        if let Some(t) = self.time.filter(|t| !t.is_finite()) {
            return Err(voltex::Error::Invalid(format!("--time {t}: expected a finite number of seconds")));
        }
        if let Some(n) = self.supersample {
            if !(1..=8).contains(&n) {
                return Err(voltex::Error::Invalid(format!(
                    "--supersample {n}: expected 1 to 8 samples per axis"
                )));
            }
        }
        if let Some(s) = self.step {
            if !(s.is_finite() && s > 0.0) {
                return Err(voltex::Error::Invalid(format!("--step {s}: expected a positive world length")));
            }
        }
        Ok(RenderOptions {
            size: self.size,
            graph: self.graph.clone(),
            planes: self.planes,
            trivial_reject: self.no_trivial_reject.then_some(false),
            method: self.method.map(method_kind),
            step: self.step,
            supersample: self.supersample,
            time: self.time,
            axis_criteria: self.criteria,
            ..Default::default()
        })
    }
}

fn main() -> ExitCode {
    default_sigpipe();
    private_runtime_dir();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render { scene, output, frames: None, overrides, .. } => render(&scene, output, &overrides),
        Command::Render { scene, output, frames: Some(frames), fps, overrides } => {
            render_frames(&scene, output, frames, fps, &overrides)
        }
        Command::Bake { scene, texels, out } => bake(&scene, &texels, out),
        Command::Compare { actual, reference, diff } => compare(&actual, &reference, diff.as_deref()),
        Command::Plan { scene, overrides } => plan(&scene, &overrides),
        Command::Preview { scene, overrides, record, quit_after, view } => {
            use voltex::preview::present::Mode;
            let mode = match view {
                ViewArg::Image => Mode::Image,
                ViewArg::Reference => Mode::Reference,
                ViewArg::Difference => Mode::Difference,
            };
            overrides.options().and_then(|options| {
                let args = voltex::preview::window::PreviewArgs { scene, options, record, quit_after, mode };
                voltex::preview::window::run(args)
            })
        }
        Command::Regress(args) => voltex::regress::command(&args),
        Command::Info => GpuContext::new().map(|ctx| print!("{}", ctx.describe())),
        Command::Bench { scenes, planes, size, frames, reference_planes } => {
            voltex::bench::run(&scenes, &planes, size, frames, reference_planes)
        }
        Command::BenchHyper { size, frames, quick, segments } => {
            voltex::hypertexture::bench::run(size, frames, quick, segments)
        }
        Command::Pareto(p) => voltex::pareto::run(&voltex::pareto::Args {
            scene: p.scene,
            size: p.size,
            frames: p.frames,
            out: p.out,
            truth: p.truth,
            methods: p.methods.into_iter().map(sweep).collect(),
            planes: p.planes,
            steps: p.steps,
            criteria: p.criteria,
            ray_steps: p.ray_steps,
            ray_segments: p.ray_segments.into_iter().map(segments).collect(),
            ray_adaptive: p.ray_adaptive,
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bake(scene_path: &Path, texels: &[String], out: Option<PathBuf>) -> voltex::Result<()> {
    let scene = scene::load(scene_path)?;
    // A sequence is baked as its frames.
    let volumes =
        scene.texels.iter().filter(|(_, t)| !matches!(t.source, scene::TexelSource::Sequence { .. }));
    let names: Vec<String> =
        if texels.is_empty() { volumes.map(|(n, _)| n.clone()).collect() } else { texels.to_vec() };
    if names.is_empty() {
        return Err(voltex::Error::Invalid(format!("{}: the scene defines no texels", scene_path.display())));
    }
    // Every plan first, so an unknown texel fails before any GPU work.
    let plans =
        names.iter().map(|n| voltex::render::baked_texel(&scene, n)).collect::<voltex::Result<Vec<_>>>()?;
    let out =
        out.unwrap_or_else(|| PathBuf::from("out/bake").join(scene_path.file_stem().unwrap_or_default()));
    std::fs::create_dir_all(&out).map_err(|e| voltex::Error::file(&out, e))?;
    io::atomic::check_writable_dir(&out)?;
    let ctx = GpuContext::new()?;
    let mut baker = voltex::bake::Baker::new(&voltex::gpu::sources::Sources::project()?);
    for plan in plans {
        let start = std::time::Instant::now();
        let baked = baker.bake(&ctx, &plan.request)?;
        let volume = voltex::bake::axis_slices::read_texture(&ctx, &baked.volume, 4)?;
        let dir = out.join(&plan.texel);
        voltex::bake::stack::write(&dir, plan.request.resolution, &volume)?;
        let [w, h, d] = plan.request.resolution;
        println!("{} ({w}x{h}x{d}, {:.0} ms)", dir.display(), start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(())
}

fn compare(actual: &Path, reference: &Path, diff: Option<&Path>) -> voltex::Result<()> {
    use voltex::metrics;
    let (a, _) = voltex::io::exr::read(actual)?;
    let (r, _) = voltex::io::exr::read(reference)?;
    let flip = metrics::flip(&a, &r)?;
    println!("FLIP (mean)         {:.5}", flip.mean);
    println!("relative RMSE       {:.5}", metrics::relative_rmse(&a, &r)?);
    println!("largest difference  {:.3e}", metrics::max_abs_diff(&a, &r)?);
    println!("non-finite pixels   {} / {}", metrics::count_nonfinite(&a), metrics::count_nonfinite(&r));
    if let Some(path) = diff {
        voltex::io::png::write_rgba8(
            path,
            a.width,
            a.height,
            &metrics::diff_heatmap(&flip.map, a.width, a.height),
        )?;
        println!("heat map            {}", path.display());
    }
    Ok(())
}

/// Like other command-line tools, end quietly when the reader of stdout goes away
/// (`voltex compare a.exr b.exr | head -1`): Rust ignores SIGPIPE, so printing would panic.
fn default_sigpipe() {
    #[cfg(target_os = "linux")]
    {
        extern "C" {
            fn signal(signum: i32, handler: usize) -> usize;
        }
        const SIGPIPE: i32 = 13;
        const SIG_DFL: usize = 0;
        // SAFETY: restores the default disposition before any thread starts.
        unsafe {
            signal(SIGPIPE, SIG_DFL);
        }
    }
}

/// Mesa prints "XDG_RUNTIME_DIR is invalid" on every device unless that variable names a private
/// folder; give it one (before any thread starts) so users see only voltex's own messages.
fn private_runtime_dir() {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir()) {
            return;
        }
        let uid = std::fs::metadata("/proc/self").map(|m| m.uid()).unwrap_or(0);
        let dir = std::env::temp_dir().join(format!("voltex-runtime-{uid}"));
        if std::fs::DirBuilder::new().mode(0o700).create(&dir).is_ok() || dir.is_dir() {
            std::env::set_var("XDG_RUNTIME_DIR", &dir);
        }
    }
}

fn plan(scene_path: &Path, overrides: &Overrides) -> Result<()> {
    let scene = scene::load(scene_path)?;
    let bp = Blueprint::new(&scene, &overrides.options()?)?;
    print!("{}", bp.describe());
    Ok(())
}

fn render(scene_path: &Path, output: Option<PathBuf>, overrides: &Overrides) -> Result<()> {
    let opts = overrides.options()?;
    let scene = scene::load(scene_path)?;
    let exr_path = output_path(scene_path, output)?;
    let ctx = GpuContext::new()?;
    render_one(&ctx, &scene, &opts, &exr_path, &mut GpuCache::default(), true)
}

/// `render --frames A..B`: one scene, one device, bakes shared between frames; frame N at time
/// N / fps is written as `<stem>_NNNN.exr` (and `.png`) beside the output path.
fn render_frames(
    scene_path: &Path,
    output: Option<PathBuf>,
    (first, last): (u32, u32),
    fps: f64,
    overrides: &Overrides,
) -> Result<()> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(voltex::Error::Invalid(format!("--fps {fps}: expected a positive frame rate")));
    }
    let opts = overrides.options()?;
    let scene = scene::load(scene_path)?;
    let path = output_path(scene_path, output)?;
    let stem = path.file_stem().unwrap_or_default().to_string_lossy().to_string();
    let ctx = GpuContext::new()?;
    let mut cache = GpuCache::default();
    // A texel baked from an animated hypertexture is baked anew every frame: keep only what the
    // last frame used, or the bakes pile up (a sequence's frames are then re-baked when they
    // come back).
    let animated = scene.texels.values().any(|t| match &t.source {
        scene::TexelSource::Hypertexture { name, .. } => {
            scene.hypertextures.get(&name.value).is_some_and(|h| h.noises.iter().any(|n| n.speed != 0.0))
        }
        _ => false,
    });
    for n in first..=last {
        let frame_opts = RenderOptions { time: Some(n as f64 / fps), ..opts.clone() };
        let exr = path.with_file_name(format!("{stem}_{n:04}.exr"));
        cache.begin();
        render_one(&ctx, &scene, &frame_opts, &exr, &mut cache, n == first)?;
        if animated {
            cache.retain_used();
        }
    }
    Ok(())
}

/// The EXR path to write (default `out/<stem>.exr`), its folder checked writable before any GPU
/// work (`out/` is created when missing).
fn output_path(scene_path: &Path, output: Option<PathBuf>) -> Result<PathBuf> {
    let exr_path = output.unwrap_or_else(|| {
        let stem = scene_path.file_stem().unwrap_or_default();
        PathBuf::from("out").join(stem).with_extension("exr")
    });
    let dir = match exr_path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.exists() && dir == Path::new("out") {
        std::fs::create_dir_all(&dir).map_err(|e| voltex::Error::file(&dir, e))?;
    }
    io::atomic::check_writable_dir(&dir)?;
    Ok(exr_path)
}

fn render_one(
    ctx: &GpuContext,
    scene: &scene::Scene,
    opts: &RenderOptions,
    exr_path: &Path,
    cache: &mut GpuCache,
    warn: bool,
) -> Result<()> {
    let png_path = exr_path.with_extension("png");
    let bp = Blueprint::new(scene, opts)?;
    for w in scene.warnings.iter().filter(|_| warn) {
        eprintln!("warning: {w}");
    }
    for o in bp.objects.iter().filter(|_| warn) {
        for w in &o.object.report.warnings {
            eprintln!("warning: {}: object `{}`: {w}", scene.path.display(), o.object.name);
        }
    }
    // Nothing is evicted: a sequence's frames come back, and a scene's bakes are bounded.
    let mut renderer = Renderer::with_cache(ctx, bp, cache)?;
    let frame = renderer.render(ctx)?;
    let metadata = renderer.metadata(ctx, &frame);
    let meta: Vec<(&str, String)> = metadata.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    io::exr::write(exr_path, &frame.image, &meta)?;
    io::png::write_tonemapped(&png_path, &frame.image)?;
    let gpu = frame.gpu_ms().map(|t| format!("{t:.2} ms GPU")).unwrap_or_else(|| "no GPU timestamps".into());
    println!(
        "{} and {} ({}x{}, {gpu}, {})",
        exr_path.display(),
        png_path.display(),
        frame.image.width,
        frame.image.height,
        ctx.adapter_line()
    );
    for (pass, ms) in &frame.pass_times {
        println!("  {pass:<20} {ms:>9.3} ms");
    }
    Ok(())
}

/// The methods `pareto` sweeps: those of `--method`, and the hypertextures' ray marching.
#[derive(clap::ValueEnum, Clone, Copy)]
enum SweepArg {
    ViewSlices,
    Reference,
    AxisSlices,
    RayMarch,
}

fn sweep(m: SweepArg) -> voltex::pareto::Sweep {
    use voltex::pareto::Sweep;
    match m {
        SweepArg::ViewSlices => Sweep::Method(MethodKind::ViewSlices),
        SweepArg::Reference => Sweep::Method(MethodKind::Reference),
        SweepArg::AxisSlices => Sweep::Method(MethodKind::AxisSlices),
        SweepArg::RayMarch => Sweep::RayMarch,
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

fn method_kind(m: MethodArg) -> MethodKind {
    match m {
        MethodArg::ViewSlices => MethodKind::ViewSlices,
        MethodArg::Reference => MethodKind::Reference,
        MethodArg::AxisSlices => MethodKind::AxisSlices,
    }
}
