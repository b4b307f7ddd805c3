//! Scene files (RON): types, loading with `file:line:col` errors, validation and flattening of the
//! node tree into world-space objects.
//!
//! Range checks run while deserializing (ron attaches the position); checks that need the whole
//! scene run after a first parse and are positioned by a second parse that fails at the
//! offending value (`Mark`). Files the scene refers to (OBJ, PNG) are loaded by [`load`].

/// Most samples per pixel axis of a supersampled render (`--supersample`, `regress.supersample`).
pub const MAX_SUPERSAMPLE: u32 = 8;

mod budget;
mod flatten;
pub mod hypertexture;
mod image;
pub mod import;
mod locations;
pub(crate) mod methods;
mod types;
mod validate;
pub(crate) mod values;

pub use budget::{MAX_NODES, MAX_SHAPE_VOXELS, MAX_TRIANGLES};
pub(crate) use flatten::{HyperNode, SceneObject, VolumeNode};
pub(crate) use hypertexture::Hypertexture;
pub use image::HeightImage;
pub(crate) use locations::Locations;
pub use types::*;
// The registered methods, each with its knob types (from its folder: see `methods`).
pub use methods::*;

use crate::error::{Error, FileLoc, Result};
use std::collections::BTreeMap;
use std::path::Path;

pub(crate) fn options() -> ron::Options {
    use ron::extensions::Extensions;
    // Method variants wrap a struct: `ViewSlices(planes: 400)` rather than `ViewSlices((planes: 400))`.
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
}

impl Scene {
    /// The methods the scene's nodes are drawn with (a density node without one: its default).
    pub(crate) fn methods(&self) -> Vec<Method> {
        fn walk(nodes: &[Node], out: &mut Vec<Method>) {
            for n in nodes {
                match &n.method {
                    Some(m) => out.push(m.value.clone()),
                    None if n.hypertexture.is_some() || n.volume.is_some() => {
                        out.push(Method::for_densities())
                    }
                    None => {}
                }
                walk(&n.children, out);
            }
        }
        let mut out = Vec::new();
        walk(&self.nodes, &mut out);
        out
    }

    /// The files (meshes, images, hypertexture meshes and point sets) and slice-stack folders the
    /// scene refers to, resolved.
    pub(crate) fn asset_paths(&self) -> Vec<std::path::PathBuf> {
        let a = &self.assets;
        a.meshes
            .keys()
            .chain(a.images.keys())
            .chain(a.stacks.keys())
            .chain(a.shapes.keys())
            .chain(a.point_sets.keys())
            .chain(a.volume_files.iter())
            .cloned()
            .collect()
    }

    /// A height image the scene refers to (by its path as written), as `load` read it.
    pub fn image(&self, path: &str) -> Option<&HeightImage> {
        self.assets.images.get(&self.assets.dir.join(path)).map(|i| i.as_ref())
    }

    /// A slice stack the scene refers to (by its path as written), as `load` read it.
    pub fn stack(&self, path: &str) -> Option<&crate::io::stack::SliceStack> {
        self.assets.stacks.get(&self.assets.dir.join(path)).map(|s| s.as_ref())
    }

    /// A mesh texel's pattern (by its path as written): closed parts when `fill` and the mesh is
    /// closed, else the whole mesh as one open part (`filled` false).
    pub fn texel_mesh(
        &self,
        path: &str,
        fill: bool,
    ) -> Option<(std::sync::Arc<crate::mesh::shape::MeshShape>, bool)> {
        let full = self.assets.dir.join(path);
        let closed = self.assets.texel_meshes.get(&(full.clone(), true)).filter(|_| fill);
        match closed {
            Some(s) => Some((s.clone(), true)),
            None => self.assets.texel_meshes.get(&(full, false)).map(|s| (s.clone(), false)),
        }
    }

    /// A volume of `volumes` as read from its file (by its name).
    pub fn volume(&self, name: &str) -> Option<&std::sync::Arc<crate::vdb::SparseVolume>> {
        self.assets.volumes.get(name)
    }

    /// The scene file's text.
    pub(crate) fn source(&self) -> &str {
        &self.source
    }
}

/// Reads, parses and checks a scene file, and loads the files it refers to.
/// A mesh asset (`.glb`, `.gltf`, `.obj`) is opened as the scene `voltex import` would write.
pub fn load(path: &Path) -> Result<Scene> {
    if import::is_asset(path) {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        return parse(&import::scene_text(path, name, None)?, path);
    }
    let source = crate::input::read_text(path, "a scene file")?;
    parse(&source, path)
}

/// Parses and checks scene text; `path` names it in errors and anchors relative file paths.
pub fn parse(source: &str, path: &Path) -> Result<Scene> {
    let mut scene: Scene =
        values::with_marking(BTreeMap::new(), || options().from_str(source)).map_err(|e| located(path, e))?;
    scene.path = path.to_path_buf();
    let dir = path.parent().unwrap_or(Path::new(""));
    let found = validate::check(&scene, dir, source, path);
    if let Some(first) = found.fail.values().next().cloned() {
        let again: ron::error::SpannedResult<Scene> =
            values::with_marking(found.fail, || options().from_str(source));
        return Err(match again {
            Err(e) => located(path, e),
            Ok(_) => Error::Invalid(format!("{}: {first}", path.display())),
        });
    }
    if let Some(e) = found.other {
        return Err(e);
    }
    for h in scene.hypertextures.values_mut() {
        match &mut h.object.value {
            hypertexture::SoftObject::Mesh { path, shape, .. } => {
                *shape = found.assets.shapes.get(&dir.join(&path.value)).cloned();
            }
            hypertexture::SoftObject::Points { path, set, .. } => {
                *set = found.assets.point_sets.get(&dir.join(&path.value)).cloned();
            }
            _ => {}
        }
        for noise in h.noises.value.iter_mut() {
            if let hypertexture::ShapeTransfer::Image { path, rows } = &mut noise.shape {
                if let Some(img) = found.assets.images.get(&dir.join(&path.value)) {
                    let at = |x: usize, y: usize| img.data[(y * img.width + x) * img.channels] as f64;
                    *rows = (0..img.height).map(|y| (0..img.width).map(|x| at(x, y)).collect()).collect();
                }
            }
        }
    }
    scene.assets = found.assets;
    // A slice stack's manifest gives its texel's opacity length unless the file does.
    for t in scene.texels.values_mut() {
        if let (TexelSource::Slices { dir: stack }, None) = (&t.source, t.opacity_length_given) {
            let manifest = scene.assets.stacks.get(&dir.join(&stack.value)).and_then(|s| s.manifest.as_ref());
            t.opacity_length_given = manifest.map(|m| m.opacity_length);
        }
    }
    // A warning at a mark is positioned like an error: by a parse that stops there.
    scene.warnings = (found.warnings.into_iter())
        .map(|(seq, msg)| match seq {
            Some(seq) => {
                let again: ron::error::SpannedResult<Scene> =
                    values::with_marking(BTreeMap::from([(seq, msg.clone())]), || options().from_str(source));
                match again {
                    Err(e) => located(path, e).to_string(),
                    Ok(_) => format!("{}: {msg}", path.display()),
                }
            }
            None => msg,
        })
        .collect();
    scene.locations = Locations::of(&scene, source);
    scene.source = source.to_string();
    Ok(scene)
}

/// ron's error at its position. Mark failures happen before their value is read, so the value
/// starts where ron's span ends.
fn located(path: &Path, e: ron::error::SpannedError) -> Error {
    let msg = match e.code {
        ron::Error::Eof => {
            "unexpected end of file: expected the rest of the scene (an unclosed `(`, `[` or `{`?)"
                .to_string()
        }
        ref code => code.to_string(),
    };
    let (pos, msg) = match msg.strip_prefix(values::MARK_PREFIX) {
        Some(m) => (e.span.end, m.to_string()),
        None => (e.span.start, msg),
    };
    Error::at(FileLoc::new(path, pos.line, pos.col), msg)
}

#[cfg(test)]
mod tests;
