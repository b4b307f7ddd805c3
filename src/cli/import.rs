//! `voltex import`: writes the scene that `voltex render|preview FILE` opens for an asset (a mesh
//! or an OpenVDB file), as an editable, commented scene file.

use std::path::PathBuf;

use clap::Args;

use voltex::scene::import;
use voltex::{Error, Result};

#[derive(Args)]
pub struct ImportArgs {
    /// An asset: a mesh (`.glb`, `.gltf` or `.obj`) or an OpenVDB file (`.vdb`).
    pub file: PathBuf,
    /// The scene file to write (default: FILE with the extension `.ron`).
    #[arg(short, long, visible_alias = "output")]
    pub out: Option<PathBuf>,
    /// The look a mesh gets, from the presets built in (scenes/presets/NAME.ron shows each on a
    /// sphere): grain (the default), moss, grass, fur, pears, cobbles, cloud.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Print nothing but warnings and errors (not the written scene's path).
    #[arg(short, long)]
    pub quiet: bool,
}

pub fn run(args: ImportArgs) -> Result<()> {
    if !import::is_asset(&args.file) {
        return Err(Error::Invalid(format!(
            "{}: expected an asset: a mesh (.glb, .gltf or .obj) or an OpenVDB file (.vdb)",
            args.file.display()
        )));
    }
    let out = args.out.unwrap_or_else(|| args.file.with_extension("ron"));
    let mesh = import::mesh_path(&args.file, &out);
    let text = import::scene_text(&args.file, &mesh.to_string_lossy(), args.preset.as_deref())?;
    // What `render` would read back must parse: check before writing.
    voltex::scene::parse(&text, &out)?;
    voltex::io::atomic::write_bytes(&out, text.as_bytes())?;
    if !args.quiet {
        println!("{}", out.display());
    }
    Ok(())
}
