//! The `Tiles` compositor of ViewSlices: its buffers, and the CPU twins of its kernels
//! (`wgsl/shared/tiles.wgsl`, `bin_slices.wgsl`, `scan_tiles.wgsl`, `fill_tiles.wgsl`,
//! `composite_tiles.wgsl`). Geometry in f32 with the same arithmetic as the WGSL, shading in f64.
//!
//! The slice triangles (plane by plane, back to front, as `emit_slices` wrote them) are projected
//! to pixels and binned into the 8 x 8 pixel tiles they touch. A tile's list has one segment per block of 32
//! planes, so a pixel walks the segments front to back; within a segment it keeps, per plane, the
//! one triangle covering it (the slices of one plane do not overlap), so the order in which atomics
//! filled the segment does not matter. Each pixel composites its fragments front to back in
//! registers and stops once opaque (texel coordinates from per-triangle affine functions of the
//! pixel, exact on a view plane). A segment whose
//! entries did not fit the lists is composited from every triangle of its planes.

use crate::methods::reference::trace_reference::DecodedTexel;
use crate::types::{FrameParams, SliceVertex, TileAttributes, TileParams, TileTriangle};

/// Tile side in pixels (`TILE_SIZE` in `wgsl/shared/tiles.wgsl`).
pub(crate) const TILE_SIZE: u32 = 8;
/// Planes per list segment (`TILE_PLANES`): the per-pixel slots of `composite_tiles`.
pub(crate) const TILE_PLANES: u32 = 32;
/// Transmittance below which a pixel stops (`MIN_TRANSMITTANCE` in `composite_tiles.wgsl`).
pub const MIN_TRANSMITTANCE: f64 = 1e-4;
/// Largest triangle index an entry can hold (`t << 5 | slot` in a u32).
pub const MAX_TRIANGLES: u64 = 1 << 27;

/// Tiles and segments of an output of `size` for a chunk of `planes` planes.
pub fn tile_params(size: (u32, u32), planes: u32, entry_capacity: u32) -> TileParams {
    TileParams {
        tiles_x: size.0.div_ceil(TILE_SIZE),
        tiles_y: size.1.div_ceil(TILE_SIZE),
        blocks: planes.div_ceil(TILE_PLANES),
        entry_capacity,
        width: size.0,
        height: size.1,
        _pad: [0; 2],
    }
}

fn mul(m: &[[f32; 4]; 4], p: [f32; 3]) -> [f32; 4] {
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// Pixel position (y down) and depth of a camera-relative point.
pub(crate) fn project_to_pixels(p: [f32; 3], view_proj: &[[f32; 4]; 4], size: [f32; 2]) -> [f32; 3] {
    let c = mul(view_proj, p);
    let ndc = [c[0] / c[3], c[1] / c[3], c[2] / c[3]];
    [(ndc[0] * 0.5 + 0.5) * size[0], (0.5 - ndc[1] * 0.5) * size[1], ndc[2]]
}

/// Twice the signed area of the triangle `a b c`.
pub(crate) fn tile_area(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> f32 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The edge function of `a -> b` as coefficients (x, y, constant), from the endpoints in
/// canonical order, negated if they were swapped.
pub(crate) fn tile_edge(a: [f32; 2], b: [f32; 2]) -> [f32; 3] {
    let swap = a[1] > b[1] || (a[1] == b[1] && a[0] > b[0]);
    let (lo, hi) = if swap { (b, a) } else { (a, b) };
    let n = [lo[1] - hi[1], hi[0] - lo[0]];
    let e = [n[0], n[1], -(n[0] * lo[0] + n[1] * lo[1])];
    if swap {
        e.map(|v| -v)
    } else {
        e
    }
}

/// The edge oriented so the inside is positive, `w` 1 when the inside owns centres on it.
pub(crate) fn tile_oriented_edge(e: [f32; 3], orient: f32) -> [f32; 4] {
    let n = e.map(|v| v * orient);
    let owns = n[0] > 0.0 || (n[0] == 0.0 && n[1] > 0.0);
    [n[0], n[1], n[2], if owns { 1.0 } else { -1.0 }]
}

/// Twin of `tile_triangle`: corners in pixels with their depth.
pub(crate) fn tile_triangle(
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
    plane: u32,
    tiles: [u32; 2],
    size: [f32; 2],
) -> TileTriangle {
    let (a2, b2, c2) = ([a[0], a[1]], [b[0], b[1]], [c[0], c[1]]);
    let area = tile_area(a2, b2, c2);
    let orient = if area > 0.0 { 1.0 } else { -1.0 };
    let mut t = TileTriangle {
        e0: tile_oriented_edge(tile_edge(b2, c2), orient),
        e1: tile_oriented_edge(tile_edge(c2, a2), orient),
        e2: tile_oriented_edge(tile_edge(a2, b2), orient),
        tiles: [1, 1, 0, 0],
        depth: (a[2] + b[2] + c[2]) / 3.0,
        plane,
        _pad: [0; 2],
    };
    let lo = [0, 1].map(|i| a[i].min(b[i]).min(c[i]) - 0.5);
    let hi = [0, 1].map(|i| a[i].max(b[i]).max(c[i]) - 0.5);
    if area.abs() > 0.0 && hi[0] >= 0.0 && hi[1] >= 0.0 && lo[0] <= size[0] && lo[1] <= size[1] {
        let p0 = [0, 1].map(|i| lo[i].floor().clamp(0.0, size[i] - 1.0) as u32 / TILE_SIZE);
        let p1 =
            [0, 1].map(|i| (hi[i].ceil().clamp(0.0, size[i] - 1.0) as u32 / TILE_SIZE).min(tiles[i] - 1));
        t.tiles = [p0[0], p0[1], p1[0], p1[1]];
    }
    t
}

fn tile_edge_touches(e: &[f32; 4], x: u32, y: u32) -> bool {
    let lo = [(x * TILE_SIZE) as f32 + 0.5, (y * TILE_SIZE) as f32 + 0.5];
    let hi = lo.map(|v| v + (TILE_SIZE - 1) as f32);
    let corner = [if e[0] > 0.0 { hi[0] } else { lo[0] }, if e[1] > 0.0 { hi[1] } else { lo[1] }];
    e[0] * corner[0] + e[1] * corner[1] + e[2] >= -(e[0].abs() + e[1].abs()) / 1024.0
}

/// Twin of `tile_touches`: whether the triangle may cover a pixel centre of tile (x, y).
pub(crate) fn tile_touches(t: &TileTriangle, x: u32, y: u32) -> bool {
    [&t.e0, &t.e1, &t.e2].iter().all(|e| tile_edge_touches(e, x, y))
}

/// Twin of `tile_attributes_of`: texel coordinates as an affine function of the pixel position.
pub(crate) fn tile_attributes_of(
    a: [f32; 2],
    b: [f32; 2],
    c: [f32; 2],
    fa: [f32; 3],
    fb: [f32; 3],
    fc: [f32; 3],
) -> TileAttributes {
    let d1 = [b[0] - a[0], b[1] - a[1]];
    let d2 = [c[0] - a[0], c[1] - a[1]];
    let det = d1[0] * d2[1] - d1[1] * d2[0];
    let inv = if det != 0.0 { 1.0 / det } else { 0.0 };
    let f1: [f32; 3] = std::array::from_fn(|i| fb[i] - fa[i]);
    let f2: [f32; 3] = std::array::from_fn(|i| fc[i] - fa[i]);
    let dx: [f32; 3] = std::array::from_fn(|i| (f1[i] * d2[1] - f2[i] * d1[1]) * inv);
    let dy: [f32; 3] = std::array::from_fn(|i| (f2[i] * d1[0] - f1[i] * d2[0]) * inv);
    TileAttributes {
        at_a: [fa[0], fa[1], fa[2], a[0]],
        d_x: [dx[0], dx[1], dx[2], a[1]],
        d_y: [dy[0], dy[1], dy[2], 0.0],
    }
}

fn tile_edge_inside(e: &[f32; 4], p: [f32; 2]) -> Option<f32> {
    let v = e[0] * p[0] + e[1] * p[1] + e[2];
    (v > 0.0 || (v == 0.0 && e[3] > 0.0)).then_some(v)
}

/// Barycentrics of pixel centre `p` in the triangle, `None` when it is not covered.
pub fn tile_cover(t: &TileTriangle, p: [f32; 2]) -> Option<[f32; 3]> {
    let e = [tile_edge_inside(&t.e0, p)?, tile_edge_inside(&t.e1, p)?, tile_edge_inside(&t.e2, p)?];
    let sum = e[0] + e[1] + e[2];
    Some(e.map(|v| v / sum))
}

/// The tile range of a binned triangle, `None` when it covers no pixel.
pub(crate) fn tile_range(t: &TileTriangle) -> Option<[u32; 4]> {
    (t.tiles[0] <= t.tiles[2] && t.tiles[1] <= t.tiles[3]).then_some(t.tiles)
}

/// The plane whose vertex range (ends in `plane_ends`) holds vertex `v`.
fn plane_of(plane_ends: &[u32], v: u32) -> u32 {
    plane_ends.partition_point(|&end| end <= v) as u32
}

/// Twin of `bin_slices`: the projected triangles, their texel coordinates, and the triangle count
/// of every segment (`(tile_y * tiles_x + tile_x) * blocks + block`).
pub fn bin_slices(
    frame: &FrameParams,
    params: &TileParams,
    vertices: &[SliceVertex],
    plane_ends: &[u32],
) -> (Vec<TileTriangle>, Vec<TileAttributes>, Vec<u32>) {
    let size = [params.width as f32, params.height as f32];
    let tiles = [params.tiles_x, params.tiles_y];
    let mut counts = vec![0u32; (params.tiles_x * params.tiles_y * params.blocks) as usize];
    let mut triangles = Vec::with_capacity(vertices.len() / 3);
    let mut attributes = Vec::with_capacity(vertices.len() / 3);
    for (t, tri) in vertices.chunks_exact(3).enumerate() {
        let p: [[f32; 3]; 3] = std::array::from_fn(|i| {
            let v = tri[i].position;
            project_to_pixels([v[0], v[1], v[2]], &frame.view_proj, size)
        });
        let plane = plane_of(plane_ends, 3 * t as u32).min(plane_ends.len().max(1) as u32 - 1);
        let tt = tile_triangle(p[0], p[1], p[2], plane, tiles, size);
        if let Some(r) = tile_range(&tt) {
            for y in r[1]..=r[3] {
                for x in (r[0]..=r[2]).filter(|&x| tile_touches(&tt, x, y)) {
                    counts[((y * params.tiles_x + x) * params.blocks + plane / TILE_PLANES) as usize] += 1;
                }
            }
        }
        triangles.push(tt);
        let uvw = |i: usize| [tri[i].uvw[0], tri[i].uvw[1], tri[i].uvw[2]];
        let xy = |i: usize| [p[i][0], p[i][1]];
        attributes.push(tile_attributes_of(xy(0), xy(1), xy(2), uvw(0), uvw(1), uvw(2)));
    }
    (triangles, attributes, counts)
}

/// Twin of `scan_tiles`: where each segment starts.
pub fn scan_tiles(counts: &[u32]) -> Vec<u32> {
    let mut running = 0u32;
    counts
        .iter()
        .map(|&c| {
            let start = running;
            running += c;
            start
        })
        .collect()
}

/// Twin of `fill_tiles`: each segment's end (what the kernel leaves in `tile_cursors`) and the
/// entries (`t << 5 | plane % 32`), each segment's in triangle order (the kernel's order within a
/// segment depends on its atomics). Entries at or past `entry_capacity` are dropped.
pub fn fill_tiles(params: &TileParams, triangles: &[TileTriangle], starts: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let mut cursors = starts.to_vec();
    let ranges: Vec<Option<[u32; 4]>> = triangles.iter().map(tile_range).collect();
    let area = |r: &[u32; 4]| ((r[2] - r[0] + 1) * (r[3] - r[1] + 1)) as usize;
    let total: usize = ranges.iter().flatten().map(area).sum();
    let mut entries = vec![0u32; total.min(params.entry_capacity as usize)];
    for ((t, tri), r) in triangles.iter().enumerate().zip(ranges) {
        let Some(r) = r else { continue };
        for y in r[1]..=r[3] {
            for x in (r[0]..=r[2]).filter(|&x| tile_touches(tri, x, y)) {
                let seg = ((y * params.tiles_x + x) * params.blocks + tri.plane / TILE_PLANES) as usize;
                let at = cursors[seg] as usize;
                cursors[seg] += 1;
                if let Some(e) = entries.get_mut(at) {
                    *e = ((t as u32) << 5) | (tri.plane % TILE_PLANES);
                }
            }
        }
    }
    (cursors, entries)
}

/// What `composite_tiles` reads, for its twin (lighting `Baked` only: the per-pixel frames are
/// `draw_slices`' own code, checked by the Tiles-against-Raster images).
pub struct TileFrame<'a> {
    pub(crate) frame: &'a FrameParams,
    pub(crate) params: TileParams,
    pub(crate) spacing: f32,
    pub(crate) opacity_length: f32,
    pub(crate) vertices: &'a [SliceVertex],
    pub(crate) plane_ends: &'a [u32],
    pub(crate) vertex_count: u32,
    pub(crate) triangles: &'a [TileTriangle],
    /// Segment ends (after `fill_tiles`).
    pub(crate) cursors: &'a [u32],
    pub(crate) entries: &'a [u32],
    pub(crate) volume: &'a DecodedTexel,
    /// The depth buffer (row-major), `None` for all 1.0.
    pub(crate) depth: Option<&'a [f32]>,
}

/// The premultiplied fragment of triangle `t` at barycentrics `bary` (`slice_fragment`, baked).
fn tile_fragment(f: &TileFrame, t: usize, bary: [f32; 3]) -> [f64; 4] {
    let v = &f.vertices[3 * t..3 * t + 3];
    let mix = |g: &dyn Fn(&SliceVertex) -> [f32; 4]| -> [f64; 3] {
        std::array::from_fn(|c| (0..3).map(|i| bary[i] as f64 * g(&v[i])[c] as f64).sum())
    };
    let uvw = mix(&|v| v.uvw);
    let rel = mix(&|v| v.position);
    let texel = f.volume.sample(glam::DVec3::from(uvw));
    let len = (rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]).sqrt();
    let fw = f.frame.forward;
    let cos = (rel[0] * fw[0] as f64 + rel[1] * fw[1] as f64 + rel[2] * fw[2] as f64) / len;
    let step = f.spacing as f64 / cos.max(1e-4);
    let a = texel[3].clamp(0.0, 1.0);
    let corrected = 1.0 - (1.0 - a.min(0.999999)).powf(step / f.opacity_length as f64);
    let k = if a > 1e-6 { corrected / a } else { 0.0 };
    let l = f.frame.light_color;
    [texel[0] * k * l[0] as f64, texel[1] * k * l[1] as f64, texel[2] * k * l[2] as f64, corrected]
}

/// Twin of `composite_tiles`: the premultiplied layer, row-major.
pub fn composite_tiles(f: &TileFrame) -> Vec<[f32; 4]> {
    let p = &f.params;
    let capacity = p.entry_capacity as usize;
    let mut layer = vec![[0.0f32; 4]; (p.width * p.height) as usize];
    for py in 0..p.height {
        for px in 0..p.width {
            let tile = (py / TILE_SIZE) * p.tiles_x + px / TILE_SIZE;
            let centre = [px as f32 + 0.5, py as f32 + 0.5];
            let behind = f.depth.map_or(1.0, |d| d[(py * p.width + px) as usize]);
            let (mut rgb, mut transmittance) = ([0.0f64; 3], 1.0f64);
            for block in (0..p.blocks).rev() {
                if transmittance <= MIN_TRANSMITTANCE {
                    break;
                }
                let mut slots = [None; TILE_PLANES as usize];
                let seg = (tile * p.blocks + block) as usize;
                let end = f.cursors[seg] as usize;
                let start = if seg == 0 { 0 } else { f.cursors[seg - 1] as usize };
                let mut take = |t: usize, slot: usize| {
                    if tile_cover(&f.triangles[t], centre).is_some() {
                        slots[slot] = Some(t);
                    }
                };
                if end <= capacity {
                    for &e in &f.entries[start..end] {
                        take((e >> 5) as usize, (e & 31) as usize);
                    }
                } else {
                    let first = block * TILE_PLANES;
                    let last = (first + TILE_PLANES).min(f.plane_ends.len() as u32);
                    for k in first..last {
                        let begin = if k == 0 { 0 } else { f.plane_ends[k as usize - 1] } / 3;
                        let finish = f.plane_ends[k as usize].min(f.vertex_count) / 3;
                        for t in begin..finish {
                            take(t as usize, (k - first) as usize);
                        }
                    }
                }
                for t in slots.iter().rev().flatten() {
                    if transmittance <= MIN_TRANSMITTANCE {
                        break;
                    }
                    let tri = &f.triangles[*t];
                    // The rasteriser's `Less` (NaN fails).
                    if tri.depth.partial_cmp(&behind) != Some(std::cmp::Ordering::Less) {
                        continue;
                    }
                    let bary = tile_cover(tri, centre).expect("covered");
                    let c = tile_fragment(f, *t, bary);
                    for i in 0..3 {
                        rgb[i] += transmittance * c[i];
                    }
                    transmittance *= 1.0 - c[3];
                }
            }
            let at = (py * p.width + px) as usize;
            layer[at] = [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, (1.0 - transmittance) as f32];
        }
    }
    layer
}

/// The twin's layer of a `Tiles` object as a frame rendered it (baked lighting, one chunk):
/// `read` returns a buffer of the object's graph instance as the kernels left it
/// (`slice_vertices`, `plane_cursors`, `draw_args`, `tile_triangles`, `tile_cursors`,
/// `tile_entries`), `texel` is its texel volume (resolution, rgba8 bytes of level 0, x fastest),
/// `depth` the opaque surfaces' depth (row-major; `None`: all 1.0).
pub fn composite_tiles_frame(
    frame: &FrameParams,
    plan: &super::ViewSlicesPlan,
    opacity_length: f32,
    read: impl Fn(&str) -> Vec<u8>,
    texel: ([u32; 3], &[u8]),
    depth: Option<&[f32]>,
) -> Vec<[f32; 4]> {
    fn pod<T: bytemuck::Pod>(bytes: Vec<u8>) -> Vec<T> {
        let n = bytes.len() / std::mem::size_of::<T>() * std::mem::size_of::<T>();
        bytemuck::pod_collect_to_vec(&bytes[..n])
    }
    let params = tile_params(plan.size, plan.sweep.plane_count, plan.tile_entries[0]);
    let vertex_count = pod::<crate::types::DrawIndirect>(read("draw_args"))[0].vertex_count;
    let vertices: Vec<SliceVertex> = pod(read("slice_vertices"));
    let mut plane_ends: Vec<u32> = pod(read("plane_cursors"));
    plane_ends.truncate(plan.sweep.plane_count as usize);
    let ([w, h, d], bytes) = texel;
    let volume = DecodedTexel {
        resolution: [w, h, d],
        texels: bytes.chunks_exact(4).map(|b| std::array::from_fn(|c| b[c] as f64 / 255.0)).collect(),
    };
    composite_tiles(&TileFrame {
        frame,
        params,
        spacing: plan.sweep.spacing,
        opacity_length,
        vertices: &vertices[..(vertex_count as usize).min(vertices.len())],
        plane_ends: &plane_ends,
        vertex_count,
        triangles: &pod::<TileTriangle>(read("tile_triangles")),
        cursors: &pod::<u32>(read("tile_cursors")),
        entries: &pod::<u32>(read("tile_entries")),
        volume: &volume,
        depth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> TileTriangle {
        tile_triangle(
            [a[0], a[1], 0.5],
            [b[0], b[1], 0.5],
            [c[0], c[1], 0.5],
            0,
            [40u32.div_ceil(TILE_SIZE), 24u32.div_ceil(TILE_SIZE)],
            [40.0, 24.0],
        )
    }

    /// Pixel centres on an edge or a vertex shared by triangles are covered exactly once, in
    /// either winding: a fan of six triangles around a pixel centre, and a split square.
    #[test]
    fn shared_edges_and_vertices_cover_once() {
        let c = [8.5, 8.5];
        let ring: Vec<[f32; 2]> = (0..6)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 6.0;
                [c[0] + 5.0 * a.cos(), c[1] + 5.0 * a.sin()]
            })
            .collect();
        for flip in [false, true] {
            let fan: Vec<TileTriangle> = (0..6)
                .map(|i| {
                    let (a, b) = (ring[i], ring[(i + 1) % 6]);
                    if flip {
                        tri(c, b, a)
                    } else {
                        tri(c, a, b)
                    }
                })
                .collect();
            for p in [c, ring[0], [c[0] + 2.0, c[1]], [c[0], c[1] + 1.0], [c[0] - 2.0, c[1]]] {
                let inside_ring = (p[0] - c[0]).hypot(p[1] - c[1]) < 4.0;
                let n = fan.iter().filter(|t| tile_cover(t, p).is_some()).count();
                assert_eq!(n, inside_ring as usize, "{p:?} flip {flip}");
            }
        }
        // A square split along its diagonal, whose corners and edges lie on pixel centres.
        let (a, b, cc, d) = ([2.5, 2.5], [6.5, 2.5], [6.5, 6.5], [2.5, 6.5]);
        let halves = [tri(a, b, cc), tri(a, cc, d)];
        let mut covered = 0;
        for y in 0..10 {
            for x in 0..10 {
                let p = [x as f32 + 0.5, y as f32 + 0.5];
                let n = halves.iter().filter(|t| tile_cover(t, p).is_some()).count();
                assert!(n <= 1, "{p:?} covered twice");
                covered += n;
            }
        }
        // 5 x 5 centres on the closed square, of which the half-open rule keeps 4 x 4.
        assert_eq!(covered, 16);
    }

    #[test]
    fn tile_ranges_hold_every_covered_pixel() {
        for t in [
            tri([15.6, 3.0], [16.4, 3.0], [16.0, 20.0]),
            tri([-30.0, -5.0], [70.0, 10.0], [0.0, 60.0]),
            tri([31.5, 15.5], [32.5, 15.5], [32.0, 16.5]),
        ] {
            let r = tile_range(&t).unwrap();
            for y in 0..24u32 {
                for x in 0..40u32 {
                    if tile_cover(&t, [x as f32 + 0.5, y as f32 + 0.5]).is_some() {
                        let (tx, ty) = (x / TILE_SIZE, y / TILE_SIZE);
                        assert!(
                            tx >= r[0] && tx <= r[2] && ty >= r[1] && ty <= r[3],
                            "{x},{y} outside {r:?}"
                        );
                    }
                }
            }
        }
        assert_eq!(tile_range(&tri([50.0, 1.0], [60.0, 1.0], [55.0, 9.0])), None);
        assert_eq!(tile_range(&tri([1.0, 1.0], [5.0, 5.0], [9.0, 9.0])), None);
    }
}
