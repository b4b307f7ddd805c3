//! CPU twins of the axis-slicing kernels (`choose_axis_slices`, `emit_axis_slices`,
//! `bake_axis_slices` and `wgsl/shared/axis_slices.wgsl`), in f32 like the kernels so that the
//! discrete decisions (direction, level) agree. Directions: 0 = s, 1 = t, 2 = w.

use glam::{Vec2, Vec3, Vec4};

use super::slice_images::{level_count, level_layer, level_slices, occupancy_base, slice_layer};

use crate::types::{AxisChoice, AxisParams, AxisVertex};

/// Most slices of one direction crossing one prism.
pub(crate) const MAX_PRISM_SLICES: u32 = 4096;

/// A prism as the kernels see it: camera-relative corners, uvs, slice normals and thicknesses.
#[derive(Clone, Debug)]
pub struct AxisFrame {
    pub(crate) bottom: [Vec3; 3],
    pub(crate) top: [Vec3; 3],
    pub(crate) uv: [Vec2; 3],
    /// Per direction: unit slice-plane normal (xyz) and the texel's thickness along it (w).
    pub(crate) axes: [Vec4; 3],
    pub(crate) centre: Vec3,
    pub(crate) has_uv: bool,
}

fn axis_of(n: Vec3, along: Vec3) -> Vec4 {
    let len = n.length();
    if len < 1e-20 {
        return Vec4::ZERO;
    }
    let mut u = n / len;
    let mut l = u.dot(along);
    if l < 0.0 {
        u = -u;
        l = -l;
    }
    u.extend(l)
}

impl AxisFrame {
    /// The frame of the prism with these bottom and top corners (camera-relative) and uvs.
    pub fn new(bottom: [Vec3; 3], top: [Vec3; 3], uv: [Vec2; 3]) -> Self {
        let mid = |i: usize| 0.5 * (bottom[i] + top[i]);
        let (e1, e2) = (mid(1) - mid(0), mid(2) - mid(0));
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        let dw = ((top[0] - bottom[0]) + (top[1] - bottom[1]) + (top[2] - bottom[2])) / 3.0;
        let has_uv = det.abs() > 1e-12;
        let (ds, dt) = if has_uv {
            ((e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det)
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        let axes = [axis_of(dt.cross(dw), ds), axis_of(dw.cross(ds), dt), axis_of(ds.cross(dt), dw)];
        let centre = (0..3).map(|i| bottom[i] + top[i]).sum::<Vec3>() / 6.0;
        Self { bottom, top, uv, axes, centre, has_uv }
    }

    /// The frame of prism `index` of a shell (camera-relative, as uploaded).
    pub fn of_shell(shell: &crate::mesh::shell::Shell, index: usize) -> Self {
        let p = &shell.prisms[index];
        let v = |i: usize| &shell.vertices[p.vertices[i] as usize];
        let b = |i: usize| Vec4::from(v(i).bottom).truncate();
        let t = |i: usize| Vec4::from(v(i).top).truncate();
        let uv =
            [Vec2::new(p.uv01[0], p.uv01[1]), Vec2::new(p.uv01[2], p.uv01[3]), Vec2::new(p.uv2[0], p.uv2[1])];
        Self::new([b(0), b(1), b(2)], [t(0), t(1), t(2)], uv)
    }
}

/// The quality score `(1/c^2 - 1) h^2` of a direction (section 4.2); huge when unusable.
pub(crate) fn direction_score(f: &AxisFrame, params: &AxisParams, d: usize, view: Vec3) -> f32 {
    let axis = f.axes[d];
    let c = axis.truncate().dot(view).abs();
    if c < 1e-6 || axis.w <= 0.0 || (d < 2 && !f.has_uv) {
        return 3.0e38;
    }
    let h = axis.w / params.resolution[d] as f32;
    (1.0 / (c * c) - 1.0) * h * h
}

/// Slices needed by the criteria `h tan(a) / d <= 1` and `h sin(a) / (z / f) <= p` (the smaller,
/// since meeting either suffices), with `a` clamped to the maximum view angle, for a direction
/// of `r` slices at the finest level whose texel thickness is `thickness` at view depth `z`.
pub(crate) fn needed_slices(params: &AxisParams, r: u32, cos_a: f32, thickness: f32, z: f32) -> f32 {
    let a = cos_a.clamp(0.0, 1.0).acos().min(params.criteria[2]);
    let depth = r as f32 * a.tan() / params.criteria[0];
    let pixels = thickness * a.sin() * params.criteria[3] / (z.max(1e-6) * params.criteria[1]);
    depth.min(pixels).clamp(1.0, r as f32)
}

/// The coarsest power-of-two level of `r` slices with at least `needed` slices.
pub(crate) fn level_for(r: u32, needed: f32) -> u32 {
    let mut level = 0;
    while level + 1 < level_count(r) && level_slices(r, level + 1) as f32 >= needed {
        level += 1;
    }
    level
}

/// The eye's texture coordinate (s, t or w) in the prism's frame: the eye is the origin of the
/// camera-relative positions, and a coordinate grows by 1 over the axis' thickness from the
/// centre (s, t: the mean corner uv; w: 1/2). A huge negative value for an unusable direction.
pub(crate) fn eye_coordinate(f: &AxisFrame, d: usize) -> f32 {
    let axis = f.axes[d];
    if axis.w <= 0.0 || (d < 2 && !f.has_uv) {
        return -3.0e38;
    }
    let mid = if d < 2 { (f.uv[0][d] + f.uv[1][d] + f.uv[2][d]) / 3.0 } else { 0.5 };
    mid - f.centre.dot(axis.truncate()) / axis.w
}

/// The eye inside the shell (the host's test, `forward[3]`) and within this prism's height
/// range: rays from the eye may leave the layer through its top or bottom before reaching a
/// coarse slab's one slice, so the criteria (made for an eye outside) give way to the finest level.
pub(crate) fn eye_in_layer(f: &AxisFrame, params: &AxisParams) -> bool {
    let w = eye_coordinate(f, 2);
    params.forward[3] != 0.0 && (0.0..=1.0).contains(&w)
}

/// The eye in the prism's box of texture coordinates widened by one finest slice: there the
/// camera's forward, not the direction to the centre, says which way the rays go.
pub(crate) fn eye_near(f: &AxisFrame, params: &AxisParams) -> bool {
    (0..2).all(|d| {
        let c = f.uv.map(|uv| uv[d]);
        let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
        let margin = 1.0 / params.resolution[d] as f32;
        let e = eye_coordinate(f, d);
        !(e < lo - margin || e > hi + margin)
    })
}

/// The eye's position in slices of the chosen level (slice g spans `[g, g + 1]`) when the eye is
/// in the prism's layer, else a huge negative value: slices are then drawn farthest from the eye
/// first on both of its sides, and the slab holding the eye is split at it.
pub(crate) fn eye_slice(f: &AxisFrame, params: &AxisParams, c: &AxisChoice) -> f32 {
    if !eye_in_layer(f, params) {
        return -3.0e38;
    }
    let e = eye_coordinate(f, c.direction as usize);
    if e < -1.0e30 {
        return e;
    }
    e * level_slices(params.resolution[c.direction as usize], c.level) as f32
}

/// Whether slab `g` holds the eye at `xe` (in slices): a ray from the eye sees only the part on
/// its own side, so each part is drawn as its own slice.
pub(crate) fn splits_at_eye(g: i32, xe: f32) -> bool {
    xe > g as f32 && xe < (g + 1) as f32
}

/// The two parts of slab `g` split at `xe`: texture coordinates of their middles and their
/// thicknesses in slices, for `n` slices per tile.
pub(crate) fn split_slab(g: i32, xe: f32, n: f32) -> ([f32; 2], [f32; 2]) {
    let below = xe - g as f32;
    let above = (g + 1) as f32 - xe;
    ([(g as f32 + 0.5 * below) / n, (xe + 0.5 * above) / n], [below, above])
}

/// The slices of a choice in draw order: back to front, or with the eye in the layer, the two
/// ends of the remaining range, farthest from the eye first (each side of the eye back to front).
pub(crate) fn draw_order(c: &AxisChoice, xe: f32) -> Vec<i32> {
    let (mut lo, mut hi) = (c.first, c.first + c.count as i32 - 1);
    (0..c.count)
        .map(|j| {
            if xe <= -1.0e30 {
                return slice_position(c, j);
            }
            if (lo as f32 + 0.5 - xe).abs() > (hi as f32 + 0.5 - xe).abs() {
                lo += 1;
                lo - 1
            } else {
                hi -= 1;
                hi + 1
            }
        })
        .collect()
}

/// Direction, level and slice range of a prism; `vertex_count` and the offset are left at 0.
pub fn choose_axis(f: &AxisFrame, params: &AxisParams) -> AxisChoice {
    let inside = eye_in_layer(f, params);
    let view = if inside && eye_near(f, params) {
        Vec4::from(params.forward).truncate()
    } else {
        f.centre.normalize()
    };
    let (mut best, mut best_score) = (2usize, 3.4e38f32);
    for k in 0..3 {
        let d = (k + 2) % 3;
        if params.flags[0] & (1 << d) == 0 {
            continue;
        }
        let s = direction_score(f, params, d, view);
        if s < best_score {
            (best, best_score) = (d, s);
        }
    }
    let axis = f.axes[best];
    let r = params.resolution[best];
    let z = f.centre.dot(Vec4::from(params.forward).truncate());
    let needed = needed_slices(params, r, axis.truncate().dot(view).abs(), axis.w, z);
    let level = if inside { 0 } else { level_for(r, needed) };
    let n = level_slices(r, level);
    let (mut first, mut count) = (0, n);
    if best < 2 {
        let c = f.uv.map(|uv| uv[best]);
        let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
        let g_lo = (lo * n as f32 - 0.5).ceil() as i32;
        let g_hi = (hi * n as f32 - 0.5).floor() as i32;
        first = g_lo;
        count = (g_hi - g_lo + 1).clamp(0, MAX_PRISM_SLICES as i32) as u32;
    }
    AxisChoice {
        direction: best as u32,
        level,
        first,
        count,
        reverse: (axis.truncate().dot(view) > 0.0) as u32,
        ..Default::default()
    }
}

/// The opaque base surfaces' depth as `draw_base` leaves it in `base_depth`, with the frame's
/// projection: what the occlusion culling reads.
pub struct Occluders<'a> {
    /// The frame's camera-relative world to clip transform.
    pub view_proj: glam::Mat4,
    /// Size of the depth image in pixels (width, height).
    pub size: (u32, u32),
    /// Row-major, top row first: NDC depth of the nearest base surface, 1 where there is none.
    pub depth: &'a [f32],
}

/// Largest screen rectangle (pixels) the occlusion test reads; larger prisms are drawn.
pub(crate) const MAX_OCCLUSION_PIXELS: i32 = 4096;

/// Tolerance of the coverage test (pixels): wider than the rasteriser's sub-pixel snapping.
const COVER_TOLERANCE: f32 = 1.0 / 64.0;

fn edge_function(a: Vec2, b: Vec2, p: Vec2) -> f32 {
    (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)
}

/// Twin of `in_triangle`: `p` in triangle abc widened by the tolerance; no area covers nothing.
fn in_triangle(a: Vec2, b: Vec2, c: Vec2, p: Vec2) -> bool {
    let area = edge_function(a, b, c);
    if area == 0.0 {
        return false;
    }
    let s = area.signum();
    [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| s * edge_function(u, v, p) >= -COVER_TOLERANCE * (v - u).length())
}

/// Twin of `in_projection`: `p` in the projected base or top triangle or a side's hull.
fn in_projection(q: &[Vec2; 6], p: Vec2) -> bool {
    in_triangle(q[0], q[1], q[2], p)
        || in_triangle(q[3], q[4], q[5], p)
        || (0..3).any(|i| {
            let j = (i + 1) % 3;
            let (a, b, c, d) = (q[i], q[j], q[j + 3], q[i + 3]);
            in_triangle(a, b, c, p)
                || in_triangle(a, c, d, p)
                || in_triangle(a, b, d, p)
                || in_triangle(b, c, d, p)
        })
}

/// Twin of `hidden_behind_base` (wgsl/shared/occlusion.wgsl): whether every pixel centre in the
/// prism's projection already holds a base surface nearer than its nearest corner, so that no
/// fragment of its slices can pass the depth test.
pub(crate) fn hidden_behind_base(f: &AxisFrame, occ: &Occluders) -> bool {
    let size = glam::Vec2::new(occ.size.0 as f32, occ.size.1 as f32);
    let (mut lo, mut hi, mut near) = (Vec2::splat(3.4e38), Vec2::splat(-3.4e38), 3.4e38f32);
    let mut q = [Vec2::ZERO; 6];
    for (k, p) in f.bottom.iter().chain(&f.top).enumerate() {
        let c = occ.view_proj * p.extend(1.0);
        if c.w <= 0.0 {
            return false;
        }
        let ndc = c.truncate() / c.w;
        let px = Vec2::new((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y)
            .clamp(Vec2::splat(-1e7), Vec2::splat(1e7));
        q[k] = px;
        lo = lo.min(px);
        hi = hi.max(px);
        near = near.min(ndc.z);
    }
    near -= 1e-6 * (1.0 + near.abs());
    let first = (lo - 0.5).ceil().as_ivec2().max(glam::IVec2::ZERO);
    let last = (hi - 0.5).floor().as_ivec2().min(size.as_ivec2() - 1);
    if last.x < first.x || last.y < first.y {
        return true;
    }
    let span = last - first + 1;
    if span.x * span.y > MAX_OCCLUSION_PIXELS {
        return false;
    }
    (first.y..=last.y).all(|y| {
        (first.x..=last.x).all(|x| {
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            !in_projection(&q, centre) || occ.depth[(y as u32 * occ.size.0 + x as u32) as usize] < near
        })
    })
}

/// The j-th slice position drawn (back to front).
pub(crate) fn slice_position(c: &AxisChoice, j: u32) -> i32 {
    let k = if c.reverse == 1 { c.count - 1 - j } else { j };
    c.first + k as i32
}

fn occupied(c: &AxisChoice, params: &AxisParams, occupancy: &[u32], g: i32) -> bool {
    if params.flags[3] == 0 {
        return true;
    }
    let res = [params.resolution[0], params.resolution[1], params.resolution[2]];
    let n = level_slices(res[c.direction as usize], c.level);
    occupancy[(occupancy_base(res, c.direction, c.level) + slice_layer(g, n)) as usize] != 0
}

/// Crossings of the line `uv[direction] = x` with the uv triangle's edges (half-open edges, so
/// a line crosses 0 or 2 of them): (edge start, edge end, parameter).
fn crossings(f: &AxisFrame, direction: usize, x: f32) -> Vec<(usize, usize, f32)> {
    (0..3)
        .filter_map(|e| {
            let e2 = (e + 1) % 3;
            let (a, b) = (f.uv[e][direction], f.uv[e2][direction]);
            ((a <= x && x < b) || (b <= x && x < a)).then(|| (e, e2, (x - a) / (b - a)))
        })
        .collect()
}

/// Twin of `choose_axis_slices`: the choice with its vertex count (occlusion culling applied
/// when switched on and `occluders` are given).
pub fn choose_axis_slices(
    f: &AxisFrame,
    params: &AxisParams,
    occupancy: &[u32],
    occluders: Option<&Occluders>,
) -> AxisChoice {
    let mut c = choose_axis(f, params);
    if params.flags[2] != 0 && occluders.is_some_and(|o| hidden_behind_base(f, o)) {
        c.culled = 1;
        return c;
    }
    c.vertex_count = emit_axis_slices(f, params, occupancy, &c).len() as u32;
    c
}

/// Twin of `emit_axis_slices`: the slices of one prism, back to front, as triangle-list vertices.
pub fn emit_axis_slices(
    f: &AxisFrame,
    params: &AxisParams,
    occupancy: &[u32],
    c: &AxisChoice,
) -> Vec<AxisVertex> {
    let d = c.direction as usize;
    let r = params.resolution[d];
    let n = level_slices(r, c.level);
    let layer0 = level_layer(r, c.level);
    let slab = f.axes[d].w / n as f32;
    let xe = eye_slice(f, params, c);
    let mut out = Vec::new();
    for g in draw_order(c, xe) {
        if !occupied(c, params, occupancy, g) {
            continue;
        }
        let layer = layer0 + slice_layer(g, n);
        if splits_at_eye(g, xe) {
            let (x, parts) = split_slab(g, xe, n as f32);
            emit_slice(f, d, x[0], parts[0] * slab, layer, &mut out);
            emit_slice(f, d, x[1], parts[1] * slab, layer, &mut out);
        } else {
            emit_slice(f, d, (g as f32 + 0.5) / n as f32, slab, layer, &mut out);
        }
    }
    out
}

/// The slice of direction `d` at texture coordinate `x` standing for a slab `thickness` (world)
/// thick: a triangle (w) or a ruled quad (s, t; nothing when the line misses the uv triangle).
fn emit_slice(f: &AxisFrame, d: usize, x: f32, thickness: f32, layer: u32, out: &mut Vec<AxisVertex>) {
    let normal = f.axes[d].truncate().extend(0.0).to_array();
    let layer = layer as f32;
    if d == 2 {
        for i in 0..3 {
            let p = f.bottom[i].lerp(f.top[i], x);
            out.push(AxisVertex {
                position: p.extend(thickness).to_array(),
                texcoord: [f.uv[i].x, f.uv[i].y, layer, 2.0],
                normal,
            });
        }
        return;
    }
    let hits = crossings(f, d, x);
    if hits.len() < 2 {
        return;
    }
    let other = 1 - d;
    let ends: Vec<(Vec3, f32, f32)> = hits[..2]
        .iter()
        .flat_map(|&(a, b, l)| {
            let u = f.uv[a][other] + (f.uv[b][other] - f.uv[a][other]) * l;
            [(f.bottom[a].lerp(f.bottom[b], l), u, 0.0), (f.top[a].lerp(f.top[b], l), u, 1.0)]
        })
        .collect();
    for k in [0, 2, 3, 0, 3, 1] {
        let (p, u, v) = ends[k];
        out.push(AxisVertex {
            position: p.extend(thickness).to_array(),
            texcoord: [u, v, layer, d as f32],
            normal,
        });
    }
}

/// Twin of `bake_axis_slices`: every level of every direction from an RGBA8 premultiplied volume
/// (`s` fastest), as (per direction, layers of `width x height` RGBA texels) and the occupancy
/// words.
pub fn bake_axis_slices(volume: &[[u8; 4]], res: [u32; 3]) -> ([Vec<[f32; 4]>; 3], Vec<u32>) {
    let voxel = |p: [u32; 3]| {
        let v = volume[((p[2] * res[1] + p[1]) * res[0] + p[0]) as usize];
        v.map(|x| x as f32 / 255.0)
    };
    let mut arrays: [Vec<[f32; 4]>; 3] = Default::default();
    let mut occupancy = Vec::new();
    for d in 0..3 {
        let size = match d {
            0 => [res[1], res[2]],
            1 => [res[0], res[2]],
            _ => [res[0], res[1]],
        };
        for level in 0..level_count(res[d]) {
            let span = 1u32 << level;
            for k in 0..level_slices(res[d], level) {
                let (begin, end) = (k * span, ((k + 1) * span).min(res[d]));
                let mut any = false;
                for y in 0..size[1] {
                    for x in 0..size[0] {
                        let (mut optical, mut colour) = (0.0f32, Vec3::ZERO);
                        for j in begin..end {
                            let p = match d {
                                0 => [j, x, y],
                                1 => [x, j, y],
                                _ => [x, y, j],
                            };
                            let v = voxel(p);
                            let a = v[3].clamp(0.0, 1.0);
                            if a > 0.0 {
                                let e = -(1.0 - a).max(1e-6).ln();
                                optical += e;
                                colour += e * Vec3::new(v[0], v[1], v[2]) / a;
                            }
                        }
                        let mut out = [0.0; 4];
                        if optical > 0.0 {
                            let alpha = 1.0 - (-optical / (end - begin) as f32).exp();
                            let c = colour / optical * alpha;
                            out = [c.x, c.y, c.z, alpha];
                        }
                        any |= out[3] >= 0.5 / 255.0;
                        arrays[d].push(out);
                    }
                }
                occupancy.push(any as u32);
            }
        }
    }
    (arrays, occupancy)
}
