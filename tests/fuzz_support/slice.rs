//! The slicing twin's fuzz target: prisms and planes with exact coincidences, and the
//! invariants every slice polygon keeps.

use glam::DVec3;
use proptest::prelude::*;
use voltex::mesh::prism;
use voltex::methods::view_slices::slice_prisms;
use voltex::types::{Prism, ShellVertex};

/// A prism and a plane for the slicing twin: corners on a small integer grid (every dot product
/// is exact in f32) or random floats; planes through corners, along edges or faces, or anywhere.
#[derive(Debug, Clone)]
pub struct SliceInput {
    corners: [[f32; 3]; 6],
    ids: [u32; 3],
    normal: [f32; 3],
    d: f32,
    /// All heights equal and on the outer side of the base: the prism is convex.
    convex: bool,
}

pub fn slice_input() -> impl Strategy<Value = SliceInput> {
    let grid = || (-3i32..=3).prop_map(|x| x as f32);
    let point = move || [grid(), grid(), grid()];
    let float_point = || [-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0];
    let corners = prop_oneof![
        // Oblique convex prism: one height vector for all three corners.
        (point(), point(), point(), point())
            .prop_map(|(a, b, c, h)| ([a, b, c, add(a, h), add(b, h), add(c, h)], true)),
        (point(), point(), point(), point(), point(), point())
            .prop_map(|(a, b, c, d, e, f)| ([a, b, c, d, e, f], false)),
        (float_point(), float_point(), float_point(), float_point(), float_point(), float_point())
            .prop_map(|(a, b, c, d, e, f)| ([a, b, c, d, e, f], false)),
    ];
    let ids = prop_oneof![Just([0u32, 1, 2]), Just([2u32, 0, 1]), Just([1u32, 2, 0]), Just([0u32, 2, 1])];
    // Plane: a normal (grid, axis, random or through three corners) and an offset (through a
    // corner, through an edge's midpoint, or random).
    (corners, ids, point(), float_point(), 0..4u8, [0..6usize, 0..6usize, 0..6usize], 0..3u8, -4.0f32..4.0)
        .prop_map(|((corners, convex0), ids, gn, fnrm, nkind, pick, dkind, dr)| {
            let normal = match nkind {
                0 => gn,
                1 => fnrm,
                2 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]][pick[0] % 3],
                _ => cross(sub(corners[pick[1]], corners[pick[0]]), sub(corners[pick[2]], corners[pick[0]])),
            };
            let d = match dkind {
                0 => dot(normal, corners[pick[0]]),
                1 => dot(normal, scale(add(corners[pick[0]], corners[pick[1]]), 0.5)),
                _ => dr,
            };
            // Convex only if the shared height is on the outer side of a non-degenerate base.
            let h = sub(corners[3], corners[0]);
            let n0 = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]));
            SliceInput { corners, ids, normal, d, convex: convex0 && dot(h, n0) > 0.0 }
        })
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Distance from `p` to the segment `a`-`b`, in f64.
fn segment_distance(p: [f32; 3], a: [f32; 3], b: [f32; 3]) -> f64 {
    let [p, a, b] = [p, a, b].map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
    let ab = b - a;
    let t =
        if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).length()
}

/// Checks the invariants; `Ok(true)` when the plane cut the prism.
pub fn slice_case(input: &SliceInput) -> Result<bool, String> {
    let c = input.corners;
    // Welded vertex i is corner slot i of the prism; `ids` permutes which corner is which id.
    let mut vertices = [ShellVertex::default(); 3];
    for k in 0..3 {
        let i = input.ids[k] as usize;
        vertices[i] = ShellVertex {
            bottom: [c[k][0], c[k][1], c[k][2], 1.0],
            top: [c[k + 3][0], c[k + 3][1], c[k + 3][2], 1.0],
        };
    }
    let corners64 = c.map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
    let (centre, radius) = prism::bounding_sphere(corners64);
    let radius = radius * (1.0 + 1e-5) + 1e-6;
    let prism = Prism {
        vertices: [input.ids[0], input.ids[1], input.ids[2], 0],
        uv01: [0.0, 0.0, 1.0, 0.0],
        uv2: [0.0, 1.0, 0.0, 0.0],
    };
    let sphere = [centre.x as f32, centre.y as f32, centre.z as f32, radius as f32];
    let (n, d) = (input.normal, input.d);
    let poly = slice_prisms::slice_prism(&vertices, &prism, sphere, 7, n, d, false);
    // The trivial reject (sphere against plane) assumes a unit normal, as the sweep's is.
    let nlen = (dot(n, n) as f64).sqrt();
    if nlen > 0.0 {
        let (un, ud) = (scale(n, (1.0 / nlen) as f32), (d as f64 / nlen) as f32);
        let kept = slice_prisms::slice_prism(&vertices, &prism, sphere, 7, un, ud, false);
        let rejected = slice_prisms::slice_prism(&vertices, &prism, sphere, 7, un, ud, true);
        if format!("{rejected:?}") != format!("{kept:?}") {
            return Err(format!("the trivial reject changed the polygon: {rejected:?} vs {kept:?}"));
        }
    }
    if !matches!(poly.len, 0 | 3 | 4 | 5) {
        return Err(format!("{} vertices: the 27 cases give 0, 3, 4 or 5", poly.len));
    }
    let size = c.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs() as f64));
    let tol = 1e-5 * size;
    let edges = [(0, 3), (1, 4), (2, 5), (0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3)];
    for v in poly.as_slice() {
        let p = [v.position[0], v.position[1], v.position[2]];
        if !p.iter().chain(&v.uvw[..3]).all(|x| x.is_finite()) {
            return Err(format!("non-finite slice vertex {v:?}"));
        }
        if v.position[3].to_bits() != 7 {
            return Err("the prism index was lost".into());
        }
        let off = (dot(n, p) as f64 - d as f64).abs();
        if off > tol * nlen.max(1.0) * 4.0 {
            return Err(format!("vertex {p:?} is {off} off the plane"));
        }
        let near_edge =
            edges.iter().map(|&(a, b)| segment_distance(p, c[a], c[b])).fold(f64::INFINITY, f64::min);
        if near_edge > tol * 4.0 {
            return Err(format!("vertex {p:?} lies on no prism edge (nearest {near_edge})"));
        }
        let [s, t, w] = [v.uvw[0], v.uvw[1], v.uvw[2]];
        if !(-1e-6..=1.0 + 1e-6).contains(&w) || s < -1e-6 || t < -1e-6 || s + t > 1.0 + 1e-5 {
            return Err(format!("texture coordinate {:?} outside the prism", &v.uvw[..3]));
        }
    }
    // A convex prism that the plane strictly separates has a cross-section of positive area.
    if input.convex && nlen > 0.0 {
        let s: Vec<f32> = c.iter().map(|&p| dot(n, p) - d).collect();
        let margin = 1e-3 * nlen as f32 * size as f32;
        if s.iter().any(|&x| x > margin) && s.iter().any(|&x| x < -margin) && poly.len == 0 {
            return Err("a plane through the inside of a convex prism gave no polygon".into());
        }
    }
    Ok(poly.len > 0)
}
