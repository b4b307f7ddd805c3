//! CPU twin of view-aligned prism slicing: `wgsl/shared/slice_prism.wgsl` (the intersection),
//! `count_slices.wgsl`, `scan_plane_offsets.wgsl` and `emit_slices.wgsl`. f32, with the same
//! functions and the same arithmetic in the same order as the WGSL, so results agree up to
//! the GPU's fused multiply-adds.

use crate::mesh::shell::Shell;
use crate::types::{DrawIndirect, Prism, ShellVertex, SliceParams, SliceVertex};

/// Below this `|s_a - s_b|` an edge counts as lying in the plane (t = 0.5).
pub(crate) const MIN_DENOM: f32 = 1e-30;

/// Where the plane cuts a prolonged normal edge (paper Fig. 3(b)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeClass {
    /// a: above the top.
    Above,
    /// b: between bottom and top.
    Within,
    /// c: below the bottom (the paper's rule also puts edges parallel to the plane here).
    Below,
}

/// One slice polygon: up to five vertices in order around the prism, in the sense of its base
/// triangle; `position.w` holds the prism index as f32 bits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Polygon {
    pub(crate) vertices: [SliceVertex; 5],
    /// Vertices used, 0 (no intersection) or 3 to 5.
    pub len: usize,
}

impl Polygon {
    /// The polygon's vertices.
    pub fn as_slice(&self) -> &[SliceVertex] {
        &self.vertices[..self.len]
    }
}

type V3 = [f32; 3];

/// Mirrors WGSL `PrismCorners`.
struct PrismCorners {
    bottom: [V3; 3],
    top: [V3; 3],
    uv: [[f32; 2]; 3],
    ids: [u32; 3],
    sphere: [f32; 4],
}

/// Mirrors WGSL `SlicePolygon`.
struct SlicePolygon {
    count: usize,
    pos: [V3; 5],
    uvw: [V3; 5],
}

#[derive(Clone, Copy)]
struct EdgePoint {
    pos: V3,
    uvw: V3,
}

fn xyz(v: [f32; 4]) -> V3 {
    [v[0], v[1], v[2]]
}

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn lerp(a: V3, b: V3, t: f32) -> V3 {
    [a[0] * (1.0 - t) + b[0] * t, a[1] * (1.0 - t) + b[1] * t, a[2] * (1.0 - t) + b[2] * t]
}

/// `None` for vertex ids out of range (the GPU reads clamped garbage there; here it is no slice).
fn load_prism(vertices: &[ShellVertex], prism: &Prism, sphere: [f32; 4]) -> Option<PrismCorners> {
    let ids = [prism.vertices[0], prism.vertices[1], prism.vertices[2]];
    let v = |i: usize| vertices.get(ids[i] as usize);
    let (v0, v1, v2) = (v(0)?, v(1)?, v(2)?);
    Some(PrismCorners {
        bottom: [xyz(v0.bottom), xyz(v1.bottom), xyz(v2.bottom)],
        top: [xyz(v0.top), xyz(v1.top), xyz(v2.top)],
        uv: [[prism.uv01[0], prism.uv01[1]], [prism.uv01[2], prism.uv01[3]], [prism.uv2[0], prism.uv2[1]]],
        ids,
        sphere,
    })
}

/// Depth of plane `k` (0 = back-most).
pub(crate) fn plane_offset(params: &SliceParams, k: u32) -> f32 {
    params.first_plane - k as f32 * params.spacing
}

/// A zero distance counts as the positive side, everywhere.
fn positive_side(s: f32) -> bool {
    s >= 0.0
}

fn crossed(sa: f32, sb: f32) -> bool {
    positive_side(sa) != positive_side(sb)
}

/// The paper's per-edge classification from the signed distances of bottom and top: b if they
/// are on different sides, else a if `|s_top| < |s_bottom|`, else c (parallel edges included).
/// For reference and tests: the slicer emits edges by their sign crossings and uses
/// `classify_oriented` only to pick the paper's order where its walk is free.
pub fn classify(s_bottom: f32, s_top: f32) -> EdgeClass {
    if crossed(s_bottom, s_top) {
        EdgeClass::Within
    } else if s_top.abs() < s_bottom.abs() {
        EdgeClass::Above
    } else {
        EdgeClass::Below
    }
}

/// The classification used by the slicer: "above" is taken relative to the whole prism's rise
/// (`rising`: the summed `s_top - s_bottom` is >= 0), not the edge's own. Equal to [`classify`]
/// for every edge whose own rise has the prism's sign; it differs for edges parallel to the plane
/// (where the paper's rule calls both sides c) and in twisted prisms.
pub(crate) fn classify_oriented(s_bottom: f32, s_top: f32, rising: bool) -> EdgeClass {
    if crossed(s_bottom, s_top) {
        return EdgeClass::Within;
    }
    // Uncrossed: the plane is above the edge if the prism rises towards it from the edge's side.
    if positive_side(s_bottom) != rising {
        EdgeClass::Above
    } else {
        EdgeClass::Below
    }
}

/// Point where the plane crosses edge a -> b; callers pass edges in canonical order.
fn edge_point(pa: V3, ua: V3, sa: f32, pb: V3, ub: V3, sb: f32) -> EdgePoint {
    let den = sa - sb;
    let mut t = 0.5;
    if den.abs() > MIN_DENOM {
        t = (sa / den).clamp(0.0, 1.0);
    }
    EdgePoint { pos: lerp(pa, pb, t), uvw: lerp(ua, ub, t) }
}

fn poly_push(poly: &mut SlicePolygon, p: EdgePoint) {
    let n = poly.count;
    if n > 0 && poly.pos[n - 1] == p.pos {
        return;
    }
    if n < 5 {
        poly.pos[n] = p.pos;
        poly.uvw[n] = p.uvw;
        poly.count = n + 1;
    }
}

/// Intersection of the upper or lower edge between corners i and j, smaller welded id first.
fn side_edge_point(c: &PrismCorners, s: &[f32; 3], upper: bool, i: usize, j: usize) -> EdgePoint {
    let (mut a, mut b) = (i, j);
    if c.ids[j] < c.ids[i] {
        a = j;
        b = i;
    }
    let w = if upper { 1.0 } else { 0.0 };
    let (mut pa, mut pb) = (c.bottom[a], c.bottom[b]);
    if upper {
        pa = c.top[a];
        pb = c.top[b];
    }
    let ua = [c.uv[a][0], c.uv[a][1], w];
    let ub = [c.uv[b][0], c.uv[b][1], w];
    edge_point(pa, ua, s[a], pb, ub, s[b])
}

/// Which cap the last emitted point lies on (WGSL `CAP_*`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cap {
    None,
    Top,
    Bottom,
}

/// Mirrors WGSL `slice_polygon`; see the comment there for the walk, its order and the bound of 5.
fn slice_polygon(c: &PrismCorners, n: V3, d: f32, trivial_reject: bool) -> SlicePolygon {
    let mut poly = SlicePolygon { count: 0, pos: [[0.0; 3]; 5], uvw: [[0.0; 3]; 5] };
    if trivial_reject && (dot(n, xyz(c.sphere)) - d).abs() > c.sphere[3] {
        return poly;
    }
    let mut sb = [0.0f32; 3];
    let mut st = [0.0f32; 3];
    for i in 0..3 {
        sb[i] = dot(n, c.bottom[i]) - d;
        st[i] = dot(n, c.top[i]) - d;
    }
    let rising = ((st[0] - sb[0]) + (st[1] - sb[1])) + (st[2] - sb[2]) >= 0.0;
    let mut start = 0;
    if !crossed(sb[0], st[0]) {
        if crossed(sb[1], st[1]) {
            start = 1;
        } else if crossed(sb[2], st[2]) {
            start = 2;
        }
    }
    let mut last_cap = Cap::None;
    for f in 0..3 {
        let i = (start + f) % 3;
        let j = (i + 1) % 3;
        if crossed(sb[i], st[i]) {
            let ub = [c.uv[i][0], c.uv[i][1], 0.0];
            let ut = [c.uv[i][0], c.uv[i][1], 1.0];
            let p = edge_point(c.bottom[i], ub, sb[i], c.top[i], ut, st[i]);
            poly_push(&mut poly, p);
            last_cap = Cap::None;
        }
        let upper = crossed(st[i], st[j]);
        let lower = crossed(sb[i], sb[j]);
        let mut lower_first = last_cap == Cap::Bottom;
        if last_cap == Cap::None {
            lower_first = classify_oriented(sb[i], st[i], rising) == EdgeClass::Below;
        }
        if lower_first {
            if lower {
                poly_push(&mut poly, side_edge_point(c, &sb, false, i, j));
                last_cap = Cap::Bottom;
            }
            if upper {
                poly_push(&mut poly, side_edge_point(c, &st, true, i, j));
                last_cap = Cap::Top;
            }
        } else {
            if upper {
                poly_push(&mut poly, side_edge_point(c, &st, true, i, j));
                last_cap = Cap::Top;
            }
            if lower {
                poly_push(&mut poly, side_edge_point(c, &sb, false, i, j));
                last_cap = Cap::Bottom;
            }
        }
    }
    if poly.count > 1 && poly.pos[poly.count - 1] == poly.pos[0] {
        poly.count -= 1;
    }
    if poly.count < 3 {
        poly.count = 0;
    }
    poly
}

/// The slice polygon of `prism` (with its bounding `sphere`) with the plane `dot(normal, x) = d`.
pub fn slice_prism(
    vertices: &[ShellVertex],
    prism: &Prism,
    sphere: [f32; 4],
    prism_index: u32,
    normal: [f32; 3],
    d: f32,
    trivial_reject: bool,
) -> Polygon {
    let mut out = Polygon::default();
    let Some(corners) = load_prism(vertices, prism, sphere) else {
        return out;
    };
    let poly = slice_polygon(&corners, normal, d, trivial_reject);
    for i in 0..poly.count {
        let p = poly.pos[i];
        let t = poly.uvw[i];
        out.vertices[i] = SliceVertex {
            position: [p[0], p[1], p[2], f32::from_bits(prism_index)],
            uvw: [t[0], t[1], t[2], 0.0],
        };
    }
    out.len = poly.count;
    out
}

/// Triangle-list vertices of a polygon with `count` points (WGSL `fan_vertex_count`).
pub(crate) fn fan_vertex_count(count: usize) -> u32 {
    if count >= 3 {
        3 * (count as u32 - 2)
    } else {
        0
    }
}

/// Fan triangulation (0, f+1, f+2), in the order `emit_slices` writes it.
pub(crate) fn triangulate(polygon: &Polygon) -> Vec<SliceVertex> {
    let v = polygon.as_slice();
    let mut out = Vec::with_capacity(fan_vertex_count(v.len()) as usize);
    for f in 0..v.len().saturating_sub(2) {
        out.extend([v[0], v[f + 1], v[f + 2]]);
    }
    out
}

fn planes<'a>(
    shell: &'a Shell,
    params: &'a SliceParams,
    trivial_reject: bool,
) -> impl Iterator<Item = impl Iterator<Item = Polygon> + 'a> + 'a {
    let normal = xyz(params.plane_normal);
    let prisms = shell.prisms.iter().zip(&shell.spheres);
    let prism_count = prisms.len().min(params.prism_count as usize);
    (0..params.plane_count).map(move |k| {
        let d = plane_offset(params, k);
        prisms.clone().take(prism_count).enumerate().map(move |(i, (p, &sphere))| {
            slice_prism(&shell.vertices, p, sphere, i as u32, normal, d, trivial_reject)
        })
    })
}

/// Twin of `emit_slices`: triangle-list vertices per plane, back to front (k ascending), prisms
/// in index order.
pub fn emit_slices(shell: &Shell, params: &SliceParams, trivial_reject: bool) -> Vec<Vec<SliceVertex>> {
    planes(shell, params, trivial_reject)
        .map(|plane| plane.flat_map(|p| triangulate(&p)).collect())
        .collect()
}

/// Twin of `count_slices`: the triangle-list vertex count of each plane.
pub fn count_slices(shell: &Shell, params: &SliceParams, trivial_reject: bool) -> Vec<u32> {
    planes(shell, params, trivial_reject)
        .map(|plane| plane.map(|p| fan_vertex_count(p.len)).sum())
        .collect()
}

/// Twin of `scan_plane_offsets`: exclusive prefix sums of `counts` and the draw arguments.
pub(crate) fn scan_plane_offsets(counts: &[u32], vertex_capacity: u32) -> (Vec<u32>, DrawIndirect) {
    let mut total = 0u32;
    let offsets = counts
        .iter()
        .map(|&c| {
            let o = total;
            total = total.wrapping_add(c);
            o
        })
        .collect();
    let args = DrawIndirect {
        vertex_count: total.min(vertex_capacity),
        instance_count: 1,
        first_vertex: 0,
        first_instance: 0,
    };
    (offsets, args)
}

/// Twin of the per-plane draw arguments of `scan_plane_offsets`: each plane's range of the vertex
/// buffer, cut at the capacity.
pub fn plane_draws(counts: &[u32], vertex_capacity: u32) -> Vec<DrawIndirect> {
    let (offsets, _) = scan_plane_offsets(counts, vertex_capacity);
    offsets
        .iter()
        .zip(counts)
        .map(|(&o, &c)| {
            let first = o.min(vertex_capacity);
            DrawIndirect {
                vertex_count: c.min(vertex_capacity - first),
                instance_count: 1,
                first_vertex: first,
                first_instance: 0,
            }
        })
        .collect()
}

#[cfg(test)]
#[path = "slice_prisms_tests.rs"]
mod tests;
