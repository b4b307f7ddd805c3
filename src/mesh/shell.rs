//! Shells on the GPU side: camera-relative prism corners and bounding spheres, and the opaque
//! base-surface triangles. Positions are made camera-relative in f64 before they become f32.

use glam::DVec3;

use crate::mesh::{prism, BaseSurface};
use crate::types::{BaseVertex, Prism, ShellVertex, VertexFrame};

/// The prisms of one object, as the kernels read them: shell vertices (camera-relative) and
/// prisms.
pub struct Shell {
    /// Bottom and top of each welded vertex, camera-relative.
    pub vertices: Vec<ShellVertex>,
    /// One prism per base triangle.
    pub prisms: Vec<Prism>,
}

fn rel(p: DVec3, eye: DVec3) -> [f32; 4] {
    let r = p - eye;
    [r.x as f32, r.y as f32, r.z as f32, 1.0]
}

/// Each prism's bounding sphere in world space (centre, radius): what a shell needs of its
/// prisms that does not depend on the view, made once per surface (see `SceneObject::spheres`).
pub(crate) fn prism_spheres(surface: &BaseSurface) -> Vec<(DVec3, f64)> {
    (0..surface.triangles.len()).map(|t| prism::bounding_sphere(surface.prism(t))).collect()
}

impl Shell {
    /// The shell of `surface` with positions made relative to the camera at `eye` (in f64, then f32).
    pub fn new(surface: &BaseSurface, eye: DVec3) -> Self {
        Self::with_spheres(surface, &prism_spheres(surface), eye)
    }

    /// [`Shell::new`] with the prisms' world-space bounding spheres given ([`prism_spheres`]):
    /// a new view moves them to the camera, O(prisms) with no square root.
    pub(crate) fn with_spheres(surface: &BaseSurface, spheres: &[(DVec3, f64)], eye: DVec3) -> Self {
        let vertices = surface
            .positions
            .iter()
            .zip(&surface.heights)
            .map(|(&p, &h)| ShellVertex { bottom: rel(p, eye), top: rel(p + h, eye) })
            .collect();
        let prisms = surface
            .triangles
            .iter()
            .zip(&surface.corner_uvs)
            .zip(spheres)
            .map(|((ids, uv), &(centre, radius))| {
                let centre = centre - eye;
                // Grown by a relative epsilon so that f32 rounding never rejects a touching plane.
                let radius = radius * (1.0 + 1e-5) + 1e-6;
                Prism {
                    vertices: [ids[0], ids[1], ids[2], 0],
                    uv01: [uv[0].x as f32, uv[0].y as f32, uv[1].x as f32, uv[1].y as f32],
                    uv2: [uv[2].x as f32, uv[2].y as f32, 0.0, 0.0],
                    sphere: [centre.x as f32, centre.y as f32, centre.z as f32, radius as f32],
                }
            })
            .collect();
        Self { vertices, prisms }
    }

    /// Range of `dot(n, x)` over all corners.
    pub(crate) fn depth_range(&self, n: [f32; 3]) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in &self.vertices {
            for p in [v.bottom, v.top] {
                let d = n[0] as f64 * p[0] as f64 + n[1] as f64 * p[1] as f64 + n[2] as f64 * p[2] as f64;
                lo = lo.min(d);
                hi = hi.max(d);
            }
        }
        (lo, hi)
    }
}

/// Triangle corners of the base surface with face normals, for the opaque base pass.
pub(crate) fn base_vertices(surface: &BaseSurface, eye: DVec3) -> Vec<BaseVertex> {
    let mut out = Vec::with_capacity(surface.triangles.len() * 3);
    for t in &surface.triangles {
        let p = t.map(|i| surface.positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for (k, &i) in t.iter().enumerate() {
            let h = surface.heights[i as usize].normalize_or_zero();
            let normal = if h != DVec3::ZERO { h } else { n };
            out.push(BaseVertex {
                position: rel(p[k], eye),
                normal: [normal.x as f32, normal.y as f32, normal.z as f32, 0.0],
            });
        }
    }
    out
}

/// Per welded vertex, `dP/ds` and `dP/dt` of its triangles (from their uv mapping), averaged with
/// triangle area as the weight, for per-pixel lighting that is continuous across prism edges.
/// An average, not a sum: the lengths matter (the Jacobian's cofactors mix `ds x dt` with
/// `dt x dw`, and the Reference's default step is taken from them), and a sum would scale them
/// with the area around the vertex.
pub(crate) fn vertex_frames(surface: &BaseSurface) -> Vec<VertexFrame> {
    let n = surface.positions.len();
    let mut sum = vec![(DVec3::ZERO, DVec3::ZERO, 0.0); n];
    for (t, uv) in surface.triangles.iter().zip(&surface.corner_uvs) {
        let p = t.map(|i| surface.positions[i as usize]);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 {
            continue; // no uv area: no texel directions to take from this triangle
        }
        let ds = (e1 * d2.y - e2 * d1.y) / det;
        let dt = (e2 * d1.x - e1 * d2.x) / det;
        let area = 0.5 * e1.cross(e2).length();
        for &i in t {
            let s = &mut sum[i as usize];
            s.0 += ds * area;
            s.1 += dt * area;
            s.2 += area;
        }
    }
    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    sum.into_iter()
        .map(|(ds, dt, area)| {
            // Zero-area triangles around a vertex alone: no direction to average.
            let k = if area > 0.0 { 1.0 / area } else { 0.0 };
            VertexFrame { ds: f(ds * k), dt: f(dt * k) }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// The frames are `dP/ds` and `dP/dt` themselves, whatever the triangle sizes: on a plane of
    /// size L with one texture tile, both have length L at every vertex (a fine and a coarse grid,
    /// at unit scale and at 1e-4).
    #[test]
    fn frames_are_the_uv_derivatives_at_any_scale_and_tessellation() {
        for scale in [1.0, 1e-4] {
            for cells in [1, 16] {
                let mesh = crate::mesh::generate::plane([2.0 * scale, 2.0 * scale], [cells, cells], 0.0, 0);
                let frames = vertex_frames(&mesh.to_base(0.5 * scale, None, DVec2::ONE));
                for f in &frames {
                    let v = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
                    let (ds, dt) = (v(f.ds), v(f.dt));
                    assert!(
                        (ds.length() / (2.0 * scale) - 1.0).abs() < 1e-6,
                        "scale {scale}, cells {cells}: |ds| = {}",
                        ds.length()
                    );
                    assert!(
                        (dt.length() / (2.0 * scale) - 1.0).abs() < 1e-6,
                        "scale {scale}, cells {cells}: |dt| = {}",
                        dt.length()
                    );
                }
            }
        }
    }
}
