//! Closed triangle meshes as solid shapes (hypertexture mesh objects, mesh texels): welded and
//! checked when the scene is loaded, split into closed parts, and the grid of samples their
//! closest-surface bake covers ([`GridSpec`]). No GPU: the bakes live with their users.
//!
//! A mesh made of several closed parts (edge-connected components) is their union, so parts may
//! overlap (a teapot's spout and handle through its body).

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::Path;

use glam::DVec3;

use crate::mesh::Mesh;
use crate::types::MeshGridParams;

/// Most samples per axis of a mesh grid (16 bytes each: 32 MiB at 128).
pub(crate) const MAX_RESOLUTION: u32 = 128;
/// Most voxels of a mesh texel (its grid: 256 MiB, e.g. 256^3).
pub(crate) const MAX_TEXEL_SAMPLES: u64 = 1 << 24;
/// Most closed parts of one mesh (the bake walks each part's BVH per sample).
pub(crate) const MAX_PARTS: usize = 16;

/// A closed triangle mesh in its node's frame, vertices welded by position.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshShape {
    pub(crate) positions: Vec<DVec3>,
    /// Triangles as indices into the welded positions, grouped by part.
    pub triangles: Vec<[u32; 3]>,
    /// Lowest corner of the mesh's bounding box.
    pub lo: DVec3,
    /// Highest corner of the mesh's bounding box.
    pub hi: DVec3,
    /// Closed parts: (first triangle, triangle count); triangles are grouped by part.
    pub parts: Vec<(u32, u32)>,
    /// Per triangle, its corners' colours (OBJ vertex colours), when the mesh has any.
    pub(crate) colors: Option<Vec<[[f32; 3]; 3]>>,
    /// Of positions and triangles: the bake cache's key.
    pub(crate) hash: u64,
}

/// Where a mesh grid's samples lie: `n[a]` along axis `a` at the vertices of the box `lo..hi`.
/// `parity: false` skips the inside test (open patterns drawn as shells): every distance is
/// then negative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    /// Lowest corner of the sampled box.
    pub lo: DVec3,
    /// Highest corner of the sampled box.
    pub hi: DVec3,
    /// Samples along each axis.
    pub n: [u32; 3],
    /// Test inside by ray parity (a closed mesh); `false`: distances only (a shell).
    pub parity: bool,
}

impl GridSpec {
    /// The sample `(i, j, k)` in object space.
    pub fn point(&self, i: u32, j: u32, k: u32) -> DVec3 {
        let [x, y, z] = self.n.map(|n| (n - 1) as f64);
        let f = DVec3::new(i as f64 / x, j as f64 / y, k as f64 / z);
        self.lo + (self.hi - self.lo) * f
    }

    /// Samples in all.
    pub(crate) fn samples(&self) -> u64 {
        self.n.iter().map(|&n| n as u64).product()
    }

    pub(crate) fn params(&self, triangles: u32, nodes: u32, parts: u32) -> MeshGridParams {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        let [x, y, z] = self.n;
        MeshGridParams {
            lo: f(self.lo),
            hi: f(self.hi),
            counts: [x, triangles, nodes, parts],
            size: [x, y, z, self.parity as u32],
        }
    }
}

impl MeshShape {
    /// Welds `mesh` by position and checks that it is closed (every edge shared by an even
    /// number of triangles, so ray parity says inside or outside) and encloses a volume. Errors
    /// name `path` and the line of the offending face.
    pub fn new(mesh: &Mesh, path: &Path) -> std::result::Result<Self, String> {
        let (positions, triangles, lines, sources) = weld(mesh, path)?;
        let at = |t: usize| match lines.get(t) {
            Some(&l) if l > 0 => format!("{}:{l}:1", path.display()),
            _ => path.display().to_string(),
        };
        let mut edges: HashMap<(u32, u32), (u32, usize)> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_insert((0, t)).0 += 1;
            }
        }
        let mut open: Vec<_> = edges.iter().filter(|(_, (count, _))| count % 2 == 1).collect();
        open.sort_by_key(|(_, (_, t))| *t);
        if let Some(((a, b), (count, t))) = open.first() {
            let (pa, pb) = (positions[*a as usize], positions[*b as usize]);
            return Err(format!(
                "{}: open mesh: the edge from ({}, {}, {}) to ({}, {}, {}) of this face belongs to {count} \
                 triangle(s) ({} open edges in all): expected a closed mesh, every edge shared by two triangles",
                at(*t),
                pa.x,
                pa.y,
                pa.z,
                pb.x,
                pb.y,
                pb.z,
                open.len()
            ));
        }
        let lo = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        // Parts: triangles joined by shared vertices (union-find), grouped in order of first face.
        let mut root: Vec<u32> = (0..positions.len() as u32).collect();
        fn find(root: &mut [u32], mut i: u32) -> u32 {
            while root[i as usize] != i {
                root[i as usize] = root[root[i as usize] as usize];
                i = root[i as usize];
            }
            i
        }
        for t in &triangles {
            for e in 1..3 {
                let (a, b) = (find(&mut root, t[0]), find(&mut root, t[e]));
                root[a.max(b) as usize] = a.min(b);
            }
        }
        let mut part_of: HashMap<u32, usize> = HashMap::new();
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (t, tri) in triangles.iter().enumerate() {
            let r = find(&mut root, tri[0]);
            let g = *part_of.entry(r).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            groups[g].push(t);
        }
        if groups.len() > MAX_PARTS {
            return Err(format!(
                "{}: {} separate closed parts: expected at most {MAX_PARTS}",
                path.display(),
                groups.len()
            ));
        }
        let extent = (hi - lo).max_element();
        let mut parts = Vec::new();
        let mut grouped = Vec::with_capacity(triangles.len());
        let mut order = Vec::with_capacity(triangles.len());
        for g in &groups {
            let volume: f64 = g
                .iter()
                .map(|&t| {
                    let [a, b, c] = triangles[t].map(|i| positions[i as usize] - lo);
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            if volume.abs() <= 1e-9 * extent.powi(3) {
                return Err(format!(
                    "{}: degenerate mesh: the part of this face encloses no volume (bounds {:?} to {:?})",
                    at(g[0]),
                    lo.to_array(),
                    hi.to_array()
                ));
            }
            parts.push((grouped.len() as u32, g.len() as u32));
            grouped.extend(g.iter().map(|&t| triangles[t]));
            order.extend(g.iter().map(|&t| sources[t]));
        }
        let triangles = grouped;
        let colors = corner_colors(mesh, &order);
        let hash = digest(&positions, &triangles, &colors);
        Ok(MeshShape { positions, triangles, lo, hi, parts, colors, hash })
    }

    /// The welded mesh as one part, closed or not: only its unsigned distance means anything
    /// (a mesh texel's shell). Errors only when no triangle is left.
    pub fn open(mesh: &Mesh, path: &Path) -> std::result::Result<Self, String> {
        let (positions, triangles, _, sources) = weld(mesh, path)?;
        let lo = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let hi = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        let parts = vec![(0, triangles.len() as u32)];
        let colors = corner_colors(mesh, &sources);
        let hash = digest(&positions, &triangles, &colors);
        Ok(MeshShape { positions, triangles, lo, hi, parts, colors, hash })
    }

    /// The grid of `n` samples per axis over the mesh's bounds enlarged by the largest shift (the
    /// field is needed wherever a noise may shift a point from) and two cells.
    pub fn grid(&self, n: u32, max_shift: f64) -> GridSpec {
        let extent = (self.hi - self.lo).max_element() + 2.0 * max_shift;
        let pad = max_shift + 2.0 * extent / (n - 1) as f64;
        GridSpec { lo: self.lo - DVec3::splat(pad), hi: self.hi + DVec3::splat(pad), n: [n; 3], parity: true }
    }

    /// The positions of triangle `t`'s corners.
    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }
}

/// Positions welded (equal coordinates become one vertex) and triangles that still bound
/// something, with the OBJ line of each and its index in the mesh.
type Welded = (Vec<DVec3>, Vec<[u32; 3]>, Vec<u32>, Vec<usize>);

/// Per triangle of `mesh` in `order`, its corners' vertex colours (before welding, so that a
/// seam keeps both sides' colours).
fn corner_colors(mesh: &Mesh, order: &[usize]) -> Option<Vec<[[f32; 3]; 3]>> {
    let colors = mesh.colors.as_ref()?;
    let corner = |v: u32| colors[v as usize].map(|c| c as f32);
    Some(order.iter().map(|&t| mesh.triangles[t].map(corner)).collect())
}

fn weld(mesh: &Mesh, path: &Path) -> std::result::Result<Welded, String> {
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let weld: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            // `+ 0.0` makes -0 and 0 one coordinate (OBJ writers print both).
            *ids.entry(p.to_array().map(|c| (c + 0.0).to_bits())).or_insert_with(|| {
                positions.push(*p);
                positions.len() as u32 - 1
            })
        })
        .collect();
    let mut triangles = Vec::new();
    let mut lines = Vec::new();
    let mut sources = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| weld[i as usize]);
        // A triangle with a repeated vertex bounds nothing.
        if a != b && b != c && a != c {
            triangles.push([a, b, c]);
            lines.push(mesh.face_lines.get(t).copied().unwrap_or(0));
            sources.push(t);
        }
    }
    if triangles.is_empty() {
        return Err(format!("{}: degenerate mesh: every triangle repeats a vertex", path.display()));
    }
    Ok((positions, triangles, lines, sources))
}

fn digest(positions: &[DVec3], triangles: &[[u32; 3]], colors: &Option<Vec<[[f32; 3]; 3]>>) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in positions {
        p.to_array().map(f64::to_bits).hash(&mut h);
    }
    triangles.hash(&mut h);
    for c in colors.iter().flatten().flatten().flatten() {
        c.to_bits().hash(&mut h);
    }
    h.finish()
}
