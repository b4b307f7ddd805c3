//! `voltex export`: texels and hypertexture nodes as OpenVDB files (`density` + `Cd`).

use std::path::PathBuf;

use voltex::gpu::sources::Sources;
use voltex::gpu::GpuContext;
use voltex::io::vdb::Compression;
use voltex::progress::{Progress, Verbosity};
use voltex::render::export::{self, ExportOptions};
use voltex::{scene, Error, Result};

#[derive(clap::Args)]
pub struct ExportArgs {
    scene: PathBuf,
    /// Output folder (made if missing): one NAME.vdb per texel and per node drawing a
    /// hypertexture.
    #[arg(long)]
    out: PathBuf,
    /// Export only this texel or hypertexture node (repeatable; default: all of them).
    #[arg(long = "only", value_name = "NAME")]
    only: Vec<String>,
    /// Time of the bake in seconds (animated hypertextures, sequences, moving surfaces;
    /// default: the scene's `time`).
    #[arg(long, allow_negative_numbers = true)]
    time: Option<f64>,
    /// Voxels along the longest side of a hypertexture node's box (the others in proportion).
    #[arg(long, default_value_t = export::DEFAULT_HYPER_RESOLUTION)]
    resolution: u32,
    /// How voxel values are stored.
    #[arg(long, value_enum, default_value_t = CompressionArg::Zip)]
    compression: CompressionArg,
    /// No progress on stderr (errors still show).
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::ValueEnum, Clone, Copy)]
enum CompressionArg {
    /// Every value as it is.
    None,
    /// zlib, active values only.
    Zip,
}

pub fn run(args: ExportArgs) -> Result<()> {
    if let Some(t) = args.time.filter(|t| !t.is_finite()) {
        return Err(Error::Invalid(format!("--time {t}: expected a finite number of seconds")));
    }
    if !(1..=1024).contains(&args.resolution) {
        return Err(Error::Invalid(format!("--resolution {}: expected 1 to 1024 voxels", args.resolution)));
    }
    let opts = ExportOptions {
        only: args.only,
        time: args.time,
        resolution: args.resolution,
        compression: match args.compression {
            CompressionArg::None => Compression::None,
            CompressionArg::Zip => Compression::Zip,
        },
    };
    let scene = scene::load(&args.scene)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    // Names, sizes and the output folder are checked before any GPU work.
    let exports = export::plan(&scene, &opts)?;
    let made = !args.out.exists();
    if made {
        std::fs::create_dir_all(&args.out)
            .map_err(|e| Error::file(&args.out, format!("cannot make the output folder: {e}")))?;
    }
    let verbosity = Verbosity::from_flags(args.quiet, false);
    let result = write_all(&args.out, &exports, opts.compression, verbosity);
    if result.is_err() && made {
        let _ = std::fs::remove_dir(&args.out); // only if still empty
    }
    result
}

fn write_all(
    out: &std::path::Path,
    exports: &[export::Export],
    compression: Compression,
    verbosity: Verbosity,
) -> Result<()> {
    voltex::io::atomic::check_writable_dir(out)?;
    let ctx = GpuContext::new()?;
    let mut baker = voltex::bake::Baker::full_precision(&Sources::project()?);
    // Every file is staged first and renamed into place only when all are written.
    let mut staged = Vec::new();
    let mut lines = Vec::new();
    let mut progress = Progress::new(exports.len(), verbosity);
    for e in exports {
        let start = std::time::Instant::now();
        progress.started(&e.name);
        let rgba = export::bake(&ctx, &mut baker, e)?;
        let grids = export::grids(e, &rgba);
        let path = export::path_in(out, e);
        staged.push(voltex::io::vdb::stage(&path, &grids, compression)?);
        let active = match &grids[0].data {
            voltex::io::vdb::GridData::Float(v) => v.active_count(),
            _ => 0,
        };
        let [x, y, z] = e.request.resolution;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        progress.finished(&e.name, &format!("{} {x}x{y}x{z}: {ms:.0} ms", e.what), true, false);
        lines.push(format!(
            "{}  {} {x}x{y}x{z}, {active} active voxels, opacity length {}, {ms:.0} ms{}",
            path.display(),
            e.what,
            e.opacity_length as f32,
            e.note.as_ref().map(|n| format!("\n    note: {n}")).unwrap_or_default()
        ));
    }
    progress.end();
    for s in staged {
        s.commit()?;
    }
    for l in lines {
        println!("{l}");
    }
    Ok(())
}
