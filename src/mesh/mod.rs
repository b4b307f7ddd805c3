//! Base surfaces: triangle meshes whose welded vertices carry height vectors, the generators and OBJ
//! and glTF loaders that make them, and the prism checks that say whether their extrusions are usable.

pub(crate) mod bvh;
pub mod generate;
pub mod gltf;
pub(crate) mod motion;
pub mod obj;
pub mod points;
pub mod prism;
pub mod shape;
pub mod shell;

use glam::{DMat4, DVec2, DVec3};

use crate::error::Result;

/// Reads a mesh file by its extension: `.gltf` and `.glb` as glTF 2.0, anything else as OBJ.
pub fn load(path: &std::path::Path) -> Result<Mesh> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("gltf" | "glb") => gltf::load(path),
        _ => obj::load(path),
    }
}

/// A base surface ready for a method: world-space (or model-space) f64 data.
///
/// Vertices are welded: a position shared by several triangles is one vertex, even across uv seams,
/// so shared edges extrude to identical prism faces (no cracks). Uvs live per triangle corner.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BaseSurface {
    /// Welded vertex positions, object space.
    pub positions: Vec<DVec3>,
    /// Height vector per welded vertex (direction and length of the texel's `w` axis).
    pub heights: Vec<DVec3>,
    /// Counter-clockwise seen from outside (the side the height vectors point to).
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates per triangle corner, tiling applied.
    pub corner_uvs: Vec<[DVec2; 3]>,
}

impl BaseSurface {
    /// Unnormalised normal (twice the area) of triangle `t`.
    pub(crate) fn face_normal(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }

    /// The shell's mean scale: world units per uv unit along s and t (the square root of world
    /// area over uv area; not finite without uv area) and the mean height (along w).
    pub(crate) fn mean_scale(&self) -> (f64, f64) {
        let (mut world, mut uv) = (0.0, 0.0);
        for (t, uvs) in self.corner_uvs.iter().enumerate() {
            world += self.face_normal(t).length() / 2.0;
            uv += (uvs[1] - uvs[0]).perp_dot(uvs[2] - uvs[0]).abs() / 2.0;
        }
        let height = self.heights.iter().map(|h| h.length()).sum::<f64>() / self.heights.len().max(1) as f64;
        ((world / uv).sqrt(), height)
    }

    /// The six corners of triangle `t`'s prism: `p_0..p_2` then `p_0 + h_0 .. p_2 + h_2`.
    pub(crate) fn prism(&self, t: usize) -> [DVec3; 6] {
        let [a, b, c] = self.triangles[t].map(|i| i as usize);
        let p = &self.positions;
        let h = &self.heights;
        [p[a], p[b], p[c], p[a] + h[a], p[b] + h[b], p[c] + h[c]]
    }

    /// Applies an affine transform. Height vectors transform as directions with the model matrix
    /// (not the inverse transpose) so a prism maps exactly onto the transformed prism; a mirroring
    /// transform reverses the winding so triangles stay counter-clockwise seen from outside.
    pub(crate) fn transformed(&self, m: &DMat4) -> BaseSurface {
        let flip = m.determinant() < 0.0;
        BaseSurface {
            positions: self.positions.iter().map(|&p| m.transform_point3(p)).collect(),
            heights: self.heights.iter().map(|&h| m.transform_vector3(h)).collect(),
            triangles: if flip {
                self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                self.triangles.clone()
            },
            corner_uvs: if flip {
                self.corner_uvs.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                self.corner_uvs.clone()
            },
        }
    }
}

/// A surface before heights are assigned: what generators and the OBJ loader produce.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Welded vertex positions, object space.
    pub positions: Vec<DVec3>,
    /// Unit outward normal per welded vertex (zero where undefined).
    pub normals: Vec<DVec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Per corner, one tile = `[0, 1]^2`, no tiling.
    pub corner_uvs: Vec<[DVec2; 3]>,
    /// One uv per welded vertex (from its first corner) for sampling height textures.
    pub(crate) vertex_uvs: Vec<DVec2>,
    /// Optional scalar per vertex (OBJ: first colour channel of `v x y z r g b`).
    pub(crate) attribute: Option<Vec<f64>>,
    /// Optional colour per vertex (OBJ: `v x y z r g b`; white where a vertex has none).
    pub colors: Option<Vec<[f64; 3]>>,
    /// OBJ: the line of the `f` statement of each triangle, for errors (empty when generated).
    pub(crate) face_lines: Vec<u32>,
    /// glTF: some primitive had no `TEXCOORD_0` (its corners' uvs are planar).
    pub(crate) uvs_missing: bool,
}

impl Mesh {
    /// Height vectors = unit normal * `length` * `scale[i]`; uvs multiplied by `tiling`.
    pub fn to_base(&self, length: f64, scale: Option<&[f64]>, tiling: DVec2) -> BaseSurface {
        let heights =
            self.normals.iter().enumerate().map(|(i, &n)| n * length * scale.map_or(1.0, |s| s[i])).collect();
        BaseSurface {
            positions: self.positions.clone(),
            heights,
            triangles: self.triangles.clone(),
            corner_uvs: self.corner_uvs.iter().map(|c| c.map(|uv| uv * tiling)).collect(),
        }
    }

    /// Per-vertex uvs taken from the first corner that references each vertex.
    pub(crate) fn vertex_uvs_from_corners(&self) -> Vec<DVec2> {
        let mut uvs = vec![None; self.positions.len()];
        for (tri, corners) in self.triangles.iter().zip(&self.corner_uvs) {
            for k in 0..3 {
                uvs[tri[k] as usize].get_or_insert(corners[k]);
            }
        }
        uvs.into_iter().map(|u| u.unwrap_or(DVec2::ZERO)).collect()
    }
}

/// Area-weighted average of adjacent face normals, normalised (zero for unreferenced vertices).
pub fn area_weighted_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let f = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += f;
        }
    }
    n.into_iter().map(|v| v.normalize_or_zero()).collect()
}
