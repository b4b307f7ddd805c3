//! `voltex export`: texels, hypertexture nodes and volume nodes as OpenVDB files (`density` +
//! `Cd`); with `--world`, every textured object resampled in world space; with `--frames`, a
//! numbered sequence.

use std::path::PathBuf;

use voltex::gpu::sources::Sources;
use voltex::gpu::GpuContext;
use voltex::io::vdb::Compression;
use voltex::progress::{Progress, Verbosity};
use voltex::render::export::{self, ExportOptions};
use voltex::{scene, Error, Result};

#[derive(clap::Args)]
pub struct ExportArgs {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
    scene: PathBuf,
    /// Output folder (made if missing): one NAME.vdb per texel (per textured object with
    /// --world) and per node drawing a hypertexture or a volume.
    #[arg(short = 'o', long, visible_alias = "output")]
    out: PathBuf,
    /// Every textured object's look resampled into world-space voxels, one NAME.vdb per object
    /// (its node's name), where its shell puts it; in place of one tile per texel.
    #[arg(long)]
    world: bool,
    /// Voxel side of --world in world units (default per object: its texel voxel's mean world
    /// size).
    #[arg(long, requires = "world")]
    voxel: Option<f64>,
    /// Sub-points per axis averaged into each --world voxel, 1 to 8 (default: enough that the
    /// sub-points are no farther apart than the texel's voxels).
    #[arg(long, requires = "world")]
    samples: Option<u32>,
    /// Also write each --world object's base surface (world space, with its uvs) as NAME.obj.
    #[arg(long, requires = "world")]
    with_mesh: bool,
    /// Export frames A to B (inclusive), at time N / fps for frame N, as NAME.NNNN.vdb: the
    /// numbered sequence Blender, Houdini and Unreal import as one animated volume.
    #[arg(long, value_parser = super::parse_frames, conflicts_with = "time")]
    frames: Option<(u32, u32)>,
    /// Frames per second of --frames.
    #[arg(long, default_value_t = 24.0, requires = "frames")]
    fps: f64,
    /// Export only this texel, hypertexture node or volume node (repeatable; default: all of
    /// them).
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
    /// Also write view.json: output size, camera, background and lights, for other renderers
    /// (tools/peers/).
    #[arg(long)]
    view: bool,
    /// No progress on stderr (errors still show).
    #[arg(long, short)]
    quiet: bool,
    /// Keep every file's line above the progress bar on a terminal (without one, every line is
    /// printed anyway).
    #[arg(long, short, conflicts_with = "quiet")]
    verbose: bool,
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
    if let Some(v) = args.voxel.filter(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(Error::Invalid(format!("--voxel {v}: expected a positive number of world units")));
    }
    if let Some(n) = args.samples.filter(|n| !(1..=export::world::MAX_SAMPLES).contains(n)) {
        return Err(Error::Invalid(format!(
            "--samples {n}: expected 1 to {} sub-points per axis",
            export::world::MAX_SAMPLES
        )));
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err(Error::Invalid(format!("--fps {}: expected a positive frame rate", args.fps)));
    }
    let opts = ExportOptions {
        only: args.only,
        time: args.time,
        resolution: args.resolution,
        compression: match args.compression {
            CompressionArg::None => Compression::None,
            CompressionArg::Zip => Compression::Zip,
        },
        world: args.world.then_some(export::WorldOptions { voxel: args.voxel, samples: args.samples }),
    };
    let scene = scene::load(&args.scene)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    // Names and sizes of every frame are checked before any GPU work.
    let frames: Vec<Option<u32>> = match args.frames {
        Some((a, b)) => (a..=b).map(Some).collect(),
        None => vec![None],
    };
    let mut plans = Vec::new();
    for &frame in &frames {
        let time = frame.map(|n| n as f64 / args.fps).or(opts.time);
        plans.push((frame, export::plan(&scene, &export::ExportOptions { time, ..opts.clone() })?));
    }
    let made = !args.out.exists();
    if made {
        std::fs::create_dir_all(&args.out)
            .map_err(|e| Error::file(&args.out, format!("cannot make the output folder: {e}")))?;
    }
    let verbosity = Verbosity::from_flags(args.quiet, args.verbose);
    let view = args.view.then(|| export::view_json(&scene, &plans[0].1));
    let result = write_all(&args.out, &plans, view, opts.compression, args.with_mesh, verbosity);
    if result.is_err() && made {
        let _ = std::fs::remove_dir(&args.out); // only if still empty
    }
    result
}

fn write_all(
    out: &std::path::Path,
    plans: &[(Option<u32>, Vec<export::Export>)],
    view: Option<String>,
    compression: Compression,
    with_mesh: bool,
    verbosity: Verbosity,
) -> Result<()> {
    voltex::io::atomic::check_writable_dir(out)?;
    // What a world export may take, before any work: every voxel of the leaves its shell meets
    // is read back (16 bytes each), and at most those are written (4 bytes of density and 12 of
    // colour each, before compression); the voxel budget of `plan` bounds both.
    if !matches!(verbosity, Verbosity::Quiet) {
        for e in &plans[0].1 {
            if let export::Source::Shell(shell) = &e.source {
                let mib = (shell.voxels() * 16) as f64 / (1 << 20) as f64;
                eprintln!(
                    "{}: at most {} voxels in the leaves its shell meets: at most {mib:.0} MiB read back and \
                     {mib:.0} MiB in the file before compression{}",
                    e.what,
                    shell.voxels(),
                    if plans.len() > 1 { ", a frame" } else { "" }
                );
            }
        }
    }
    // Volume nodes are written from their grids: the GPU starts only for bakes.
    let mut gpu = None;
    if plans.iter().flat_map(|p| &p.1).any(|e| e.needs_gpu()) {
        gpu = Some((GpuContext::new()?, voltex::bake::Baker::full_precision(&Sources::project()?)));
    }
    // Every file is staged first and renamed into place only when all are written.
    let mut staged = Vec::new();
    let mut lines = Vec::new();
    let mut progress = Progress::new(plans.iter().map(|p| p.1.len()).sum(), verbosity);
    for (frame, exports) in plans {
        for e in exports {
            let start = std::time::Instant::now();
            let name = match frame {
                Some(n) => format!("{}.{n:04}", e.name),
                None => e.name.clone(),
            };
            progress.started(&name);
            let values = match &mut gpu {
                Some((ctx, baker)) if e.needs_gpu() => export::bake(ctx, baker, e)?,
                _ => Vec::new(),
            };
            let grids = export::grids(e, &values);
            let path = out.join(format!("{name}.vdb"));
            staged.push(voltex::io::vdb::stage(&path, &grids, compression)?);
            let active = match &grids[0].data {
                voltex::io::vdb::GridData::Float(v) => v.active_count(),
                _ => 0,
            };
            let [x, y, z] = e.resolution();
            let ms = start.elapsed().as_secs_f64() * 1e3;
            progress.finished(
                &name,
                &format!("{} {x}x{y}x{z}: {ms:.0} ms", e.what),
                true,
                verbosity == Verbosity::Verbose,
            );
            let convention = match &e.source {
                export::Source::Bake { opacity_length, .. } => {
                    format!("opacity length {}", *opacity_length as f32)
                }
                export::Source::Volume { density_scale, .. } => {
                    format!("density_scale {density_scale} applied")
                }
                export::Source::Shell(shell) => format!(
                    "{} voxels resampled, {:.2} M voxels/s",
                    shell.voxels(),
                    shell.voxels() as f64 / ms / 1e3
                ),
            };
            let bytes = staged.last().map_or(0, |s| s.bytes());
            lines.push(format!(
                "{}  {} {x}x{y}x{z}, {active} active voxels, {convention}, {:.1} MiB, {ms:.0} ms{}",
                path.display(),
                e.what,
                bytes as f64 / (1 << 20) as f64,
                e.note.as_ref().map(|n| format!("\n    note: {n}")).unwrap_or_default()
            ));
            if let (true, export::Source::Shell(shell)) = (with_mesh, &e.source) {
                let path = out.join(format!("{name}.obj"));
                let text = export::world::surface_obj(shell, &e.name);
                staged.push(voltex::io::atomic::stage(&path, |tmp| {
                    std::fs::write(tmp, &text)
                        .map_err(|err| Error::file(&path, format!("cannot write: {err}")))
                })?);
                lines.push(format!(
                    "{}  the base surface of object \"{}\", world space",
                    path.display(),
                    e.name
                ));
            }
        }
    }
    progress.end();
    if let Some(json) = view {
        let path = out.join("view.json");
        staged.push(voltex::io::atomic::stage(&path, |tmp| {
            std::fs::write(tmp, json).map_err(|e| Error::file(&path, format!("cannot write: {e}")))
        })?);
        lines.push(format!("{}  the view: size, camera, background, lights", path.display()));
    }
    for s in staged {
        s.commit()?;
    }
    for l in lines {
        println!("{l}");
    }
    Ok(())
}
