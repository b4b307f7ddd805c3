//! `voltex bake`: texels baked on the GPU, written as slice stacks.

use std::path::PathBuf;

use voltex::gpu::sources::Sources;
use voltex::gpu::GpuContext;
use voltex::{io, scene, Result};

#[derive(clap::Args)]
pub struct BakeArgs {
    scene: PathBuf,
    /// Texels to bake (default: every texel of the scene).
    #[arg(long = "texel")]
    texels: Vec<String>,
    /// Output folder (default: out/bake/<scene name>).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(args: BakeArgs) -> Result<()> {
    let BakeArgs { scene: scene_path, texels, out } = args;
    let scene = scene::load(&scene_path)?;
    // A sequence is baked as its frames.
    let volumes =
        scene.texels.iter().filter(|(_, t)| !matches!(t.source, scene::TexelSource::Sequence { .. }));
    let names: Vec<String> =
        if texels.is_empty() { volumes.map(|(n, _)| n.clone()).collect() } else { texels.to_vec() };
    if names.is_empty() {
        return Err(voltex::Error::Invalid(format!("{}: the scene defines no texels", scene_path.display())));
    }
    // Every plan first, so an unknown texel fails before any GPU work.
    let plans =
        names.iter().map(|n| voltex::render::baked_texel(&scene, n)).collect::<voltex::Result<Vec<_>>>()?;
    let out =
        out.unwrap_or_else(|| PathBuf::from("out/bake").join(scene_path.file_stem().unwrap_or_default()));
    std::fs::create_dir_all(&out).map_err(|e| voltex::Error::file(&out, e))?;
    io::atomic::check_writable_dir(&out)?;
    let ctx = GpuContext::new()?;
    let mut baker = voltex::bake::Baker::new(&Sources::project()?);
    for plan in plans {
        let start = std::time::Instant::now();
        let baked = baker.bake(&ctx, &plan.request)?;
        let volume = voltex::bake::axis_slices::read_texture(&ctx, &baked.volume, 4)?;
        let dir = out.join(&plan.texel);
        voltex::io::stack::write(&dir, plan.request.resolution, &volume)?;
        let [w, h, d] = plan.request.resolution;
        println!("{} ({w}x{h}x{d}, {:.0} ms)", dir.display(), start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(())
}
