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
    /// Print the metrics as one JSON object at full precision (flip, rel_rmse, rmse,
    /// max_difference; for scripts such as tools/peers/).
    #[arg(long)]
    json: bool,
    /// Print nothing (the heat map is still written; --json still prints its object).
    #[arg(short, long)]
    quiet: bool,
    /// Also print the image size and the FLIP map's percentiles (median, 95th, 99th, largest).
    #[arg(short, long, conflicts_with = "quiet")]
    verbose: bool,
}

pub fn run(args: CompareArgs) -> Result<()> {
    let CompareArgs { actual, reference, diff, json, quiet, verbose } = args;
    let (a, _) = voltex::io::exr::read(&actual)?;
    let (r, _) = voltex::io::exr::read(&reference)?;
    let flip = metrics::flip(&a, &r)?;
    // The heat map is written with --json too (it was silently left out).
    if let Some(path) = &diff {
        voltex::io::png::write_rgba8(
            path,
            a.width,
            a.height,
            &metrics::diff_heatmap(&flip.map, a.width, a.height),
        )?;
    }
    if json {
        let v = serde_json::json!({
            "flip": flip.mean,
            "rel_rmse": metrics::relative_rmse(&a, &r)?,
            "rmse": rmse(&a, &r),
            "max_difference": metrics::max_abs_diff(&a, &r)?,
        });
        println!("{v}");
        return Ok(());
    }
    if quiet {
        return Ok(());
    }
    println!("FLIP (mean)         {:.5}", flip.mean);
    if verbose {
        let mut sorted: Vec<f32> = flip.map.iter().copied().filter(|v| v.is_finite()).collect();
        sorted.sort_by(f32::total_cmp);
        let at =
            |q: f64| sorted.get(((sorted.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(0.0);
        println!("size                {}x{}", a.width, a.height);
        println!(
            "FLIP percentiles    median {:.5}, 95th {:.5}, 99th {:.5}, largest {:.5}",
            at(0.5),
            at(0.95),
            at(0.99),
            at(1.0)
        );
    }
    println!("relative RMSE       {:.5}", metrics::relative_rmse(&a, &r)?);
    println!("largest difference  {:.3e}", metrics::max_abs_diff(&a, &r)?);
    println!("non-finite pixels   {} / {}", metrics::count_nonfinite(&a), metrics::count_nonfinite(&r));
    if let Some(path) = diff {
        println!("heat map            {}", path.display());
    }
    Ok(())
}

/// RMSE over pixels and R, G, B (sizes already checked by the metrics above).
fn rmse(a: &voltex::io::Image, r: &voltex::io::Image) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&r.pixels)
        .map(|(x, y)| (0..3).map(|c| (x[c] as f64 - y[c] as f64).powi(2)).sum::<f64>())
        .sum();
    (sum / (3 * a.pixels.len().max(1)) as f64).sqrt()
}
