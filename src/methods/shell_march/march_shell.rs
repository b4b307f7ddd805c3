//! CPU twin (f64) of `wgsl/shell_march/march_shell.wgsl`: the same algorithm without the BVH,
//! the budget or the fixed-size lists. Per pixel: the intervals of the ray inside every prism
//! (crossings of its triangles and bilinear sides, with the exact inverse map there from the
//! crossing itself; corners of a side in canonical order, so neighbours agree); per interval its
//! samples (the path through (s, t, w) over the step, at least one per w-voxel) and the pieces in
//! which (b, w) is interpolated, each checked against the exact map at two interior points
//! (exact where that misses the tolerance, or where the prism's map folds); then every sample
//! of every interval composited in depth order until the transmittance falls below the cutoff.
//! Empty-space skipping changes no pixel, so the twin samples everything. The kernel finds the
//! exact map at a piece's check points by a few Newton steps from the line's own value
//! (`prism_near`, falling back to mapping the piece exactly where they do not settle); the twin
//! takes the f64 exact inverse there: the same map, to the kernel's rounding.

use glam::{DVec2, DVec3};

use super::filter;
use crate::cpu::decoded_texel::DecodedTexel;
use crate::cpu::prism_map::{self, quadratic_roots, PrismCorners};
use crate::methods::reference::trace_reference::{shade, TraceObject, TraceView, MAX_ALPHA};
use crate::types::ShellFilter;

/// Mirrors MAX_PIECES and MAX_SAMPLES in march_shell.wgsl.
pub(crate) const MAX_PIECES: usize = 8;
const MAX_SAMPLES: f64 = 1048576.0;

/// One object as the twin sees it: the Reference twin's object and the ShellMarch knobs.
pub struct ShellObject {
    /// Prisms, uvs, volumes and lighting (camera-relative f64 corners).
    pub trace: TraceObject,
    /// Sample spacing in voxels.
    pub step: f64,
    /// Interpolation tolerance in voxels.
    pub tolerance: f64,
    /// Per prism: the band of w outside which its texel is transparent ([1, 0]: all of it).
    pub(crate) bands: Vec<[f64; 2]>,
    /// The footprint filter, where the object filters.
    pub(crate) filter: Option<Footprint>,
}

/// An object's footprint filter as the twin sees it.
pub(crate) struct Footprint {
    /// Its texel's levels from 1 on (s and t halved a level), made from level 0 by the twin of
    /// the bake's MIP kernel; its normals' too, with per-pixel lighting.
    levels: Vec<DecodedTexel>,
    normal_levels: Vec<DecodedTexel>,
    filter: ShellFilter,
    /// Per prism: voxels of s and t per world unit (as the kernel reads them).
    density: Vec<f64>,
    /// A pixel's width per unit distance at the image's centre.
    cone: f64,
}

impl Footprint {
    pub(crate) fn of(
        volume: &DecodedTexel,
        normals: Option<&DecodedTexel>,
        filter: ShellFilter,
        density: Vec<f64>,
        cone: f64,
    ) -> Footprint {
        let levels = Self::levels_of(volume, filter.levels);
        let normal_levels = normals.map_or(Vec::new(), |n| Self::levels_of(n, filter.levels));
        Footprint { levels, normal_levels, filter, density, cone }
    }

    /// Levels 1.. of `volume`, each the 2x2 mean of the one above (`cpu::mip_layers`).
    fn levels_of(volume: &DecodedTexel, levels: u32) -> Vec<DecodedTexel> {
        let res = volume.resolution;
        let mut finer: Vec<[f32; 4]> = volume.texels.iter().map(|t| t.map(|v| v as f32)).collect();
        let mut out = Vec::new();
        for l in 1..levels {
            finer = crate::cpu::mip_layers::mip_layers(&finer, filter::level_size(res, l - 1), res[2], true);
            let [w, h] = filter::level_size(res, l);
            let texels = finer.iter().map(|t| t.map(|v| v as f64)).collect();
            out.push(DecodedTexel { resolution: [w, h, res[2]], texels });
        }
        out
    }

    /// The level of prism k's samples on ray `d` (unit; `through`: its unnormalised direction's
    /// length) at distance t, as `footprint_level`.
    fn level(&self, k: usize, through: f64, t: f64) -> f64 {
        filter::level(self.cone / through, t, self.density[k], &self.filter)
    }

    /// The texel at `uvw` at fractional `level`, as `sample_filtered`.
    fn sample(&self, level0: &DecodedTexel, uvw: DVec3, level: f64) -> [f64; 4] {
        Self::mixed(&self.levels, level0, uvw, level)
    }

    /// The normals at `uvw` at fractional `level`.
    fn sample_normals(&self, level0: &DecodedTexel, uvw: DVec3, level: f64) -> [f64; 4] {
        Self::mixed(&self.normal_levels, level0, uvw, level)
    }

    fn mixed(levels: &[DecodedTexel], level0: &DecodedTexel, uvw: DVec3, level: f64) -> [f64; 4] {
        let at = |l: usize| if l == 0 { level0.sample(uvw) } else { levels[l - 1].sample(uvw) };
        let l0 = level.floor();
        let (a, f) = (at(l0 as usize), level - l0);
        if level <= 0.0 || f == 0.0 {
            return a;
        }
        let b = at(l0 as usize + 1);
        std::array::from_fn(|c| a[c] + (b[c] - a[c]) * f)
    }
}

/// Where the ray crosses a prism's boundary, and the map's value there: (b0, b1, b2, w).
pub(crate) type Crossing = (f64, [f64; 4]);

/// Whether the prism map's Jacobian changes sign (or vanishes) over the prism: there the map
/// folds and interpolating it is meaningless. The determinant is linear in the barycentrics
/// (extreme at the corners) and quadratic in w along each corner's edge.
pub fn folds(p: &PrismCorners) -> bool {
    let h = [0, 1, 2].map(|i| p.top[i] - p.bottom[i]);
    let (e1, e2) = (p.bottom[1] - p.bottom[0], p.bottom[2] - p.bottom[0]);
    let (g1, g2) = (h[1] - h[0], h[2] - h[0]);
    let det = |a: DVec3, b: DVec3, c: DVec3| a.dot(b.cross(c));
    let scale = [e1, e2, h[0], h[1], h[2]].iter().map(|v| v.length()).fold(0.0, f64::max).max(1e-300);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for hi_ in h {
        let a0 = det(e1, e2, hi_);
        let a1 = det(g1, e2, hi_) + det(e1, g2, hi_);
        let a2 = det(g1, g2, hi_);
        let f = |w: f64| a0 + w * (a1 + w * a2);
        // The ends of w's range and the parabola's vertex when it lies inside (no allocation:
        // a camera move tests every prism of the shell).
        let vertex = -a1 / (2.0 * a2);
        let inside = a2 != 0.0 && vertex > 0.0 && vertex < 1.0;
        for w in [0.0, 1.0].into_iter().chain(inside.then_some(vertex)) {
            lo = lo.min(f(w));
            hi = hi.max(f(w));
        }
    }
    let zero = 1e-9 * scale * scale * scale;
    !(lo > zero || hi < -zero)
}

/// Twin of `triangle_hit`: (t, u, v) with the hit at a + u (b - a) + v (c - a).
fn triangle_hit(d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    let (u, q) = ((-a).dot(p) / det, (-a).cross(e1));
    let v = d.dot(q) / det;
    (det != 0.0 && u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| (e2.dot(q) / det, u, v))
}

/// Twin of `crossings`: every crossing of the ray with the prism's boundary and with the
/// sections bounding its band, sorted.
pub(crate) fn crossings(d: DVec3, p: &PrismCorners, band: [f64; 2]) -> Vec<Crossing> {
    let mut out = Vec::new();
    let mut section = |w: f64| {
        let q = [0, 1, 2].map(|i| p.bottom[i].lerp(p.top[i], w));
        if let Some((t, u, v)) = triangle_hit(d, q[0], q[1], q[2]) {
            out.push((t, [1.0 - u - v, u, v, w]));
        }
    };
    section(0.0);
    section(1.0);
    if band[0] > 0.0 {
        section(band[0]);
    }
    if band[1] < 1.0 {
        section(band[1]);
    }
    for e in 0..3 {
        let (mut i, mut j) = (e, (e + 1) % 3);
        if p.ids[j] < p.ids[i] {
            (i, j) = (j, e);
        }
        let (q00, q10) = (p.bottom[i], p.bottom[j]);
        let (e10, e00, e11) = (q10 - q00, p.top[i] - q00, p.top[j] - q10);
        let c0 = q00.cross(d).dot(e00);
        let c2 = e10.cross(d).dot(e11 - e00);
        let c1 = q10.cross(d).dot(e11) - c0 - c2;
        for u in quadratic_roots(c0, c1, c2).into_iter().flatten() {
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let (a, b) = (q00 + e10 * u, e00 + (e11 - e00) * u);
            let n = d.cross(b);
            let nn = n.dot(n);
            if nn == 0.0 {
                continue;
            }
            let v = a.cross(d).dot(n) / nn;
            if (0.0..=1.0).contains(&v) {
                let mut c = [0.0, 0.0, 0.0, v];
                c[i] = 1.0 - u;
                c[j] = u;
                out.push((a.cross(b).dot(n) / nn, c));
            }
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The exact inverse map at `x` as (b0, b1, b2, w), if `x` is inside.
pub(crate) fn exact(x: DVec3, p: &PrismCorners) -> Option<[f64; 4]> {
    prism_map::inverse(x, p).map(|(b, w)| [b[0], b[1], b[2], w])
}

fn mix(a: [f64; 4], b: [f64; 4], f: f64) -> [f64; 4] {
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * f)
}

/// (s, t, w) in voxels at map value `c` of a prism with corner uvs `uv`.
pub(crate) fn voxels(uv: &[DVec2; 3], res: [u32; 3], c: [f64; 4]) -> DVec3 {
    let st = uv[0] * c[0] + uv[1] * c[1] + uv[2] * c[2];
    DVec3::new(st.x * res[0] as f64, st.y * res[1] as f64, c[3] * res[2] as f64)
}

fn max3(v: DVec3) -> f64 {
    v.abs().max_element()
}

/// One piece of an interval: its span and the map at both ends, or `None` (sampled exactly).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    pub(crate) ta: f64,
    pub(crate) tb: f64,
    pub(crate) line: Option<([f64; 4], [f64; 4])>,
}

/// The ray's stretch inside one prism, as the kernel holds it.
#[derive(Debug, Clone)]
pub(crate) struct Interval {
    pub(crate) prism: usize,
    pub(crate) t0: f64,
    pub(crate) t1: f64,
    /// Samples at t0 + (k + 1/2) h, k < n.
    pub(crate) n: u64,
    pub(crate) h: f64,
    /// Pieces of the interpolation (0: the exact map at every sample).
    pub(crate) pieces: usize,
    pub(crate) c0: Option<[f64; 4]>,
    pub(crate) c1: [f64; 4],
    /// The MIP level its samples read (0: level 0 alone).
    pub(crate) level: f64,
}

/// How far (voxels) the line from ca to cb strays from the exact map at the thirds of [ta, tb].
fn line_error(d: DVec3, p: &PrismCorners, uv: &[DVec2; 3], res: [u32; 3], (ta, tb): (f64, f64), ca: [f64; 4], cb: [f64; 4]) -> f64 {
    let mut err: f64 = 0.0;
    for f in [1.0 / 3.0, 2.0 / 3.0] {
        match exact(d * (ta + (tb - ta) * f), p) {
            Some(c) => err = err.max(max3(voxels(uv, res, c) - voxels(uv, res, mix(ca, cb, f)))),
            None => return f64::INFINITY,
        }
    }
    err
}

/// Twin of `set_piece`: piece j of `iv`.
pub(crate) fn piece(d: DVec3, o: &ShellObject, iv: &Interval, j: usize) -> Piece {
    let (p, uv, res) = (&o.trace.prisms[iv.prism], &o.trace.uvs[iv.prism], o.trace.volume.resolution);
    let m = iv.pieces;
    if m == 0 {
        return Piece { ta: iv.t0, tb: iv.t1, line: None };
    }
    let at = |j: usize| iv.t0 + (iv.t1 - iv.t0) * j as f64 / m as f64;
    let (ta, tb) = (if j == 0 { iv.t0 } else { at(j) }, if j + 1 == m { iv.t1 } else { at(j + 1) });
    let ca = if j == 0 { iv.c0 } else { exact(d * ta, p) };
    let cb = if j + 1 == m { Some(iv.c1) } else { exact(d * tb, p) };
    let line = match (ca, cb) {
        (Some(a), Some(b)) if m == 1 || line_error(d, p, uv, res, (ta, tb), a, b) <= o.tolerance => Some((a, b)),
        _ => None,
    };
    Piece { ta, tb, line }
}

/// Twin of `add_interval`: [t0, t1] inside prism k (c3: the exact map at its first third), on a
/// ray whose unnormalised direction is `through` long.
#[allow(clippy::too_many_arguments)]
fn interval(d: DVec3, through: f64, o: &ShellObject, k: usize, (t0, t1): (f64, f64), c0: Option<[f64; 4]>, c1: [f64; 4], c3: [f64; 4]) -> Interval {
    let (p, uv, res) = (&o.trace.prisms[k], &o.trace.uvs[k], o.trace.volume.resolution);
    let c6 = exact(d * (t0 + (t1 - t0) * 2.0 / 3.0), p);
    let (v3, v1) = (voxels(uv, res, c3), voxels(uv, res, c1));
    let v0 = c0.map_or(v3, |c| voxels(uv, res, c));
    let v6 = c6.map_or((v3 + v1) * 0.5, |c| voxels(uv, res, c));
    // Filtered, the samples read the footprint's level at the middle, 2^level voxels wide in s, t.
    let level = o.filter.as_ref().map_or(0.0, |f| f.level(k, through, 0.5 * (t0 + t1)));
    let st = 0.5f64.powi(level.floor() as i32);
    let coarse = |v: DVec3| v * DVec3::new(st, st, 1.0);
    let path = max3(coarse(v3 - v0)) + max3(coarse(v6 - v3)) + max3(coarse(v1 - v6));
    let path_w = (v3.z - v0.z).abs() + (v6.z - v3.z).abs() + (v1.z - v6.z).abs();
    let n = (path / o.step).max(path_w).ceil().clamp(1.0, MAX_SAMPLES);
    let mut pieces = 0;
    if !folds(p) && c0.is_some() && c6.is_some() {
        let err = max3(v3 - v0.lerp(v1, 1.0 / 3.0)).max(max3(v6 - v0.lerp(v1, 2.0 / 3.0)));
        pieces = (err / o.tolerance).sqrt().ceil().clamp(1.0, MAX_PIECES as f64) as usize;
    }
    Interval { prism: k, t0, t1, n: n as u64, h: (t1 - t0) / n, pieces, c0, c1, level }
}

/// Twin of `expand_prism`: the intervals of ray `d` (unnormalised, `through` long) inside prism
/// k after `t_near`.
pub(crate) fn intervals(d: DVec3, through: f64, o: &ShellObject, k: usize, t_near: f64) -> Vec<Interval> {
    let (p, band) = (&o.trace.prisms[k], o.bands[k]);
    let mut out = Vec::new();
    if band[0] > band[1] {
        return out;
    }
    let (mut t0, mut c0, mut at_near) = (t_near, None, true);
    for (t1, c1) in crossings(d, p, band) {
        if t1 <= t0 {
            continue;
        }
        let c3 = exact(d * (t0 + (t1 - t0) / 3.0), p).filter(|c| c[3] >= band[0] && c[3] <= band[1]);
        if let Some(c3) = c3 {
            if at_near {
                c0 = exact(d * t0, p);
            }
            out.push(interval(d, through, o, k, (t0, t1), c0, c1, c3));
        }
        (t0, c0, at_near) = (t1, Some(c1), false);
    }
    out
}

/// The map value of sample t of an interval, from its pieces (made as the samples reach them).
fn coords(d: DVec3, o: &ShellObject, iv: &Interval, pieces: &mut Vec<Piece>, t: f64) -> Option<[f64; 4]> {
    if pieces.is_empty() {
        pieces.push(piece(d, o, iv, 0));
    }
    while t >= pieces.last().unwrap().tb && pieces.len() < iv.pieces {
        pieces.push(piece(d, o, iv, pieces.len()));
    }
    let last = pieces.last().unwrap();
    match last.line {
        Some((a, b)) => Some(mix(a, b, (t - last.ta) / (last.tb - last.ta))),
        None => exact(d * t, &o.trace.prisms[iv.prism]),
    }
}

/// Twin of `march_shell.wgsl`: the premultiplied layer (rgb, coverage) of the whole image.
pub fn march_shell(view: &TraceView, objects: &[ShellObject], min_transmittance: f64) -> Vec<[f64; 4]> {
    let mut out = Vec::with_capacity((view.width * view.height) as usize);
    for y in 0..view.height {
        for x in 0..view.width {
            out.push(march_ray(view, objects, view.ray(x, y), view.through(x, y), min_transmittance));
        }
    }
    out
}

fn march_ray(view: &TraceView, objects: &[ShellObject], d: DVec3, through: f64, min_transmittance: f64) -> [f64; 4] {
    let t_near = view.near / d.dot(view.forward);
    let mut t_opaque = f64::INFINITY;
    let mut held = Vec::new();
    for (i, o) in objects.iter().enumerate() {
        for (k, p) in o.trace.prisms.iter().enumerate() {
            if o.trace.opaque_base {
                let n = (p.bottom[1] - p.bottom[0]).cross(p.bottom[2] - p.bottom[0]);
                if let Some(t) = prism_map::ray_triangle(d, p.bottom[0], p.bottom[1], p.bottom[2]) {
                    if d.dot(n) < 0.0 && t > t_near {
                        t_opaque = t_opaque.min(t);
                    }
                }
            }
            held.extend(intervals(d, through, o, k, t_near).into_iter().map(|iv| (i, iv)));
        }
    }
    // Every sample before the first opaque surface, nearest first.
    let mut samples: Vec<(f64, usize, u64)> = Vec::new();
    for (h, (_, iv)) in held.iter().enumerate() {
        samples.extend((0..iv.n).map(|k| (iv.t0 + (k as f64 + 0.5) * iv.h, h, k)).filter(|s| s.0 < t_opaque));
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut pieces: Vec<Vec<Piece>> = vec![Vec::new(); held.len()];
    let (mut rgb, mut transmittance) = (DVec3::ZERO, 1.0);
    for (t, h, _) in samples {
        if transmittance < min_transmittance {
            break;
        }
        let (i, iv) = &held[h];
        let o = &objects[*i];
        let Some(c) = coords(d, o, iv, &mut pieces[h], t) else { continue };
        let uv = o.trace.uvs[iv.prism];
        let st = uv[0] * c[0] + uv[1] * c[1] + uv[2] * c[2];
        let uvw = DVec3::new(st.x, st.y, c[3]);
        let texel = match &o.filter {
            Some(f) => f.sample(&o.trace.volume, uvw, iv.level),
            None => o.trace.volume.sample(uvw),
        };
        let alpha = texel[3].clamp(0.0, MAX_ALPHA);
        if alpha <= 1e-6 {
            continue;
        }
        let mut colour = DVec3::new(texel[0], texel[1], texel[2]) / alpha;
        if let Some(pp) = &o.trace.per_pixel {
            let p = &o.trace.prisms[iv.prism];
            let tn = match &o.filter {
                Some(f) => f.sample_normals(&pp.normals, uvw, iv.level),
                None => pp.normals.sample(uvw),
            };
            colour = shade(view, pp, iv.prism, p, [c[0], c[1], c[2]], tn, d, colour);
        }
        let a = 1.0 - ((1.0 - alpha).ln() * iv.h / o.trace.opacity_length).exp();
        rgb += colour * a * transmittance;
        transmittance *= 1.0 - a;
    }
    let c = view.light_color;
    [rgb.x * c[0], rgb.y * c[1], rgb.z * c[2], 1.0 - transmittance]
}

#[cfg(test)]
mod tests;
