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
}

pub fn run(args: PlanArgs) -> Result<()> {
    let scene = scene::load(&args.scene)?;
    let bp = Blueprint::new(&scene, &args.overrides.options()?)?;
    print!("{}", bp.describe());
    Ok(())
}
