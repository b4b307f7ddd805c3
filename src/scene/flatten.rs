//! The node tree flattened into world-space objects with their base surfaces.

use super::types::{HeightScale, Node, Scene, Surface, TexelSource};
use super::Method;
use crate::error::{Error, FileLoc, Result};
use crate::mesh::prism::{self, PrismReport};
use crate::mesh::{generate, motion, BaseSurface, Mesh};
use glam::{DMat4, DVec2};
use std::sync::Arc;

/// A node with a surface, in world space.
#[derive(Debug, Clone)]
pub struct SceneObject {
    /// The node's name.
    pub name: String,
    /// The base surface, world space, with its height vectors (empty for hypertexture and volume
    /// nodes).
    /// Shared: re-planning the same scene from another view reuses it (see `Session::replan`).
    pub surface: Arc<BaseSurface>,
    /// What planning needs of `surface` that does not depend on the view, made by the first
    /// plan and shared by the clones a later view plans (see [`SceneObject::prepared`]).
    prepared: Arc<std::sync::OnceLock<crate::mesh::shell::PreparedShell>>,
    /// The texel it draws, by name in `Scene::texels`.
    pub texel: Option<String>,
    pub(crate) method: Option<Method>,
    pub(crate) base_color: Option<[f32; 3]>,
    /// Prism check of `surface` (no errors, else `objects()` fails); warnings for the user.
    pub report: PrismReport,
    /// A hypertexture node (its `surface` is empty).
    pub(crate) hypertexture: Option<HyperNode>,
    /// A volume node (its `surface` is empty).
    pub volume: Option<VolumeNode>,
}

/// A node drawing a volume: its name in `Scene::volumes`, its grid as read, and the node's frame.
#[derive(Debug, Clone)]
pub struct VolumeNode {
    pub(crate) name: String,
    /// The grid's voxels as read from the file.
    pub grid: Arc<crate::vdb::SparseVolume>,
    /// The node's frame to world (the grid's own index-to-world transform comes first).
    pub to_world: DMat4,
}

impl VolumeNode {
    /// World-space corners of the box outside which the density is 0.
    pub(crate) fn corners(&self) -> [glam::DVec3; 8] {
        self.grid.world_corners(&self.to_world)
    }
}

impl SceneObject {
    /// What planning needs of the surface that does not depend on the view: made on the first
    /// call, then shared by this object's clones (each view's plan clones the scene's objects).
    pub(crate) fn prepared(&self) -> &crate::mesh::shell::PreparedShell {
        self.prepared.get_or_init(|| crate::mesh::shell::PreparedShell::new(&self.surface))
    }
}

/// A node drawing a hypertexture: its name in `Scene::hypertextures` and the node's frame.
#[derive(Debug, Clone)]
pub struct HyperNode {
    pub(crate) name: String,
    /// The node's frame (object space of the hypertexture) to world.
    pub(crate) to_world: DMat4,
}

impl Scene {
    /// Flattens the node tree (child transform = parent * child) into objects, one per node with a
    /// surface, in document order (depth first). Fails on the first object whose prisms are invalid.
    pub fn objects(&self) -> Result<Vec<SceneObject>> {
        self.objects_at(self.time)
    }

    /// [`Scene::objects`] at time `time` (seconds): nodes with a `motion` are animated.
    pub fn objects_at(&self, time: f64) -> Result<Vec<SceneObject>> {
        let mut out = Vec::new();
        for n in &self.nodes {
            self.flatten(n, DMat4::IDENTITY, time, &mut out)?;
        }
        Ok(out)
    }

    fn flatten(&self, n: &Node, parent: DMat4, time: f64, out: &mut Vec<SceneObject>) -> Result<()> {
        let world = parent * n.transform.matrix();
        if let Some(surface) = &n.surface {
            let surface = self.base_surface(n, surface, &world, time)?;
            let report = prism::check(&surface);
            if !report.errors.is_empty() {
                let (line, col) = node_position(&self.source, &n.name);
                return Err(Error::at(
                    FileLoc::new(&self.path, line, col),
                    format!("object \"{}\": invalid prisms: {}", n.name, report.errors.join("; ")),
                ));
            }
            out.push(SceneObject {
                name: n.name.clone(),
                surface: Arc::new(surface),
                prepared: Default::default(),
                texel: n.texel.as_ref().map(|t| self.texel_at(&t.value, time)),
                method: n.method.as_ref().map(|m| m.value.clone()),
                base_color: n.base_color,
                report,
                hypertexture: None,
                volume: None,
            });
        } else if let Some(h) = &n.hypertexture {
            // Without a method, a hypertexture node is ray-marched with the defaults.
            let method = n.method.as_ref().map_or_else(Method::for_densities, |m| m.value.clone());
            out.push(SceneObject {
                name: n.name.clone(),
                surface: Default::default(),
                prepared: Default::default(),
                texel: None,
                method: Some(method),
                base_color: None,
                report: PrismReport::default(),
                hypertexture: Some(HyperNode { name: h.value.clone(), to_world: world }),
                volume: None,
            });
        } else if let Some(v) = &n.volume {
            // Without a method, a volume node is ray-marched with the defaults.
            let method = n.method.as_ref().map_or_else(Method::for_densities, |m| m.value.clone());
            let grid = self.assets.volumes.get(&v.value).cloned().ok_or_else(|| {
                Error::Invalid(format!("object \"{}\": volume \"{}\" was not loaded", n.name, v.value))
            })?;
            out.push(SceneObject {
                name: n.name.clone(),
                surface: Default::default(),
                prepared: Default::default(),
                texel: None,
                method: Some(method),
                base_color: None,
                report: PrismReport::default(),
                hypertexture: None,
                volume: Some(VolumeNode { name: v.value.clone(), grid, to_world: world }),
            });
        }
        for c in &n.children {
            self.flatten(c, world, time, out)?;
        }
        Ok(())
    }

    /// The texel drawn at `time`: a sequence's current frame, else `name` itself.
    fn texel_at(&self, name: &str, time: f64) -> String {
        match self.texels.get(name).map(|t| &t.source) {
            Some(TexelSource::Sequence { texels, fps }) if !texels.is_empty() => {
                let frame = ((time * fps).floor() as i64).rem_euclid(texels.len() as i64);
                texels[frame as usize].value.clone()
            }
            _ => name.to_string(),
        }
    }

    fn base_surface(&self, n: &Node, surface: &Surface, world: &DMat4, time: f64) -> Result<BaseSurface> {
        let assets = &self.assets;
        let missing =
            |what: &str, p: &str| Error::Invalid(format!("object \"{}\": {what} {p} was not loaded", n.name));
        let mesh: Arc<Mesh> = match surface {
            Surface::Plane { size, cells, jitter, seed } => {
                Arc::new(generate::plane(*size, *cells, *jitter, *seed))
            }
            Surface::Sphere { radius, segments } => Arc::new(generate::sphere(*radius, *segments)),
            Surface::Torus { major, minor, segments, distortion, seed } => {
                Arc::new(generate::torus(*major, *minor, *segments, *distortion, *seed))
            }
            Surface::Mesh { path } => assets
                .meshes
                .get(&assets.dir.join(&path.value))
                .cloned()
                .ok_or_else(|| missing("OBJ", &path.value))?,
        };
        let scale: Option<Vec<f64>> = match n.height.scale.as_deref() {
            None => None,
            Some(HeightScale::VertexAttribute) => Some(
                mesh.attribute
                    .as_ref()
                    .ok_or_else(|| Error::Invalid(format!("object \"{}\": no vertex attribute", n.name)))?
                    .iter()
                    .map(|a| a.clamp(0.0, 1.0))
                    .collect(),
            ),
            Some(HeightScale::Texture { path, channel }) => {
                let img = assets
                    .images
                    .get(&assets.dir.join(&path.value))
                    .ok_or_else(|| missing("height texture", &path.value))?;
                Some(
                    mesh.vertex_uvs
                        .iter()
                        .map(|&uv| img.sample(uv, *channel as usize).clamp(0.0, 1.0))
                        .collect(),
                )
            }
        };
        let mut base = mesh.to_base(n.height.length, scale.as_deref(), DVec2::from(n.uv_tiling));
        let m = &n.motion;
        let wave = m.wave.map(|w| motion::Wave {
            amplitude: w.amplitude,
            wavelength: w.wavelength,
            speed: w.speed,
            direction: w.direction.normalize(),
        });
        let wind = m.wind.map(|w| motion::Wind {
            strength: w.strength,
            frequency: w.frequency,
            wavelength: w.wavelength,
            direction: w.direction.normalize(),
        });
        motion::animate(&mut base, wave.as_ref(), wind.as_ref(), time);
        Ok(base.transformed(world))
    }
}

/// Position of the node named `name` (its `name: "..."` field), or the file start.
fn node_position(source: &str, name: &str) -> (usize, usize) {
    let mut from = 0;
    while let Some((line, col)) = crate::error::locate_literal(source, name, from) {
        let offset = crate::error::offset_of(source, line, col);
        let before = source[..offset].trim_end();
        if before.strip_suffix(':').is_some_and(|b| b.trim_end().ends_with("name")) {
            return (line, col);
        }
        from = offset + 1;
    }
    (1, 1)
}
