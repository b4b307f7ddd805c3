//! `voltex bake`: texels baked on the GPU, written as slice stacks with a manifest.

use std::path::PathBuf;

use voltex::bake::BakeSource;
use voltex::gpu::sources::Sources;
use voltex::gpu::GpuContext;
use voltex::io::stack::{Manifest, StackLighting};
use voltex::progress::{Progress, Verbosity};
use voltex::{io, scene, Error, Result};

#[derive(clap::Args)]
pub struct BakeArgs {
    /// A scene file (.ron), or an asset opened as `voltex import` writes it: a mesh (.glb,
    /// .gltf, .obj) or an OpenVDB file (.vdb).
    scene: PathBuf,
    /// Texels to bake (default: every texel of the scene).
    #[arg(long = "texel")]
    texels: Vec<String>,
    /// Output folder (default: out/bake/<scene name>).
    #[arg(short = 'o', long, visible_alias = "output")]
    out: Option<PathBuf>,
    /// Bits per channel: 8 or 16 (PNG slices), or 32 (float EXR slices).
    #[arg(long, default_value_t = 16, value_parser = parse_depth)]
    depth: u32,
    /// The unlit albedo and alpha (straight colour, not premultiplied) instead of the colour
    /// shaded with the scene's first light.
    #[arg(long)]
    unlit: bool,
    /// No progress on stderr (errors still show).
    #[arg(long, short)]
    quiet: bool,
    /// Keep every texel's line above the progress bar on a terminal (without one, every line is
    /// printed anyway).
    #[arg(long, short, conflicts_with = "quiet")]
    verbose: bool,
}

fn parse_depth(s: &str) -> std::result::Result<u32, String> {
    match s.parse() {
        Ok(d @ (8 | 16 | 32)) => Ok(d),
        _ => Err("expected 8 or 16 (PNG slices) or 32 (float EXR slices)".into()),
    }
}

pub fn run(args: BakeArgs) -> Result<()> {
    let BakeArgs { scene: scene_path, texels, out, depth, unlit, quiet, verbose } = args;
    let scene = scene::load(&scene_path)?;
    // A sequence is baked as its frames.
    let volumes =
        scene.texels.iter().filter(|(_, t)| !matches!(t.source, scene::TexelSource::Sequence { .. }));
    let names: Vec<String> =
        if texels.is_empty() { volumes.map(|(n, _)| n.clone()).collect() } else { texels.to_vec() };
    if names.is_empty() {
        return Err(Error::Invalid(format!("{}: the scene defines no texels", scene_path.display())));
    }
    // Every plan first, so an unknown texel fails before any GPU work.
    let mut plans =
        names.iter().map(|n| voltex::render::baked_texel(&scene, n)).collect::<voltex::Result<Vec<_>>>()?;
    for plan in &mut plans {
        if unlit && matches!(plan.request.source, BakeSource::Stack(_)) {
            return Err(Error::Invalid(format!(
                "{}: texel \"{}\" is a slice stack with its lighting baked in: it has no unlit albedo",
                scene_path.display(),
                plan.texel
            )));
        }
        plan.request.per_pixel = unlit;
        if unlit {
            // The unlit albedo carries no lighting, baked shadows included.
            plan.request.shadow = None;
        }
    }
    let out =
        out.unwrap_or_else(|| PathBuf::from("out/bake").join(scene_path.file_stem().unwrap_or_default()));
    std::fs::create_dir_all(&out).map_err(|e| Error::file(&out, e))?;
    io::atomic::check_writable_dir(&out)?;
    let ctx = GpuContext::new()?;
    // f32 volumes, so 16- and 32-bit slices hold more than the render's 8 bits.
    let mut baker = voltex::bake::Baker::full_precision(&Sources::project()?);
    let verbosity = Verbosity::from_flags(quiet, verbose);
    let mut progress = Progress::new(plans.len(), verbosity);
    for plan in plans {
        let start = std::time::Instant::now();
        progress.started(&plan.texel);
        let baked = baker.bake(&ctx, &plan.request)?;
        let bytes = voltex::gpu::readback::read_texture(&ctx, &baked.volume, 16)?;
        let volume: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let dir = out.join(&plan.texel);
        let manifest = Manifest {
            format: io::stack::FORMAT.into(),
            resolution: plan.request.resolution,
            bounds: bounds(&scene, &plan.texel, &plan.request.source),
            opacity_length: plan.opacity_length,
            premultiplied: !unlit,
            lighting: match (unlit, stack_manifest(&scene, &plan.texel)) {
                (true, _) => StackLighting::Unlit,
                (false, Some(m)) => m.lighting, // a stack re-baked keeps what it holds
                (false, None) => StackLighting::Baked,
            },
            bit_depth: depth,
            slices: Vec::new(),
        };
        io::stack::write(&dir, &manifest, &volume)?;
        let [w, h, d] = plan.request.resolution;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        progress.finished(
            &plan.texel,
            &format!("texel \"{}\" {w}x{h}x{d}: {ms:.0} ms", plan.texel),
            true,
            verbose,
        );
        println!("{} ({w}x{h}x{d}, {ms:.0} ms)", dir.display());
    }
    progress.end();
    Ok(())
}

/// The box of its source's space a texel samples: a mesh's or hypertexture's object-space box,
/// a stack's own, else texel space.
fn bounds(scene: &scene::Scene, texel: &str, source: &BakeSource) -> [[f64; 3]; 2] {
    match (source, scene.texels.get(texel).map(|t| &t.source)) {
        (BakeSource::Hypertexture(h), _) => {
            let (lo, hi) = h.bounds();
            [lo.to_array(), hi.to_array()]
        }
        (_, Some(scene::TexelSource::Mesh { bounds, .. })) => [bounds.lo.to_array(), bounds.hi.to_array()],
        _ => stack_manifest(scene, texel).map_or([[0.0; 3], [1.0; 3]], |m| m.bounds),
    }
}

/// The manifest of the stack a `Slices` texel reads, if it has one.
fn stack_manifest<'a>(scene: &'a scene::Scene, texel: &str) -> Option<&'a Manifest> {
    match &scene.texels.get(texel)?.source {
        scene::TexelSource::Slices { dir } => scene.stack(&dir.value)?.manifest.as_ref(),
        _ => None,
    }
}
