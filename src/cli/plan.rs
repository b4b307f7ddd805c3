//! `voltex plan`: what a scene will bake, run and allocate (no GPU needed).

use std::path::PathBuf;

use voltex::render::Blueprint;
use voltex::{scene, Result};

use super::Overrides;

#[derive(clap::Args)]
pub struct PlanArgs {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
    scene: PathBuf,
    #[command(flatten)]
    overrides: Overrides,
    /// Check against this machine's adapter's limits (opens it) instead of those every
    /// adapter is assumed to offer.
    #[arg(long)]
    adapter: bool,
    /// List every pruned pass (by default the passes of methods and object kinds the scene does
    /// not use are only counted).
    #[arg(short, long)]
    verbose: bool,
    /// Print nothing: the exit status (and any error) says whether the scene plans within the
    /// limits (a check for scripts and CI).
    #[arg(short, long, conflicts_with = "verbose")]
    quiet: bool,
}

pub fn run(args: PlanArgs) -> Result<()> {
    let scene = scene::load(&args.scene)?;
    let bp = Blueprint::new(&scene, &args.overrides.options()?)?;
    if args.adapter {
        let ctx = voltex::gpu::GpuContext::new()?;
        bp.check_limits(&ctx.limits, "this adapter's limit")?;
    } else {
        // No device needed: limits every adapter voltex supports offers; `render` checks its own.
        bp.check_limits(
            &voltex::gpu::budget::plan_limits(),
            "the limit `voltex plan` assumes; --adapter checks this machine's",
        )?;
    }
    if !args.quiet {
        print!("{}", bp.describe(args.verbose));
    }
    Ok(())
}
