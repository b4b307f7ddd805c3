//! The `voltex` command line: the clap structs shared by subcommands (the top-level parser,
//! [`Overrides`], value parsers) and one module per subcommand, each with its arguments and `run`.

pub mod bake;
pub mod bench;
pub mod bench_report;
pub mod compare;
pub mod export;
pub mod farm;
pub mod import;
pub mod info;
pub mod pareto;
pub mod plan;
pub mod preview;
pub mod render;

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

use voltex::render::{MethodKind, RenderOptions};
use voltex::Result;

#[derive(Parser)]
#[command(
    name = "voltex",
    version,
    about = "Volumetric textures and hypertextures on wgpu",
    after_help = "Kernels (wgsl/) and graphs (graphs/) are built in; files on disk win: a shader is looked \
                  up beside the --graph file, then in $VOLTEX_ROOT/wgsl (default: the source tree voltex \
                  was built from, when it exists), then in the built-in copy."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Render a scene headless to EXR (linear, with metadata) and a tonemapped PNG.
    Render(render::RenderArgs),
    /// Bake texels on the GPU and write each as a slice stack: OUT/<texel>/slice_000.png onwards
    /// (16-bit RGBA, premultiplied, the scene's first light baked in; or 8-bit, float EXR,
    /// unlit) and manifest.json, readable as `Slices(dir: ..)`.
    Bake(bake::BakeArgs),
    /// Write every texel and every node's hypertexture as an OpenVDB file, OUT/<name>.vdb: a
    /// `density` grid (extinction per world unit) and a `Cd` colour grid, placed in the world,
    /// baked on the GPU at full precision (for Blender, Houdini, Mitsuba).
    Export(export::ExportArgs),
    /// Compare two EXR images: FLIP, relative RMSE, largest difference and non-finite pixels;
    /// optionally write a FLIP heat map (no GPU needed).
    Compare(compare::CompareArgs),
    /// Print the bakes, passes, pipelines and GPU memory a scene will use (no GPU needed).
    Plan(plan::PlanArgs),
    /// Write the scene that `render` and `preview` open for an asset: a mesh (.glb, .gltf, .obj)
    /// as a base surface under a default texel, or an OpenVDB file (.vdb) as a volume object;
    /// framed by a camera, editable.
    Import(import::ImportArgs),
    /// Open a window showing the scene, redrawn whenever the scene, its files, a graph or a kernel
    /// changes (keys and mouse: see the overlay and docs/src/preview.md).
    Preview(preview::PreviewArgs),
    /// Render every scene under a folder and compare it with its reference image (<stem>.ref.exr).
    Regress(voltex::regress::Args),
    /// Regression runs on a cluster: submit to Slurm as an array job and a merge job, or write a
    /// Kubernetes Indexed Job and its merge Job.
    Farm(farm::FarmArgs),
    /// Print the adapter, backend, driver, the features voltex uses and limits.
    Info,
    /// Benchmark view-aligned slicing (the 2002 paper's Table 1 set-up) with GPU timestamps.
    Bench(bench::BenchArgs),
    /// Benchmark hypertexture ray marching (the 2009 paper's Figure 11 set-up): frame times and
    /// the share of noise evaluation.
    BenchHyper(bench::BenchHyperArgs),
    /// The performance page's tables from `bench --json` and `bench-hyper --json` files: print
    /// them as Markdown, or write them into a page between its bench-report markers.
    BenchReport(bench_report::BenchReportArgs),
    /// Speed against error: sweep each method's quality knobs, time every setting with GPU
    /// timestamps, measure its error against a truth image, write pareto.csv and pareto.svg.
    Pareto(pareto::ParetoCmd),
}

#[derive(clap::Args, Clone, Default)]
pub struct Overrides {
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
    /// Render every textured object with this method (its lighting mode is kept); `reference`
    /// also switches RayMarch volume objects to the exact Reference.
    #[arg(long, value_parser = method_parser(true))]
    method: Option<MethodKind>,
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
    /// GPU memory the frame may allocate, e.g. 512M or 8G (default 4G); a scene over it is
    /// refused before any work.
    #[arg(long, value_parser = voltex::gpu::budget::parse_budget)]
    budget: Option<u64>,
    /// Extra images written as EXR channels beside the colour, by the names the graph declares,
    /// e.g. `depth,coverage,transmittance` (replaces the scene's `aovs`).
    #[arg(long, value_delimiter = ',')]
    aov: Option<Vec<String>>,
    /// Shadows of every RayMarch object: `none` (Phong), `rays` (a shadow ray per shaded sample)
    /// or `volume:N` (a light volume of resolution N) (default: the scene's).
    #[arg(long, value_parser = parse_shadows)]
    shadows: Option<ShadowsArg>,
    /// How every ViewSlices object composites its slices: `raster` (blended draws) or `tiles`
    /// (binned into screen tiles, composited front to back by compute) (default: the scene's).
    #[arg(long, value_enum)]
    compositor: Option<CompositorArg>,
    /// Level of detail of every ViewSlices object: `off` (the scene's planes, the texel at full
    /// resolution) or `auto` (planes and texel MIP level from the object's size on screen)
    /// (default: the scene's).
    #[arg(long, value_enum)]
    lod: Option<LodArg>,
    /// MIP-mapped slice images of every AxisSlices object: `on` (each pixel filters the slices
    /// over its footprint) or `off` (level 0) (default: the scene's `mipmaps`).
    #[arg(long, value_enum)]
    mipmaps: Option<OnOff>,
}

/// An `on`/`off` value.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnOff {
    On,
    Off,
}

/// A `--lod` value.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum LodArg {
    Off,
    Auto,
}

impl From<LodArg> for voltex::scene::Lod {
    fn from(l: LodArg) -> Self {
        match l {
            LodArg::Off => Self::Off,
            LodArg::Auto => Self::Auto,
        }
    }
}

/// A `--compositor` value.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum CompositorArg {
    Raster,
    Tiles,
}

impl From<CompositorArg> for voltex::scene::Compositor {
    fn from(c: CompositorArg) -> Self {
        match c {
            CompositorArg::Raster => Self::Raster,
            CompositorArg::Tiles => Self::Tiles,
        }
    }
}

/// A `--shadows` value (`None`: Phong without shadows).
#[derive(Clone, Copy, Debug)]
pub struct ShadowsArg(pub Option<voltex::scene::Shadows>);

pub fn parse_shadows(s: &str) -> std::result::Result<ShadowsArg, String> {
    voltex::scene::parse_shadows(s).map(ShadowsArg)
}

/// A method by its command-line name (`view-slices`), among the registered ones (those that
/// draw texels where `switchable`).
pub fn method_parser(switchable: bool) -> impl clap::builder::TypedValueParser<Value = MethodKind> {
    let names: Vec<&'static str> = MethodKind::all()
        .filter(|k| !switchable || k.switchable())
        .map(|k| &*Box::leak(k.cli_name().into_boxed_str()))
        .collect();
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(names)
        .map(|s: String| MethodKind::from_cli(&s).expect("a listed name"))
}

impl Overrides {
    pub fn options(&self) -> Result<RenderOptions> {
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
            if !(1..=voltex::scene::MAX_SUPERSAMPLE).contains(&n) {
                return Err(voltex::Error::Invalid(format!(
                    "--supersample {n}: expected 1 to {} samples per axis",
                    voltex::scene::MAX_SUPERSAMPLE
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
            method: self.method,
            step: self.step,
            supersample: self.supersample,
            time: self.time,
            axis_criteria: self.criteria,
            budget: self.budget,
            aovs: self.aov.clone(),
            shadows: self.shadows.map(|s| s.0),
            compositor: self.compositor.map(Into::into),
            lod: self.lod.map(Into::into),
            mipmaps: self.mipmaps.map(|m| m == OnOff::On),
            ..Default::default()
        })
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

pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WIDTHxHEIGHT, e.g. 512x512")?;
    let w: u32 = w.parse().map_err(|_| "expected WIDTHxHEIGHT, e.g. 512x512")?;
    let h: u32 = h.parse().map_err(|_| "expected WIDTHxHEIGHT, e.g. 512x512")?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err("expected a size between 1x1 and 16384x16384".into());
    }
    Ok((w, h))
}

/// Like other command-line tools, end quietly when the reader of stdout goes away
/// (`voltex compare a.exr b.exr | head -1`): Rust ignores SIGPIPE, so printing would panic.
pub fn default_sigpipe() {
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

/// Keeps memory the process frees for its next allocations instead of handing it back to the
/// system at once (glibc's malloc; call before any thread starts). A camera move in the preview
/// remakes every shell's camera-relative vertices and spheres, ~10 MB per million triangles:
/// pages fresh from the system cost a page fault each, which doubled the move's planning time
/// (17 ms against 8 ms on a 1M-triangle scene on llvmpipe's machine).
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            fn mallopt(param: i32, value: i32) -> i32;
        }
        // <malloc.h>: allocations below M_MMAP_THRESHOLD come from the heap, whose free top is
        // returned only beyond M_TRIM_THRESHOLD. 32 MiB is the largest mmap threshold glibc takes.
        const M_TRIM_THRESHOLD: i32 = -1;
        const M_MMAP_THRESHOLD: i32 = -3;
        // SAFETY: mallopt only changes malloc's thresholds; no thread runs yet.
        unsafe {
            mallopt(M_MMAP_THRESHOLD, 32 << 20);
            mallopt(M_TRIM_THRESHOLD, 512 << 20);
        }
    }
}

/// Mesa prints "XDG_RUNTIME_DIR is invalid" on every device unless that variable names a private
/// folder; give it one (before any thread starts) so users see only voltex's own messages.
pub fn private_runtime_dir() {
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

/// `--frames A..B`: frame numbers with A <= B.
pub(crate) fn parse_frames(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || "expected A..B, frame numbers with A <= B <= 99999, e.g. 0..47".to_string();
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a > b || b > 99_999 {
        return Err(bad());
    }
    Ok((a, b))
}
