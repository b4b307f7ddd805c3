//! `voltex compare`: image metrics between two EXR files, optionally a FLIP heat map.

use std::path::PathBuf;

use voltex::{metrics, Result};

#[derive(clap::Args)]
pub struct CompareArgs {
    actual: PathBuf,
    reference: PathBuf,
    /// Write the FLIP error heat map here (PNG).
    #[arg(long)]
    diff: Option<PathBuf>,
}

pub fn run(args: CompareArgs) -> Result<()> {
    let CompareArgs { actual, reference, diff } = args;
    let (a, _) = voltex::io::exr::read(&actual)?;
    let (r, _) = voltex::io::exr::read(&reference)?;
    let flip = metrics::flip(&a, &r)?;
    println!("FLIP (mean)         {:.5}", flip.mean);
    println!("relative RMSE       {:.5}", metrics::relative_rmse(&a, &r)?);
    println!("largest difference  {:.3e}", metrics::max_abs_diff(&a, &r)?);
    println!("non-finite pixels   {} / {}", metrics::count_nonfinite(&a), metrics::count_nonfinite(&r));
    if let Some(path) = diff {
        voltex::io::png::write_rgba8(
            &path,
            a.width,
            a.height,
            &metrics::diff_heatmap(&flip.map, a.width, a.height),
        )?;
        println!("heat map            {}", path.display());
    }
    Ok(())
}
