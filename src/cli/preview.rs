//! `voltex preview`: the live window.

use std::path::{Path, PathBuf};

use voltex::preview::present::Mode;
use voltex::preview::window::{self, PreviewArgs as WindowArgs};
use voltex::Result;

use super::Overrides;

#[derive(clap::Args)]
pub struct PreviewArgs {
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
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum ViewArg {
    Image,
    Reference,
    Difference,
}

pub fn run(args: PreviewArgs) -> Result<()> {
    let PreviewArgs { scene, overrides, record, quit_after, view, trace } = args;
    let mode = match view {
        ViewArg::Image => Mode::Image,
        ViewArg::Reference => Mode::Reference,
        ViewArg::Difference => Mode::Difference,
    };
    let options = overrides.options()?;
    if let Some(t) = &trace {
        voltex::io::atomic::check_writable_dir(
            t.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")),
        )?;
    }
    window::run(WindowArgs { scene, options, record, quit_after, mode, trace })
}
