//! `voltex bench-report`: the performance page's tables from `bench --json` and `bench-hyper
//! --json` files (adapter, date, load, every table, cost models, limits), printed as Markdown or
//! written into a page between its bench-report markers.

use std::path::PathBuf;

use voltex::bench::json::{self, Report};
use voltex::{Error, Result};

#[derive(clap::Args)]
pub struct BenchReportArgs {
    /// JSON files written by `bench --json` or `bench-hyper --json`.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Replace the section between the bench-report markers of this Markdown page (e.g.
    /// docs/src/performance.md) instead of printing it.
    #[arg(long)]
    update: Option<PathBuf>,
}

pub fn run(args: BenchReportArgs) -> Result<()> {
    let reports: Vec<(String, Report)> = args
        .files
        .iter()
        .map(|f| Ok((f.file_name().unwrap_or_default().to_string_lossy().to_string(), Report::read(f)?)))
        .collect::<Result<_>>()?;
    let section = json::markdown(&reports);
    match &args.update {
        None => print!("{section}"),
        Some(page) => {
            let text = voltex::input::read_text(page, "the page to update")?;
            let updated = json::splice(&text, &section).map_err(|e| Error::file(page, e))?;
            voltex::io::atomic::write_bytes(page, updated.as_bytes())?;
            println!("updated {}", page.display());
        }
    }
    Ok(())
}
