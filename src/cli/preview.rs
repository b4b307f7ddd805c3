//! `voltex preview`: the live window.

use std::path::{Path, PathBuf};

use voltex::preview::latency;
use voltex::preview::present::Mode;
use voltex::preview::window::{self, PreviewArgs as WindowArgs};
use voltex::Result;

use super::Overrides;

#[derive(clap::Args)]
pub struct PreviewArgs {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
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
    /// Keep the per-pass GPU times of the last 100 frames rendered in this Chrome/Perfetto trace
    /// (JSON, rewritten after each frame).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Open no window: measure the save-to-frame latency of typical edits (camera, light, knob,
    /// texel, noise) written into a copy of the scene beside it, and print it stage by stage.
    #[arg(long)]
    measure_latency: bool,
    /// With --measure-latency: timed saves per edit, after one warm-up.
    #[arg(long, default_value_t = 5, requires = "measure_latency", value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeat: u32,
    /// Open the window, switch to the reference view (every object drawn by the exact
    /// Reference) and time the window's frames while that frame renders, against the same frame
    /// rendered blocking; print the measurements and close.
    #[arg(long, conflicts_with = "measure_latency")]
    measure_ui: bool,
    /// With --measure-ui: switches to the reference view, each from the image view.
    #[arg(long, default_value_t = 3, requires = "measure_ui", value_parser = clap::value_parser!(u32).range(1..=100))]
    runs: u32,
    /// With --measure-latency or --measure-ui: also write the measurements to this JSON file.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum ViewArg {
    Image,
    /// The ground truth's image.
    #[value(name = "reference")]
    Truth,
    Difference,
}

pub fn run(args: PreviewArgs) -> Result<()> {
    let PreviewArgs {
        scene,
        overrides,
        record,
        quit_after,
        view,
        trace,
        measure_latency,
        repeat,
        measure_ui,
        runs,
        json,
    } = args;
    if json.is_some() && !measure_latency && !measure_ui {
        return Err(voltex::Error::Invalid("--json needs --measure-latency or --measure-ui".into()));
    }
    if measure_latency {
        let ctx = voltex::gpu::GpuContext::new()?;
        let report = latency::measure(&ctx, &scene, overrides.options()?, repeat as usize)?;
        print!("{}", report.table());
        if let Some(path) = &json {
            report.write(path)?;
            println!("wrote {}", path.display());
        }
        return Ok(());
    }
    let mode = match view {
        ViewArg::Image => Mode::Image,
        ViewArg::Truth => Mode::Truth,
        ViewArg::Difference => Mode::Difference,
    };
    let options = overrides.options()?;
    if let Some(t) = &trace {
        voltex::io::atomic::check_writable_dir(
            t.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")),
        )?;
    }
    let measure_ui = measure_ui.then_some((runs, json));
    window::run(WindowArgs { scene, options, record, quit_after, mode, trace, measure_ui })
}
