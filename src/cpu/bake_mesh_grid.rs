//! CPU twin (f64) of `wgsl/bake/bake_mesh_grid.wgsl`: per grid sample the vector to the closest
//! surface point and the signed distance (positive inside, ray parity voted over three skewed
//! directions) of the union of the mesh's closed parts and, for coloured meshes, the colour there,
//! by brute force over every triangle (ground truth: no BVH to get wrong).

use glam::DVec3;

use crate::mesh::shape::{GridSpec, MeshShape};

/// Mirrors DIR0..DIR2 of the kernel.
pub(crate) const DIRECTIONS: [[f64; 3]; 3] =
    [[0.99947, 0.02718, 0.01732], [0.01414, 0.99935, 0.03317], [0.03162, 0.02236, 0.99925]];

fn on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    if len2 <= 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// The closest point of triangle abc to p (Voronoi regions of corners, edges, face).
pub fn on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let sum = va + vb + vc;
    if sum <= 0.0 {
        let q = [on_segment(p, a, b), on_segment(p, b, c), on_segment(p, c, a)];
        return q
            .into_iter()
            .min_by(|x, y| (*x - p).length_squared().total_cmp(&(*y - p).length_squared()))
            .unwrap();
    }
    a + ab * (vb / sum) + ac * (vc / sum)
}

/// Whether the ray o + t d (t > 0) crosses triangle abc (Moller-Trumbore).
fn crosses(o: DVec3, d: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    let (e1, e2) = (b - a, c - a);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return false;
    }
    let tv = o - a;
    let u = tv.dot(pv) / det;
    let qv = tv.cross(e1);
    let v = d.dot(qv) / det;
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && e2.dot(qv) / det > 0.0
}

/// Whether p is inside the part made of `triangles`: odd crossings along at least two of the
/// three directions.
pub(crate) fn inside(shape: &MeshShape, triangles: std::ops::Range<usize>, p: DVec3) -> bool {
    let votes = DIRECTIONS
        .iter()
        .filter(|d| {
            let d = DVec3::from_array(**d);
            triangles.clone().filter(|&t| crosses(p, d, shape.triangle(t))).count() % 2 == 1
        })
        .count();
    votes >= 2
}

/// The sample at p: (vector to the closest surface point, signed distance) of the union of the
/// parts (the part with the largest signed distance); without `parity` every distance is
/// negative (a shell).
pub fn sample(shape: &MeshShape, p: DVec3, parity: bool) -> (DVec3, f64) {
    let (v, d, _) = closest(shape, p, parity);
    (v, d)
}

/// [`sample`] with the closest triangle.
fn closest(shape: &MeshShape, p: DVec3, parity: bool) -> (DVec3, f64, usize) {
    let mut out = (DVec3::ZERO, f64::NEG_INFINITY, 0);
    for &(first, count) in &shape.parts {
        let range = first as usize..(first + count) as usize;
        let mut best = (f64::INFINITY, p, 0);
        for t in range.clone() {
            let [a, b, c] = shape.triangle(t);
            let q = on_triangle(p, a, b, c);
            let d2 = (q - p).length_squared();
            if d2 < best.0 {
                best = (d2, q, t);
            }
        }
        let dist = best.0.sqrt();
        let signed = if parity && inside(shape, range, p) { dist } else { -dist };
        if signed > out.1 {
            out = (best.1 - p, signed, best.2);
        }
    }
    out
}

/// A coloured mesh's colour at the closest surface point to p: the closest triangle's corner
/// colours by barycentric weights (`None` for a mesh without colours).
pub fn sample_color(shape: &MeshShape, p: DVec3, parity: bool) -> Option<[f64; 3]> {
    let colors = shape.colors.as_ref()?;
    let (v, _, t) = closest(shape, p, parity);
    let [a, b, c] = shape.triangle(t);
    let (e1, e2, e) = (b - a, c - a, p + v - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let mut w = [1.0 / 3.0; 3];
    if det > 1e-30 * d11 * d22 {
        let v = (d22 * e.dot(e1) - d12 * e.dot(e2)) / det;
        let u = (d11 * e.dot(e2) - d12 * e.dot(e1)) / det;
        let clamped = [1.0 - v - u, v, u].map(|x: f64| x.clamp(0.0, 1.0));
        let sum = clamped.iter().sum::<f64>().max(1e-30);
        w = clamped.map(|x| x / sum);
    }
    let corner = colors[t];
    Some([0, 1, 2].map(|ch| (0..3).map(|k| corner[k][ch] as f64 * w[k]).sum()))
}

/// Every sample of the grid (x fastest, then y, then z) as (vector xyz, signed distance), and the
/// largest inside distance.
pub fn bake_mesh_grid(shape: &MeshShape, spec: &GridSpec) -> (Vec<[f64; 4]>, f64) {
    let [nx, ny, nz] = spec.n;
    let mut cells = Vec::with_capacity(spec.samples() as usize);
    let mut depth: f64 = 0.0;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (v, d) = sample(shape, spec.point(i, j, k), spec.parity);
                depth = depth.max(d);
                cells.push([v.x, v.y, v.z, d]);
            }
        }
    }
    (cells, depth)
}
