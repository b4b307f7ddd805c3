//! Built-in base surfaces: plane grid, UV sphere, (distorted) torus. All welded, counter-clockwise seen
//! from outside, uv in `[0, 1]` per tile, deterministic from their seed.

use super::Mesh;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Small deterministic generator (xorshift64*), so meshes do not depend on a rand crate's version.
struct XorShift(u64);

impl XorShift {
    fn new(seed: u32) -> Self {
        // Spread the seed so that 0 and small seeds still give good sequences.
        XorShift((seed as u64 ^ 0x9E37_79B9_7F4A_7C15).wrapping_mul(0xBF58_476D_1CE4_E5B9) | 1)
    }
    /// Uniform in [0, 1).
    fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Grid of `cells.0 x cells.1` quads (two triangles each) in the xy plane, centred at the origin,
/// normal +z. `jitter` moves interior vertices by up to that fraction of a cell (keep it < 0.5 so no
/// triangle flips); uv follows the jittered position so the pattern is not distorted.
pub fn plane(size: [f64; 2], cells: [u32; 2], jitter: f64, seed: u32) -> Mesh {
    let (nx, ny) = (cells[0] as usize, cells[1] as usize);
    let cell = DVec2::new(size[0] / nx as f64, size[1] / ny as f64);
    let mut rng = XorShift::new(seed);
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let mut p = DVec2::new(i as f64, j as f64) * cell - DVec2::from(size) * 0.5;
            let (dx, dy) = (rng.next_f64() * 2.0 - 1.0, rng.next_f64() * 2.0 - 1.0);
            if i > 0 && i < nx && j > 0 && j < ny {
                p += DVec2::new(dx, dy) * cell * jitter;
            }
            positions.push(p.extend(0.0));
        }
    }
    let uv = |p: DVec3| (p.truncate() + DVec2::from(size) * 0.5) / DVec2::from(size);
    let idx = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let corner_uvs = triangles.iter().map(|t| t.map(|k| uv(positions[k as usize]))).collect();
    let normals = vec![DVec3::Z; positions.len()];
    with_corner_uvs(positions, normals, triangles, corner_uvs)
}

/// A mesh of these triangles and corner uvs, vertex uvs derived from the corners.
fn with_corner_uvs(
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    corner_uvs: Vec<[DVec2; 3]>,
) -> Mesh {
    let mut m = Mesh {
        positions,
        normals,
        triangles,
        corner_uvs,
        vertex_uvs: vec![],
        attribute: None,
        colors: None,
        face_lines: vec![],
        uvs_missing: false,
    };
    m.vertex_uvs = m.vertex_uvs_from_corners();
    m
}

/// A parametric closed surface sampled on a grid with wrapped indices (welded seams).
/// `pos(u, v)` for u, v in `[0, 1]`; u wraps; v wraps when `wrap_v`, else v = 0 and v = 1 are poles
/// (one vertex each, triangle fans). Returns the mesh without normals.
fn parametric(nu: usize, nv: usize, wrap_v: bool, pos: impl Fn(f64, f64) -> DVec3) -> Mesh {
    let mut positions = Vec::new();
    let rows: Vec<usize> = if wrap_v { (0..nv).collect() } else { (1..nv).collect() };
    for &j in &rows {
        for i in 0..nu {
            positions.push(pos(i as f64 / nu as f64, j as f64 / nv as f64));
        }
    }
    // Grid index of (i, j) with wrapping; poles are appended after the rings.
    let ring_base = if wrap_v { 0 } else { 1 };
    let south = positions.len() as u32;
    let north = south + 1;
    if !wrap_v {
        positions.push(pos(0.0, 0.0));
        positions.push(pos(0.0, 1.0));
    }
    let vid = |i: usize, j: usize| -> u32 {
        let i = i % nu;
        if wrap_v {
            ((j % nv) * nu + i) as u32
        } else if j == 0 {
            south
        } else if j == nv {
            north
        } else {
            ((j - ring_base) * nu + i) as u32
        }
    };
    let uv = |i: usize, j: usize| DVec2::new(i as f64 / nu as f64, j as f64 / nv as f64);
    let mut triangles = Vec::new();
    let mut corner_uvs = Vec::new();
    for j in 0..nv {
        for i in 0..nu {
            // Quad (i,j) (i+1,j) (i+1,j+1) (i,j+1) is counter-clockwise when dp/du x dp/dv points out.
            let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let ids = q.map(|(a, b)| vid(a, b));
            let uvs = q.map(|(a, b)| uv(a, b));
            if !wrap_v && j == 0 {
                // South pole fan: the pole corner gets the mid-u of its wedge.
                let pole_uv = DVec2::new((i as f64 + 0.5) / nu as f64, 0.0);
                triangles.push([ids[0], ids[2], ids[3]]);
                corner_uvs.push([pole_uv, uvs[2], uvs[3]]);
            } else if !wrap_v && j == nv - 1 {
                let pole_uv = DVec2::new((i as f64 + 0.5) / nu as f64, 1.0);
                triangles.push([ids[0], ids[1], ids[2]]);
                corner_uvs.push([uvs[0], uvs[1], pole_uv]);
            } else {
                triangles.push([ids[0], ids[1], ids[2]]);
                corner_uvs.push([uvs[0], uvs[1], uvs[2]]);
                triangles.push([ids[0], ids[2], ids[3]]);
                corner_uvs.push([uvs[0], uvs[2], uvs[3]]);
            }
        }
    }
    let normals = vec![DVec3::ZERO; positions.len()];
    with_corner_uvs(positions, normals, triangles, corner_uvs)
}

/// UV sphere around the origin: `segments = (around z, pole to pole)`, at least (3, 2).
/// Poles are single vertices with triangle fans (no degenerate triangles). Analytic normals.
pub fn sphere(radius: f64, segments: [u32; 2]) -> Mesh {
    let (nu, nv) = (segments[0] as usize, segments[1] as usize);
    let dir = |u: f64, v: f64| {
        let (theta, phi) = (u * TAU, v * PI);
        DVec3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), -phi.cos())
    };
    let mut m = parametric(nu, nv, false, |u, v| dir(u, v) * radius);
    m.normals = m.positions.iter().map(|p| p.normalize()).collect();
    m
}

/// Torus around the z axis: `segments = (around z, around the tube)`, at least (3, 3), giving
/// `2 * segments.0 * segments.1` triangles. `distortion` perturbs the tube radius smoothly,
/// `minor * (1 + distortion * sin(3u + phase) * (1 + cos v) / 2)` with a phase from `seed`: bumps on
/// the outer side that fade out towards the inner equator, where tilted normals would make the
/// converging height vectors cross. Keep it < 1.
/// Normals are those of the smooth parametric surface (cross product of its partial derivatives).
pub fn torus(major: f64, minor: f64, segments: [u32; 2], distortion: f64, seed: u32) -> Mesh {
    let (nu, nv) = (segments[0] as usize, segments[1] as usize);
    let phase = XorShift::new(seed).next_f64() * TAU;
    let pos = move |u: f64, v: f64| {
        let (theta, phi) = (u * TAU, v * TAU);
        let bump = (3.0 * theta + phase).sin() * (1.0 + phi.cos()) * 0.5;
        let r = minor * (1.0 + distortion * bump);
        let ring = major + r * phi.cos();
        DVec3::new(ring * theta.cos(), ring * theta.sin(), r * phi.sin())
    };
    let mut m = parametric(nu, nv, true, pos);
    let e = 1e-6;
    m.normals = (0..m.positions.len())
        .map(|k| {
            let (i, j) = (k % nu, k / nu);
            let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
            let du = pos(u + e, v) - pos(u - e, v);
            let dv = pos(u, v + e) - pos(u, v - e);
            du.cross(dv).normalize_or_zero()
        })
        .collect();
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Every undirected edge is shared by exactly two triangles in opposite directions (closed,
    /// welded, consistently oriented).
    fn assert_closed(m: &Mesh) {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&v| v == 0), "open or misoriented edges");
    }

    fn assert_outward(m: &Mesh, centre_of: impl Fn(DVec3) -> DVec3) {
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.length() > 1e-12, "degenerate triangle {t:?}");
            let mid = (a + b + c) / 3.0;
            assert!(n.dot(mid - centre_of(mid)) > 0.0, "inward triangle {t:?}");
            for &i in t {
                assert!(m.normals[i as usize].dot(n) > 0.0, "normal against face {t:?}");
            }
        }
    }

    #[test]
    fn plane_counts_and_orientation() {
        let m = plane([2.0, 2.0], [40, 40], 0.2, 7);
        assert_eq!(m.triangles.len(), 3200);
        assert_eq!(m.positions.len(), 41 * 41);
        for t in 0..m.triangles.len() {
            let [a, b, c] = m.triangles[t].map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
        }
        // Border vertices stay on the border; jitter is deterministic.
        assert_eq!(m.positions[0], DVec3::new(-1.0, -1.0, 0.0));
        assert_eq!(m, plane([2.0, 2.0], [40, 40], 0.2, 7));
        assert_ne!(m.positions, plane([2.0, 2.0], [40, 40], 0.2, 8).positions);
    }

    #[test]
    fn torus_576_welded_outward() {
        let m = torus(1.0, 0.45, [24, 12], 0.15, 1);
        assert_eq!(m.triangles.len(), 576);
        assert_eq!(m.positions.len(), 24 * 12);
        assert_closed(&m);
        assert_outward(&m, |p| {
            let r = DVec3::new(p.x, p.y, 0.0).normalize();
            r * 1.0
        });
        // The seam triangle reaches u = 1.0 rather than wrapping back to 0.
        let seam =
            m.corner_uvs.iter().any(|c| c.iter().any(|uv| uv.x == 1.0) && c.iter().any(|uv| uv.x < 1.0));
        assert!(seam);
    }

    #[test]
    fn sphere_poles_fans_welded_outward() {
        let m = sphere(1.0, [16, 8]);
        assert_eq!(m.triangles.len(), 2 * 16 * 7);
        assert_eq!(m.positions.len(), 16 * 7 + 2);
        assert_closed(&m);
        assert_outward(&m, |_| DVec3::ZERO);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((p.length() - 1.0).abs() < 1e-12 && (*p - *n).length() < 1e-12);
        }
    }
}
