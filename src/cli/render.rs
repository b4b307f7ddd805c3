//! `voltex render`: a scene (or the frames of an animation) to EXR and PNG.

use std::path::{Path, PathBuf};

use voltex::gpu::cache::GpuCache;
use voltex::gpu::GpuContext;
use voltex::progress::Verbosity;
use voltex::render::trace::Track;
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::{io, scene, Result};

use super::Overrides;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
    scene: PathBuf,
    /// Output EXR (default: out/<scene name>.exr); the PNG goes beside it. `x.png` writes x.exr
    /// and x.png; a folder (existing, or ending in /) gets <scene name>.exr; missing folders are
    /// made. With --frames, the first frame's path: frame N is written as <stem>_NNNN.exr beside it.
    #[arg(short, long, visible_alias = "out")]
    output: Option<PathBuf>,
    /// Render frames A to B (inclusive) of an animation, at time N / fps for frame N.
    #[arg(long, value_parser = super::parse_frames, conflicts_with = "time")]
    frames: Option<(u32, u32)>,
    /// Frames per second of --frames.
    #[arg(long, default_value_t = 24.0, requires = "frames")]
    fps: f64,
    /// Write each frame's per-pass GPU times as a Chrome/Perfetto trace (JSON; open it in
    /// ui.perfetto.dev or chrome://tracing).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Print nothing but warnings and errors (no written paths, no pass times, no progress).
    #[arg(short, long)]
    quiet: bool,
    /// Also print how long planning, building (bakes, pipelines), rendering and writing took,
    /// and the frame's progress (a line at each tenth; on a terminal a bar shows it anyway).
    /// A frame with progress is submitted in steps: the same image, bit for bit, but on llvmpipe
    /// a Reference frame takes about a quarter longer than in one submission (`-q`, or stderr
    /// not a terminal).
    #[arg(short, long, conflicts_with = "quiet")]
    verbose: bool,
    #[command(flatten)]
    overrides: Overrides,
}

pub fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs { scene, output, frames, fps, trace, quiet, verbose, overrides } = args;
    let talk = Verbosity::from_flags(quiet, verbose);
    if let Some(t) = &trace {
        io::atomic::check_writable_dir(
            t.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")),
        )?;
    }
    let mut track = Track { name: format!("render {}", scene.display()), frames: Vec::new() };
    let ctx = match frames {
        None => render(&scene, output, &overrides, talk, &mut track),
        Some(frames) => render_frames(&scene, output, frames, fps, &overrides, talk, &mut track),
    }?;
    if let Some(path) = &trace {
        if track.frames.iter().all(|f| f.is_empty()) {
            eprintln!(
                "warning: {}: no timestamp queries on this adapter: the trace is empty",
                path.display()
            );
        }
        voltex::render::trace::write(path, &[track], &ctx.adapter_line())?;
        if talk != Verbosity::Quiet {
            println!("trace: {}", path.display());
        }
    }
    Ok(())
}

fn render(
    scene_path: &Path,
    output: Option<PathBuf>,
    overrides: &Overrides,
    talk: Verbosity,
    track: &mut Track,
) -> Result<GpuContext> {
    let opts = overrides.options()?;
    let scene = scene::load(scene_path)?;
    let exr_path = output_path(scene_path, output)?;
    let ctx = GpuContext::new()?;
    render_one(&ctx, &scene, &opts, &exr_path, &mut GpuCache::default(), None, talk, track)?;
    Ok(ctx)
}

/// `render --frames A..B`: one scene, one device, bakes shared between frames; frame N at time
/// N / fps is written as `<stem>_NNNN.exr` (and `.png`) beside the output path.
fn render_frames(
    scene_path: &Path,
    output: Option<PathBuf>,
    (first, last): (u32, u32),
    fps: f64,
    overrides: &Overrides,
    talk: Verbosity,
    track: &mut Track,
) -> Result<GpuContext> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(voltex::Error::Invalid(format!("--fps {fps}: expected a positive frame rate")));
    }
    let opts = overrides.options()?;
    let scene = scene::load(scene_path)?;
    let path = output_path(scene_path, output)?;
    let stem = path.file_stem().unwrap_or_default().to_string_lossy().to_string();
    let ctx = GpuContext::new()?;
    let mut cache = GpuCache::default();
    // A texel baked from an animated hypertexture is baked anew every frame: keep only what the
    // last frame used, or the bakes pile up (a sequence's frames are then re-baked when they
    // come back).
    let animated = scene.texels.values().any(|t| match &t.source {
        scene::TexelSource::Hypertexture { name, .. } => {
            scene.hypertextures.get(&name.value).is_some_and(|h| h.noises.iter().any(|n| n.speed != 0.0))
        }
        _ => false,
    });
    for n in first..=last {
        let frame_opts = RenderOptions { time: Some(n as f64 / fps), ..opts.clone() };
        let exr = path.with_file_name(format!("{stem}_{n:04}.exr"));
        cache.begin();
        render_one(&ctx, &scene, &frame_opts, &exr, &mut cache, Some((n, fps, n == first)), talk, track)?;
        if animated {
            cache.retain_used();
        }
    }
    Ok(ctx)
}

/// The EXR path to write (its PNG goes beside it), its folder made when missing and checked
/// writable before any GPU work. `-o` may name the EXR, the PNG (`x.png`: both are written, as
/// `x.exr` and `x.png`), or a folder (an existing one, or a path ending in `/`: the scene's name
/// in it); without it, `out/<stem>.exr`.
fn output_path(scene_path: &Path, output: Option<PathBuf>) -> Result<PathBuf> {
    let stem = scene_path.file_stem().unwrap_or_default();
    let named = output.unwrap_or_else(|| PathBuf::from("out").join(stem).with_extension("exr"));
    let folder = named.is_dir() || named.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR);
    let exr_path = match named.extension().and_then(|e| e.to_str()) {
        _ if folder => named.join(stem).with_extension("exr"),
        Some("exr" | "png") | None => named.with_extension("exr"),
        Some(other) => {
            return Err(voltex::Error::file(
                &named,
                format!(
                    "cannot write a .{other} image: expected an output ending in .exr or .png, or a folder"
                ),
            ))
        }
    };
    let dir = match exr_path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.exists() {
        std::fs::create_dir_all(&dir)
            .map_err(|e| voltex::Error::file(&dir, format!("cannot make the output folder: {e}")))?;
    }
    io::atomic::check_writable_dir(&dir)?;
    Ok(exr_path)
}

/// Renders one frame to `exr_path` (and its PNG); `frame`: a sequence's frame number, rate and
/// whether it is the first (whose warnings are printed).
#[allow(clippy::too_many_arguments)]
fn render_one(
    ctx: &GpuContext,
    scene: &scene::Scene,
    opts: &RenderOptions,
    exr_path: &Path,
    cache: &mut GpuCache,
    frame: Option<(u32, f64, bool)>,
    talk: Verbosity,
    track: &mut Track,
) -> Result<()> {
    let warn = frame.is_none_or(|f| f.2);
    let png_path = exr_path.with_extension("png");
    let since = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
    let started = std::time::Instant::now();
    let bp = Blueprint::new(scene, opts)?;
    let planned = since(started);
    for w in scene.warnings.iter().filter(|_| warn) {
        eprintln!("warning: {w}");
    }
    for o in bp.objects.iter().filter(|_| warn) {
        for w in &o.object.report.warnings {
            eprintln!("warning: {}: object `{}`: {w}", scene.path.display(), o.object.name);
        }
    }
    // Nothing is evicted: a sequence's frames come back, and a scene's bakes are bounded.
    let t = std::time::Instant::now();
    let mut renderer = Renderer::with_cache(ctx, bp, cache)?;
    let built = since(t);
    let sequence = frame;
    let t = std::time::Instant::now();
    let frame = renderer.render_showing(ctx, talk, "frame")?;
    let rendered = since(t);
    let t = std::time::Instant::now();
    track.frames.push(frame.spans.clone());
    let mut metadata = renderer.metadata(ctx, &frame);
    if let Some((n, fps, _)) = sequence {
        metadata.push(("voltex_frame".into(), n.to_string()));
        metadata.push(("voltex_fps".into(), fps.to_string()));
    }
    let meta: Vec<(&str, String)> = metadata.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    let extras = io::exr::Extras {
        channels: &frame.aovs,
        camera: Some(renderer.camera_attributes()),
        fps: sequence.map(|s| s.1),
    };
    io::exr::write_with(exr_path, &frame.image, &meta, &extras)?;
    io::png::write_tonemapped(&png_path, &frame.image)?;
    let written = since(t);
    if talk == Verbosity::Quiet {
        return Ok(());
    }
    let gpu = frame.gpu_ms().map(|t| format!("{t:.2} ms GPU")).unwrap_or_else(|| "no GPU timestamps".into());
    println!(
        "{} and {} ({}x{}, {gpu}, {})",
        exr_path.display(),
        png_path.display(),
        frame.image.width,
        frame.image.height,
        ctx.adapter_line()
    );
    for o in &renderer.blueprint.objects {
        for c in o.methods.iter().filter_map(|m| m.choices(o)) {
            println!("  object {}: {c}", o.object.name);
        }
    }
    for (pass, ms) in &frame.pass_times {
        println!("  {pass:<20} {ms:>9.3} ms");
    }
    if talk == Verbosity::Verbose {
        println!(
            "  wall: planned {planned:.1} ms, built {built:.1} ms (bakes, pipelines, inputs), rendered {rendered:.1} ms \
             (read back included), written {written:.1} ms"
        );
    }
    Ok(())
}
