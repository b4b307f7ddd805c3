//! Checks that need the whole scene (texel names, node consistency, files on disk) and the loading
//! of the files the scene refers to (OBJ meshes, height images).

use super::image::HeightImage;
use super::types::{HeightScale, MeshBounds, Node, Scene, Surface, Texel, TexelSource};
use super::values::Mark;
use super::Method;
use crate::error::Error;
use crate::io::stack::{self, SliceStack};
use crate::mesh::shape::MeshShape;
use crate::mesh::Mesh;
use crate::scene::methods::Draws;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Files a scene refers to, loaded once by `load`, by resolved path.
#[derive(Debug, Clone, Default)]
pub(crate) struct Assets {
    pub(crate) dir: PathBuf,
    pub(crate) meshes: BTreeMap<PathBuf, Arc<Mesh>>,
    pub(crate) images: BTreeMap<PathBuf, Arc<HeightImage>>,
    pub(crate) stacks: BTreeMap<PathBuf, Arc<SliceStack>>,
    /// Hypertexture mesh objects, welded and checked.
    pub(crate) shapes: BTreeMap<PathBuf, Arc<MeshShape>>,
    /// Hypertexture point sets, read and checked.
    pub(crate) point_sets: BTreeMap<PathBuf, Arc<crate::mesh::points::PointSet>>,
    /// Mesh texels' patterns by (path, filled): closed parts when filled, else one open part.
    pub(crate) texel_meshes: BTreeMap<(PathBuf, bool), Arc<MeshShape>>,
    /// Volumes read from their OpenVDB files, by name in `Scene::volumes`.
    pub(crate) volumes: BTreeMap<String, Arc<crate::vdb::SparseVolume>>,
    /// The OpenVDB files read, resolved (for the preview's watch list).
    pub(crate) volume_files: Vec<PathBuf>,
}

/// What the checks found: messages for marks (positioned by a second parse), and the first error
/// that has its own position (inside an OBJ file, say).
pub(super) struct Findings {
    pub(crate) fail: BTreeMap<usize, String>,
    pub(crate) other: Option<Error>,
    pub(crate) assets: Assets,
    /// Warnings, with the mark to position them at where they have one.
    pub(crate) warnings: Vec<(Option<usize>, String)>,
}

struct Checker<'a> {
    scene: &'a Scene,
    f: Findings,
}

impl Checker<'_> {
    fn fail<T>(&mut self, mark: &Mark<T>, msg: String) {
        self.f.fail.entry(mark.seq).or_insert(msg);
    }

    fn other(&mut self, e: Error) {
        self.f.other.get_or_insert(e);
    }

    fn mesh(&mut self, path: &Mark<String>) -> Option<Arc<Mesh>> {
        let full = self.f.assets.dir.join(&path.value);
        if let Some(m) = self.f.assets.meshes.get(&full) {
            return Some(m.clone());
        }
        // Special files and files over the cap fail at the path's position, before any read.
        if std::fs::metadata(&full).is_err() {
            let msg =
                format!("expected a mesh file (.obj, .gltf or .glb), but {} does not exist", full.display());
            self.fail(path, msg);
            return None;
        }
        if let Err(e) = crate::input::check(&full, crate::input::Kind::Asset, "a mesh file") {
            self.fail(path, e.to_string());
            return None;
        }
        // A glTF file's buffers may live beside it: it is read anew each time.
        let gltf = full.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
        let loaded = match gltf {
            true => crate::mesh::load(&full).map(Arc::new),
            false => crate::input::shared(&full, "", || crate::mesh::load(&full)),
        };
        match loaded {
            Ok(m) => {
                self.f.assets.meshes.insert(full, m.clone());
                Some(m)
            }
            Err(e) => {
                self.other(e);
                None
            }
        }
    }

    /// A hypertexture's mesh object: loaded, welded and checked for closure.
    fn mesh_object(&mut self, path: &Mark<String>) {
        let full = self.f.assets.dir.join(&path.value);
        if self.f.assets.shapes.contains_key(&full) {
            return;
        }
        let Some(mesh) = self.mesh(path) else { return };
        match MeshShape::new(&mesh, &full) {
            Ok(shape) => {
                self.f.assets.shapes.insert(full, Arc::new(shape));
            }
            Err(msg) => self.fail(path, msg),
        }
    }

    /// A hypertexture's point set: read and checked, its kernels' overlap within budget.
    fn points_object(&mut self, object: &Mark<super::hypertexture::SoftObject>) {
        let super::hypertexture::SoftObject::Points { path, radius, .. } = &object.value else { return };
        let full = self.f.assets.dir.join(&path.value);
        let set = match self.f.assets.point_sets.get(&full) {
            Some(s) => s.clone(),
            None => {
                if let Err(e) =
                    crate::input::check(&full, crate::input::Kind::Asset, "a point set (.ply or .obj)")
                {
                    self.fail(path, e.to_string());
                    return;
                }
                match crate::input::shared(&full, "", || crate::mesh::points::load(&full)) {
                    Ok(s) => {
                        self.f.assets.point_sets.insert(full, s.clone());
                        s
                    }
                    Err(e) => return self.other(e),
                }
            }
        };
        let overlap = set.overlap(*radius);
        if overlap > crate::mesh::points::MAX_OVERLAP {
            let msg = format!(
                "kernels of radius {radius} overlap about {overlap:.0} deep where the points of {} are densest: \
                 at most {} are allowed (the bake visits each at every grid sample; expected a smaller radius)",
                path.value,
                crate::mesh::points::MAX_OVERLAP
            );
            self.fail(object, msg);
        }
    }

    /// A mesh texel: a resolution the mesh grid allows, a box with volume, the pattern
    /// loaded and welded. Filling needs a closed mesh: an open one is drawn as a shell with a
    /// warning (filling by parity would flood the volume), as is a box that cuts the pattern.
    fn texel_mesh(
        &mut self,
        name: &str,
        t: &Texel,
        path: &Mark<String>,
        bounds: &Mark<MeshBounds>,
        fill: bool,
    ) {
        use crate::mesh::shape::MAX_TEXEL_SAMPLES;
        let samples: u64 = t.resolution.iter().map(|&n| n as u64).product();
        if t.resolution.contains(&1) || samples > MAX_TEXEL_SAMPLES {
            let msg = format!(
                "texel \"{name}\" is a mesh: expected at least 2 voxels per axis and at most {MAX_TEXEL_SAMPLES} in all \
                 (the bake's grid holds 16 bytes per voxel), found {:?}",
                t.resolution
            );
            return self.fail(path, msg);
        }
        let (lo, hi) = (bounds.lo, bounds.hi);
        if let Some(a) = (0..3).find(|&a| lo[a] >= hi[a]) {
            let msg = format!(
                "expected `lo` below `hi` on every axis, found {} >= {} on {}",
                lo[a],
                hi[a],
                ["x", "y", "z"][a]
            );
            return self.fail(bounds, msg);
        }
        let full = self.f.assets.dir.join(&path.value);
        let Some(mesh) = self.mesh(path) else { return };
        let mut filled = fill;
        if fill && !self.f.assets.texel_meshes.contains_key(&(full.clone(), true)) {
            match MeshShape::new(&mesh, &full) {
                Ok(shape) => {
                    self.f.assets.texel_meshes.insert((full.clone(), true), Arc::new(shape));
                }
                Err(msg) => {
                    self.f.warnings.push((None, format!(
                        "{msg}; texel \"{name}\" cannot be filled by parity without flooding: drawn as a one-voxel shell (`fill: false`)"
                    )));
                    filled = false;
                }
            }
        }
        if !filled && !self.f.assets.texel_meshes.contains_key(&(full.clone(), false)) {
            match MeshShape::open(&mesh, &full) {
                Ok(shape) => {
                    self.f.assets.texel_meshes.insert((full.clone(), false), Arc::new(shape));
                }
                Err(msg) => return self.fail(path, msg),
            }
        }
        let shape = &self.f.assets.texel_meshes[&(full.clone(), filled)];
        if (0..3).any(|a| shape.lo[a] < lo[a] || shape.hi[a] > hi[a]) {
            let msg = format!(
                "texel \"{name}\": the bounds {:?} to {:?} cut the pattern {}, which spans {:?} to {:?}: the texel holds only the part inside",
                lo.to_array(),
                hi.to_array(),
                full.display(),
                shape.lo.to_array(),
                shape.hi.to_array()
            );
            self.f.warnings.push((Some(bounds.seq), msg));
        }
    }

    /// A hypertexture texel: a known hypertexture, a box with volume, a volume the bake can
    /// afford; an opacity length other than the hypertexture's warns (the texel would not be as
    /// opaque as RayMarch draws the hypertexture).
    fn texel_hypertexture(
        &mut self,
        texel: &str,
        t: &Texel,
        name: &Mark<String>,
        bounds: Option<&Mark<MeshBounds>>,
    ) {
        let resolution = t.resolution;
        let Some(h) = self.scene.hypertextures.get(&name.value) else {
            let names: Vec<String> = self.scene.hypertextures.keys().map(|k| format!("\"{k}\"")).collect();
            let expected = if names.is_empty() {
                "no hypertextures are defined in `hypertextures`".to_string()
            } else {
                format!("expected one of {}", names.join(", "))
            };
            return self.fail(name, format!("unknown hypertexture \"{}\": {expected}", name.value));
        };
        if let Some(given) = t.opacity_length_given {
            let own = h.opacity_length as f32;
            if (given / own - 1.0).abs() > 1e-4 {
                let msg = format!(
                    "texel \"{texel}\": an opacity_length of {given} makes the baked hypertexture \"{}\" {} opaque \
                     than its hypertexture nodes draw it (its opacity_length is {own}; leave the texel's out to take it)",
                    name.value,
                    if given < own { "more" } else { "less" }
                );
                self.f.warnings.push((Some(name.seq), msg));
            }
        }
        let voxels: u64 = resolution.iter().map(|&r| r as u64).product();
        if voxels > MAX_HYPERTEXTURE_VOXELS {
            let msg = format!(
                "texel \"{texel}\": a resolution of {resolution:?} is {voxels} voxels: a hypertexture bake takes at most \
                 {MAX_HYPERTEXTURE_VOXELS} (256^3)"
            );
            return self.fail(name, msg);
        }
        if let Some(b) = bounds {
            if let Some(a) = (0..3).find(|&a| b.lo[a] >= b.hi[a]) {
                let msg = format!(
                    "expected `lo` below `hi` on every axis, found {} >= {} on {}",
                    b.lo[a],
                    b.hi[a],
                    ["x", "y", "z"][a]
                );
                self.fail(b, msg);
            }
        }
    }

    /// A 2D shape transfer function's image: 2 to 256 columns (noise), 2 to 64 rows (density).
    fn shape_image(&mut self, path: &Mark<String>) {
        use super::hypertexture::{MAX_ROWS, MAX_TABLE};
        let Some(img) = self.image(path) else { return };
        if !(2..=MAX_TABLE).contains(&img.width) || !(2..=MAX_ROWS).contains(&img.height) {
            let msg = format!(
                "expected an image of 2 to {MAX_TABLE} columns (noise) and 2 to {MAX_ROWS} rows (density), {} is {}x{}",
                path.value, img.width, img.height
            );
            self.fail(path, msg);
        }
    }

    fn image(&mut self, path: &Mark<String>) -> Option<Arc<HeightImage>> {
        let full = self.f.assets.dir.join(&path.value);
        if let Some(m) = self.f.assets.images.get(&full) {
            return Some(m.clone());
        }
        if std::fs::metadata(&full).is_err() {
            let msg = format!("expected a PNG or EXR image, but {} does not exist", full.display());
            self.fail(path, msg);
            return None;
        }
        if let Err(e) = crate::input::check(&full, crate::input::Kind::Asset, "a PNG or EXR image") {
            self.fail(path, e.to_string());
            return None;
        }
        match crate::input::shared(&full, "", || HeightImage::load(&full)) {
            Ok(m) => {
                self.f.assets.images.insert(full, m.clone());
                Some(m)
            }
            Err(e) => {
                self.other(e);
                None
            }
        }
    }

    /// Each frame of a sequence is a texel of the same resolution, and no sequence itself.
    fn sequence(&mut self, frames: &[Mark<String>], resolution: [u32; 3]) {
        if frames.is_empty() {
            let path = self.scene.path.display();
            return self
                .other(Error::Invalid(format!("{path}: expected at least one texel name in a sequence")));
        }
        for f in frames {
            match self.scene.texels.get(&f.value) {
                None => self.fail(f, format!("unknown texel \"{}\" in a sequence", f.value)),
                Some(t) if matches!(t.source, TexelSource::Sequence { .. }) => {
                    self.fail(f, format!("\"{}\" is a sequence: expected a texel with a volume", f.value))
                }
                Some(t) if t.resolution != resolution => {
                    let msg = format!(
                        "expected a texel of the sequence's resolution {resolution:?}, \"{}\" has {:?}",
                        f.value, t.resolution
                    );
                    self.fail(f, msg)
                }
                Some(_) => {}
            }
        }
    }

    /// Reads each volume's grids from its file; a failure is reported at the file's path.
    fn volumes(&mut self) {
        for (name, v) in &self.scene.volumes {
            let full = self.f.assets.dir.join(&v.file.value);
            if std::fs::metadata(&full).is_err() {
                let msg = format!(
                    "volume \"{name}\": expected an OpenVDB file, but {} does not exist",
                    full.display()
                );
                self.fail(&v.file, msg);
                continue;
            }
            let request =
                crate::vdb::Request { density: v.grid.clone(), color: v.color.clone(), band: v.band };
            match crate::input::shared(&full, &format!("{request:?}"), || crate::vdb::load(&full, &request)) {
                Ok(grid) => {
                    self.f.assets.volumes.insert(name.clone(), grid);
                    self.f.assets.volume_files.push(full);
                }
                Err(e) => self.fail(&v.file, format!("volume \"{name}\": {e}")),
            }
        }
    }

    /// A volume texel names a known volume and a box with volume.
    fn texel_volume(&mut self, name: &Mark<String>, bounds: Option<&Mark<MeshBounds>>) {
        if !self.scene.volumes.contains_key(&name.value) {
            let msg = format!(
                "unknown volume \"{}\": {}",
                name.value,
                expected_names(self.scene.volumes.keys(), "volumes")
            );
            self.fail(name, msg);
        }
        if let Some(b) = bounds {
            if let Some(a) = (0..3).find(|&a| b.lo[a] >= b.hi[a]) {
                let msg = format!(
                    "expected `lo` below `hi` on every axis, found {} >= {} on {}",
                    b.lo[a],
                    b.hi[a],
                    ["x", "y", "z"][a]
                );
                self.fail(b, msg);
            }
        }
    }

    /// A volume node draws a known volume with `RayMarch` (no segments or adaptive stride: the
    /// brick table skips empty space) or `Reference`, and nothing else.
    fn volume_node(&mut self, n: &Node) {
        let Some(v) = &n.volume else { return };
        if n.surface.is_some() || n.texel.is_some() || n.hypertexture.is_some() {
            let msg =
                "a node draws a `surface` with a `texel`, a `hypertexture` or a `volume`: one of them".into();
            return self.fail(v, msg);
        }
        if !self.scene.volumes.contains_key(&v.value) {
            let msg = format!(
                "unknown volume \"{}\": {}",
                v.value,
                expected_names(self.scene.volumes.keys(), "volumes")
            );
            return self.fail(v, msg);
        }
        if let Some(m) = &n.method {
            match m.value.knobs().volumes() {
                Some(Ok(())) => {}
                Some(Err(msg)) => self.fail(m, msg),
                None => self.fail(m, format!("a volume node is drawn with {}", Method::volume_methods())),
            }
        }
    }

    /// Loads the slice stack at `path` and checks it has the texel's resolution.
    fn stack(&mut self, path: &Mark<String>, resolution: [u32; 3]) {
        let full = self.f.assets.dir.join(&path.value);
        if !full.is_dir() {
            let msg = format!(
                "expected a slice-stack folder written by `voltex bake`, but {} is none",
                full.display()
            );
            return self.fail(path, msg);
        }
        match stack::read(&full) {
            Ok(s) if s.resolution != resolution => {
                let [w, h, d] = s.resolution;
                let msg =
                    format!("expected the texel's resolution {resolution:?}: the stack holds {w}x{h}x{d}");
                self.fail(path, msg);
            }
            Ok(s) => {
                self.f.assets.stacks.insert(full, Arc::new(s));
            }
            Err(e) => self.other(e),
        }
    }

    /// Loads the image at `path` and checks it has `channel`; a failure is reported at `at`.
    fn image_channel<T>(&mut self, path: &Mark<String>, channel: u32, at: &Mark<T>) {
        if let Some(img) = self.image(path) {
            if channel as usize >= img.channels {
                let msg = format!(
                    "expected a channel in 0..{} ({} has {} channels)",
                    img.channels, path.value, img.channels
                );
                self.fail(at, msg);
            }
        }
    }

    fn node(&mut self, n: &Node, parent: glam::DMat4) {
        let world = parent * n.transform.matrix();
        self.volume_node(n);
        if n.volume.is_none() {
            self.hypertexture_node(n, &world);
        }
        if let Some(m) = &n.method {
            if let Err(msg) = m.value.knobs().check() {
                self.fail(m, format!("node \"{}\": {msg}", n.name));
            }
        }
        if let Some(m) =
            n.method.as_ref().filter(|m| m.value.knobs().draws() == Draws::Texels && n.volume.is_none())
        {
            if n.texel.is_none() {
                self.fail(m, format!("node \"{}\" has a method: expected a `texel`", n.name));
            } else if n.surface.is_none() {
                self.fail(m, format!("node \"{}\" has a method: expected a `surface`", n.name));
            }
        }
        if let Some(t) = &n.texel {
            if !self.scene.texels.contains_key(&t.value) {
                let names: Vec<String> = self.scene.texels.keys().map(|k| format!("\"{k}\"")).collect();
                let expected = if names.is_empty() {
                    "no texels are defined in `texels`".to_string()
                } else {
                    format!("expected one of {}", names.join(", "))
                };
                self.fail(t, format!("unknown texel \"{}\": {expected}", t.value));
            }
        }
        let mut mesh = None;
        if let Some(s) = &n.surface {
            match &s.value {
                Surface::Torus { major, minor, .. } if minor >= major => {
                    self.fail(s, format!("expected a torus minor radius below the major radius ({major})"));
                }
                Surface::Mesh { path } => {
                    mesh = self.mesh(path);
                    // Texels tile by uv: corners without them get planar uvs (as an OBJ without
                    // `vt`), which the user should know of.
                    if mesh.as_ref().is_some_and(|m| m.uvs_missing) {
                        let msg = format!(
                            "{} has a primitive without TEXCOORD_0: its corners take planar uvs from the \
                             mesh's x, y bounds (export uvs for a texture that follows the surface)",
                            path.value
                        );
                        self.f.warnings.push((Some(path.seq), msg));
                    }
                }
                _ => {}
            }
        }
        if let Some(scale) = &n.height.scale {
            match (&scale.value, n.surface.as_deref()) {
                (_, None) => self.fail(scale, "a height scale needs a `surface`".into()),
                (HeightScale::VertexAttribute, Some(Surface::Mesh { path })) => {
                    if mesh.as_ref().is_some_and(|m| m.attribute.is_none()) {
                        let msg = format!(
                            "{} has no vertex colours: expected `v x y z r g b` lines (OBJ) or COLOR_0 (glTF) for VertexAttribute",
                            path.value
                        );
                        self.fail(scale, msg);
                    }
                }
                (HeightScale::VertexAttribute, Some(_)) => {
                    self.fail(scale, "built-in surfaces have no vertex attribute: expected Texture(path: ..) or a Mesh surface".into());
                }
                (HeightScale::Texture { path, channel }, Some(_)) => {
                    self.image_channel(path, *channel, scale)
                }
            }
        }
        for c in &n.children {
            self.node(c, world);
        }
    }

    /// A hypertexture node draws a known hypertexture with a method that draws densities and
    /// nothing else; a step that would need more than `MAX_SAMPLES_PER_RAY` samples across the
    /// bounds is refused.
    fn hypertexture_node(&mut self, n: &Node, world: &glam::DMat4) {
        let densities = n.method.as_ref().filter(|m| m.value.knobs().draws() == Draws::Densities);
        let Some(h) = &n.hypertexture else {
            if let Some(m) = densities {
                let msg = format!(
                    "node \"{}\" is drawn with {}: expected `hypertexture: \"name\"`",
                    n.name,
                    m.value.name()
                );
                self.fail(m, msg);
            }
            return;
        };
        if n.surface.is_some() || n.texel.is_some() {
            let msg = "a node draws either a `surface` with a `texel` or a `hypertexture`, not both".into();
            self.fail(h, msg);
            return;
        }
        if let Some(m) = n.method.as_ref().filter(|_| densities.is_none()) {
            let expected = Method::for_densities().name();
            let msg =
                format!("a hypertexture node is drawn with {}(...): expected {expected}", m.value.name());
            self.fail(m, msg);
            return;
        }
        let Some(model) = self.scene.hypertextures.get(&h.value) else {
            let names: Vec<String> = self.scene.hypertextures.keys().map(|k| format!("\"{k}\"")).collect();
            let expected = if names.is_empty() {
                "no hypertextures are defined in `hypertextures`".to_string()
            } else {
                format!("expected one of {}", names.join(", "))
            };
            self.fail(h, format!("unknown hypertexture \"{}\": {expected}", h.value));
            return;
        };
        let Some((m, step)) = densities.and_then(|m| Some((m, m.value.knobs().density_step()?))) else {
            return;
        };
        // Mesh objects get their bounds from the mesh, loaded before the nodes are checked.
        let mut model = model.clone();
        match &mut model.object.value {
            super::hypertexture::SoftObject::Mesh { path, shape, .. } => {
                *shape = self.f.assets.shapes.get(&self.f.assets.dir.join(&path.value)).cloned();
            }
            super::hypertexture::SoftObject::Points { path, set, .. } => {
                *set = self.f.assets.point_sets.get(&self.f.assets.dir.join(&path.value)).cloned();
            }
            _ => {}
        }
        let diagonal = super::hypertexture::diagonal(&model.world_corners(world));
        let samples = diagonal / step;
        if samples > MAX_SAMPLES_PER_RAY {
            let msg = format!(
                "a step of {step} takes {samples:.3e} samples across the bounds of \"{}\" (diagonal {diagonal:.4}): \
                 expected a step of at least {:.3e}",
                h.value,
                diagonal / MAX_SAMPLES_PER_RAY
            );
            self.fail(m, msg);
        }
    }
}

/// Most voxels of a texel baked from a hypertexture (seven density evaluations each).
pub(crate) const MAX_HYPERTEXTURE_VOXELS: u64 = 1 << 24;

/// More samples than this along one ray means a step far finer than any scene needs.
pub(crate) const MAX_SAMPLES_PER_RAY: f64 = 1e5;

pub(super) fn check(scene: &Scene, dir: &Path, source: &str, path: &Path) -> Findings {
    let mut c = Checker {
        scene,
        f: Findings {
            fail: BTreeMap::new(),
            other: None,
            assets: Assets { dir: dir.to_path_buf(), ..Assets::default() },
            warnings: Vec::new(),
        },
    };
    let cam = &scene.camera;
    let view = cam.target - cam.eye;
    if view.length_squared() == 0.0 {
        c.fail(cam, "expected a camera `target` different from its `eye`".into());
    } else if view.normalize().cross(cam.up.normalize()).length() < 1e-6 {
        c.fail(cam, "expected a camera `up` that is not parallel to the view direction".into());
    }
    for h in scene.hypertextures.values() {
        super::hypertexture::check(h, &mut |seq, msg| {
            c.f.fail.entry(seq).or_insert(msg);
        });
    }
    c.volumes();
    for (name, t) in &scene.texels {
        match &t.source {
            TexelSource::Mesh { path, bounds, fill, .. } => c.texel_mesh(name, t, path, bounds, *fill),
            TexelSource::ImageHeight { image, channel, .. } => c.image_channel(image, *channel, image),
            TexelSource::Slices { dir } => c.stack(dir, t.resolution),
            TexelSource::Sequence { texels, .. } => c.sequence(texels, t.resolution),
            TexelSource::Hypertexture { name: h, bounds } => {
                c.texel_hypertexture(name, t, h, bounds.as_ref())
            }
            TexelSource::Volume { name: v, bounds } => c.texel_volume(v, bounds.as_ref()),
            _ => {}
        }
    }
    for h in scene.hypertextures.values() {
        if let super::hypertexture::SoftObject::Mesh { path, .. } = &h.object.value {
            c.mesh_object(path);
        }
        c.points_object(&h.object);
        for noise in h.noises.iter() {
            if let super::hypertexture::ShapeTransfer::Image { path, .. } = &noise.shape {
                c.shape_image(path);
            }
        }
    }
    for n in &scene.nodes {
        c.node(n, glam::DMat4::IDENTITY);
    }
    let (marks, other) = super::budget::check(scene, &c.f.assets, source, path);
    for (seq, msg) in marks {
        c.f.fail.entry(seq).or_insert(msg);
    }
    if let Some(e) = other {
        c.other(e);
    }
    c.f
}

/// "expected one of \"a\", \"b\"", or that none are defined in `what`.
fn expected_names<'a>(names: impl Iterator<Item = &'a String>, what: &str) -> String {
    let names: Vec<String> = names.map(|k| format!("\"{k}\"")).collect();
    if names.is_empty() {
        format!("no {what} are defined in `{what}`")
    } else {
        format!("expected one of {}", names.join(", "))
    }
}
