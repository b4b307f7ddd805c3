//! Shells on the GPU side: camera-relative prism corners and bounding spheres, and the opaque
//! base-surface triangles. Positions are made camera-relative in f64 before they become f32.

use std::sync::Arc;

use glam::DVec3;

use crate::mesh::{prism, BaseSurface};
use crate::types::{BaseVertex, Prism, ShellVertex, VertexFrame};

/// The prisms of one object, as the kernels read them: shell vertices and prisms' bounding
/// spheres (camera-relative, made per view) and the prisms (shared by every view).
pub struct Shell {
    /// Bottom and top of each welded vertex, camera-relative.
    pub vertices: Vec<ShellVertex>,
    /// One prism per base triangle.
    pub prisms: Arc<[Prism]>,
    /// Each prism's welded vertex ids alone, packed: a camera move's plane ranges read these,
    /// not the whole prisms.
    pub(crate) triangles: Arc<[[u32; 3]]>,
    /// Per prism, the camera-relative centre (xyz) and radius (w) of a sphere holding its six
    /// corners, for the trivial reject.
    pub spheres: Vec<[f32; 4]>,
    /// Per run of [`BOX_VERTICES`] vertices, the least and greatest coordinates of their bottoms
    /// and tops: bounds of the f32 values themselves (each rounding step is monotonic), so that
    /// a view's depth range scans only the runs that may hold its ends.
    boxes: Vec<[[f32; 3]; 2]>,
}

fn rel(p: DVec3, eye: DVec3) -> [f32; 4] {
    let r = p - eye;
    [r.x as f32, r.y as f32, r.z as f32, 1.0]
}

/// Each prism's bounding sphere in world space (centre, radius).
pub(crate) fn prism_spheres(surface: &BaseSurface) -> Vec<(DVec3, f64)> {
    (0..surface.triangles.len()).map(|t| prism::bounding_sphere(surface.prism(t))).collect()
}

/// Shell vertices per corner box of [`PreparedShell`] and [`Shell`]: a view scans the corners of
/// the few boxes that may hold the farthest (or nearest) one.
const BOX_VERTICES: usize = 256;

/// What planning a shell needs of its surface that does not depend on the view, made once per
/// surface and shared by every view of it (see `SceneObject::prepared`), so that a camera move
/// costs O(prisms) of plain copying and no square root or cross product.
#[derive(Debug, Default)]
pub(crate) struct PreparedShell {
    /// Each prism's world-space bounding sphere ([`prism_spheres`]).
    pub(crate) spheres: Vec<(DVec3, f64)>,
    /// The prisms ([`prisms`]) and their vertex ids, which a view shares.
    prisms: Arc<[Prism]>,
    triangles: Arc<[[u32; 3]]>,
    /// Boxes (min, max) around the bottoms and tops of each run of [`BOX_VERTICES`] vertices.
    boxes: Vec<(DVec3, DVec3)>,
    /// Per-vertex frames for per-pixel lighting ([`vertex_frames`]), made when first asked.
    frames: std::sync::OnceLock<Vec<VertexFrame>>,
}

impl PreparedShell {
    pub(crate) fn new(surface: &BaseSurface) -> Self {
        let corners = surface.positions.iter().zip(&surface.heights).map(|(&p, &h)| (p, p + h));
        let boxes = corners
            .collect::<Vec<_>>()
            .chunks(BOX_VERTICES)
            .map(|run| {
                run.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &(b, t)| {
                    (lo.min(b).min(t), hi.max(b).max(t))
                })
            })
            .collect();
        Self {
            spheres: prism_spheres(surface),
            prisms: prisms(surface),
            triangles: surface.triangles.as_slice().into(),
            boxes,
            frames: Default::default(),
        }
    }

    /// The per-vertex frames of `surface` (the one this was prepared from).
    pub(crate) fn frames(&self, surface: &BaseSurface) -> &[VertexFrame] {
        self.frames.get_or_init(|| vertex_frames(surface))
    }

    /// The largest `(c - eye) . forward` over the bottom and top corners `c` of `surface`'s
    /// vertices (the one this was prepared from), `None` without vertices: exactly the value a scan
    /// of every corner gives, found by scanning only the boxes whose bound may exceed it.
    pub(crate) fn farthest(&self, surface: &BaseSurface, eye: DVec3, forward: DVec3) -> Option<f64> {
        // A box's bound, widened far beyond its rounding error so that no box holding the
        // farthest corner is skipped.
        let bound = |(lo, hi): &(DVec3, DVec3)| {
            let (centre, half) = (0.5 * (*lo + *hi) - eye, 0.5 * (*hi - *lo));
            let b = centre.dot(forward) + half.dot(forward.abs());
            b + 1e-9 * (centre.abs().element_sum() + half.element_sum())
        };
        let mut order: Vec<(f64, usize)> = self.boxes.iter().map(bound).zip(0..).collect();
        order.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
        let mut far: Option<f64> = None;
        for (b, k) in order {
            if far.is_some_and(|f| b < f) {
                break;
            }
            let run = k * BOX_VERTICES..((k + 1) * BOX_VERTICES).min(surface.positions.len());
            for (&p, &h) in surface.positions[run.clone()].iter().zip(&surface.heights[run]) {
                let d = (p - eye).dot(forward).max((p + h - eye).dot(forward));
                far = Some(far.map_or(d, |f| f.max(d)));
            }
        }
        far
    }
}

/// The prisms of `surface`: vertex ids and corner uvs.
fn prisms(surface: &BaseSurface) -> Arc<[Prism]> {
    let corners = surface.triangles.iter().zip(&surface.corner_uvs);
    corners
        .map(|(ids, uv)| Prism {
            vertices: [ids[0], ids[1], ids[2], 0],
            uv01: [uv[0].x as f32, uv[0].y as f32, uv[1].x as f32, uv[1].y as f32],
            uv2: [uv[2].x as f32, uv[2].y as f32, 0.0, 0.0],
        })
        .collect()
}

impl Shell {
    /// The shell of `surface` with positions made relative to the camera at `eye` (in f64, then f32).
    pub fn new(surface: &BaseSurface, eye: DVec3) -> Self {
        Self::prepared(surface, &PreparedShell::new(surface), eye)
    }

    /// A shell of the given parts (tests, and prisms in another order): the packed ids and the
    /// boxes made from them.
    pub(crate) fn from_parts(vertices: Vec<ShellVertex>, prisms: Vec<Prism>, spheres: Vec<[f32; 4]>) -> Self {
        let triangles = prisms.iter().map(|p| [p.vertices[0], p.vertices[1], p.vertices[2]]).collect();
        let boxes = vertices
            .chunks(BOX_VERTICES)
            .map(|run| {
                let mut b = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
                for c in run.iter().flat_map(|v| [v.bottom, v.top]) {
                    for k in 0..3 {
                        (b[0][k], b[1][k]) = (b[0][k].min(c[k]), b[1][k].max(c[k]));
                    }
                }
                b
            })
            .collect();
        Self { vertices, prisms: prisms.into(), triangles, spheres, boxes }
    }

    /// [`Shell::new`] from what `prepared` (made from `surface`) holds: a new view shares its
    /// prisms and moves its spheres and boxes to the camera, O(vertices + prisms) of copying
    /// with no square root.
    pub(crate) fn prepared(surface: &BaseSurface, prepared: &PreparedShell, eye: DVec3) -> Self {
        let vertices = (surface.positions.iter().zip(&surface.heights))
            .map(|(&p, &h)| ShellVertex { bottom: rel(p, eye), top: rel(p + h, eye) })
            .collect();
        let spheres = (prepared.spheres.iter())
            .map(|&(centre, radius)| {
                let centre = centre - eye;
                // Grown by a relative epsilon so that f32 rounding never rejects a touching plane.
                let radius = radius * (1.0 + 1e-5) + 1e-6;
                [centre.x as f32, centre.y as f32, centre.z as f32, radius as f32]
            })
            .collect();
        let xyz = |p: DVec3| {
            let r = rel(p, eye);
            [r[0], r[1], r[2]]
        };
        Self {
            vertices,
            prisms: prepared.prisms.clone(),
            triangles: prepared.triangles.clone(),
            spheres,
            boxes: prepared.boxes.iter().map(|&(lo, hi)| [xyz(lo), xyz(hi)]).collect(),
        }
    }

    /// Whether every corner coordinate lies within `±limit`, an f32 value (exact: through the
    /// boxes, and every corner only when a box reaches beyond it).
    pub(crate) fn within(&self, limit: f32) -> bool {
        let inside = |c: &[f32]| c.iter().all(|x| x.abs() <= limit);
        self.boxes.iter().all(|b| inside(&b[0]) && inside(&b[1]))
            || self.vertices.iter().all(|v| inside(&v.bottom[..3]) && inside(&v.top[..3]))
    }

    /// Range of `dot(n, x)` over all corners, exactly as a scan of every corner finds it (in
    /// f64), scanning only the boxes that may hold an end.
    pub(crate) fn depth_range(&self, n: [f32; 3]) -> (f64, f64) {
        let depth =
            |p: &[f32]| n[0] as f64 * p[0] as f64 + n[1] as f64 * p[1] as f64 + n[2] as f64 * p[2] as f64;
        // A box's least and greatest depth: its corner on each side of the normal. f32 products
        // are exact in f64 and each sum rounds monotonically, so no corner in the box computes
        // beyond these.
        let ends = |b: &[[f32; 3]; 2]| {
            let pick = |far: bool| -> [f32; 3] {
                std::array::from_fn(|k| if (n[k] >= 0.0) == far { b[1][k] } else { b[0][k] })
            };
            (depth(&pick(false)), depth(&pick(true)))
        };
        let bounds: Vec<(f64, f64)> = self.boxes.iter().map(ends).collect();
        let scan = |far: bool| {
            let mut order: Vec<usize> = (0..bounds.len()).collect();
            let key = |k: usize| if far { bounds[k].1 } else { -bounds[k].0 };
            order.sort_unstable_by(|&a, &b| key(b).total_cmp(&key(a)));
            let mut best = f64::NEG_INFINITY;
            for k in order {
                if key(k) < best {
                    break;
                }
                let run = k * BOX_VERTICES..((k + 1) * BOX_VERTICES).min(self.vertices.len());
                for v in &self.vertices[run] {
                    let (b, t) = (depth(&v.bottom), depth(&v.top));
                    best = best.max(if far { b.max(t) } else { -b.min(t) });
                }
            }
            best
        };
        (-scan(false), scan(true))
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
pub(crate) mod tests {
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

    /// A jittered plane with varied height vectors, bent into a bowl.
    pub(crate) fn bumpy(cells: u32) -> BaseSurface {
        let mut s =
            crate::mesh::generate::plane([3.0, 2.0], [cells, cells], 0.3, 7).to_base(0.4, None, DVec2::ONE);
        for (i, (p, h)) in s.positions.iter_mut().zip(&mut s.heights).enumerate() {
            p.z = 0.3 * (p.x * p.x - p.y) + 0.01 * (i % 7) as f64;
            *h *= 0.5 + 0.1 * (i % 11) as f64;
            h.x += 0.05 * ((i % 5) as f64 - 2.0);
        }
        s
    }

    /// The depth range found through the boxes is a scan of every corner's, bit for bit, from
    /// eyes all around and inside the shell and along every axis (zero normal components), for
    /// prepared shells and shells made of parts; and the range check through the boxes agrees
    /// with one of every corner.
    #[test]
    fn depth_ranges_through_the_boxes_are_exactly_a_full_scans() {
        let surface = bumpy(40);
        let prepared = PreparedShell::new(&surface);
        let scan = |shell: &Shell, n: [f32; 3]| {
            let depth = |p: [f32; 4]| {
                n[0] as f64 * p[0] as f64 + n[1] as f64 * p[1] as f64 + n[2] as f64 * p[2] as f64
            };
            shell
                .vertices
                .iter()
                .flat_map(|v| [depth(v.bottom), depth(v.top)])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)))
        };
        let mut views = 0;
        for eye in
            [DVec3::new(0.0, -4.0, 3.0), DVec3::new(5.0, 1.0, -0.5), DVec3::new(1.4, 0.9, 0.2), DVec3::ZERO]
        {
            let shell = Shell::prepared(&surface, &prepared, eye);
            let parts =
                Shell::from_parts(shell.vertices.clone(), shell.prisms.to_vec(), shell.spheres.clone());
            for n in [
                [0.3f32, -0.5, 0.81],
                [0.0, 0.0, 1.0],
                [-1.0, 0.0, 0.0],
                [0.0, -0.6, -0.8],
                [-0.2, 0.9, -0.39],
            ] {
                let expect = scan(&shell, n);
                for s in [&shell, &parts] {
                    let found = s.depth_range(n);
                    assert_eq!(
                        (found.0.to_bits(), found.1.to_bits()),
                        (expect.0.to_bits(), expect.1.to_bits()),
                        "eye {eye}, n {n:?}"
                    );
                }
                views += 1;
            }
            let largest = shell
                .vertices
                .iter()
                .flat_map(|v| [v.bottom, v.top])
                .flat_map(|c| c[..3].to_vec())
                .fold(0f32, |m, x| m.max(x.abs()));
            for limit in [largest, largest * 0.999, largest * 1.001] {
                assert_eq!(shell.within(limit), largest <= limit);
            }
        }
        assert_eq!(views, 20);
        let empty = Shell::from_parts(Vec::new(), Vec::new(), Vec::new());
        assert_eq!(empty.depth_range([0.0, 0.0, 1.0]), (f64::INFINITY, f64::NEG_INFINITY));
    }

    /// The farthest corner found through the boxes is the one a scan of every corner finds, bit
    /// for bit, from eyes all around and inside the shell (and none without vertices).
    #[test]
    fn the_farthest_corner_is_exactly_a_full_scans() {
        let surface = bumpy(40);
        let prepared = PreparedShell::new(&surface);
        let mut views = 0;
        for (i, eye) in [DVec3::new(0.0, -4.0, 3.0), DVec3::new(5.0, 1.0, -0.5), DVec3::new(1.4, 0.9, 0.2)]
            .into_iter()
            .enumerate()
        {
            for k in 0..24 {
                let a = k as f64 * 0.7 + i as f64;
                let forward = DVec3::new(a.cos(), a.sin(), 0.3 * (2.0 * a).sin()).normalize();
                let scan = surface
                    .positions
                    .iter()
                    .zip(&surface.heights)
                    .map(|(&p, &h)| (p - eye).dot(forward).max((p + h - eye).dot(forward)))
                    .fold(f64::NEG_INFINITY, f64::max);
                let found = prepared.farthest(&surface, eye, forward).unwrap();
                assert_eq!(found.to_bits(), scan.to_bits(), "eye {eye}, forward {forward}");
                views += 1;
            }
        }
        assert_eq!(views, 72);
        let empty = BaseSurface::default();
        assert_eq!(PreparedShell::new(&empty).farthest(&empty, DVec3::ZERO, DVec3::X), None);
    }
}
