//! `voltex plan`: what a scene will bake, run and allocate (no GPU needed).

use std::path::PathBuf;

use voltex::render::Blueprint;
use voltex::{scene, Result};

use super::Overrides;

#[derive(clap::Args)]
pub struct PlanArgs {
    scene: PathBuf,
    #[command(flatten)]
    overrides: Overrides,
    /// Check against this machine's adapter's limits (opens it) instead of those every
    /// adapter is assumed to offer.
    #[arg(long)]
    adapter: bool,
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
    print!("{}", bp.describe());
    Ok(())
}
