//! Prisms binned into the screen's 8x8-pixel tiles (march_shell.wgsl's workgroups), each tile's
//! list sorted by the prisms' distance from the eye: a pixel walks its tile's list in order,
//! without a traversal (a best-first walk of the BVH per tile, its first version, cost llvmpipe
//! half the frame in barriers and a serial heap).
//!
//! A prism lies in the convex hull of its six corners (every point is a convex combination of
//! them), so the screen box of the projected corners holds every pixel whose ray meets it; it is
//! grown by a pixel against rounding, and a prism with a corner not in front of the near plane
//! takes every tile.

use glam::DVec3;

use crate::methods::view::RayCamera;
use crate::types::{ReferencePrism, ShellVertex};

/// Pixels per tile side: march_shell.wgsl's workgroup size.
pub(crate) const TILE: u32 = 8;

/// The lists march_shell.wgsl reads.
#[derive(Debug, Default, Clone, PartialEq)]
pub(crate) struct TileLists {
    /// Per tile, row by row: its first entry and its entry count.
    pub(crate) tiles: Vec<[u32; 2]>,
    /// Prism indices, tile after tile, each tile's nearest first (ties by index).
    pub(crate) entries: Vec<u32>,
    /// Per prism, two rows: its corner box's minimum with the least distance from the eye of any
    /// point in it (w), and its maximum (w unused); camera-relative, as the vertices.
    pub(crate) bounds: Vec<[f32; 4]>,
}

impl TileLists {
    /// The lists with only the prisms `listed` (order kept).
    pub(crate) fn only(&self, listed: &[bool]) -> TileLists {
        let mut out = TileLists { tiles: Vec::with_capacity(self.tiles.len()), entries: Vec::new(), bounds: self.bounds.clone() };
        for &[first, count] in &self.tiles {
            let start = out.entries.len() as u32;
            let entries = &self.entries[first as usize..(first + count) as usize];
            out.entries.extend(entries.iter().filter(|&&p| listed[p as usize]));
            let kept = out.entries.len() as u32 - start;
            out.tiles.push([if kept > 0 { start } else { 0 }, kept]);
        }
        out
    }
}

/// Bins `prisms` (corners in `vertices`, camera-relative) into the tiles of a `size` image seen
/// by `camera`.
pub(crate) fn bin(prisms: &[ReferencePrism], vertices: &[ShellVertex], camera: &RayCamera, size: (u32, u32)) -> TileLists {
    let tiles = (size.0.div_ceil(TILE), size.1.div_ceil(TILE));
    let forward = camera.right.cross(camera.up).normalize() * -1.0;
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let mut bounds = Vec::with_capacity(2 * prisms.len());
    // (tile, near, prism) for every tile a prism's screen box covers.
    let mut keyed: Vec<(u32, f32, u32)> = Vec::new();
    for (index, p) in prisms.iter().enumerate() {
        let corners: Vec<DVec3> =
            p.vertices[..3].iter().flat_map(|&v| [v3(vertices[v as usize].bottom), v3(vertices[v as usize].top)]).collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for c in &corners {
            lo = lo.min(*c);
            hi = hi.max(*c);
        }
        // Grown as the Reference's BVH boxes are: f32 rounding in the slab test never loses a prism.
        let pad = 1e-5 * (hi - lo).max_element() + 1e-7;
        let (lo, hi) = (lo - DVec3::splat(pad), hi + DVec3::splat(pad));
        let near = DVec3::ZERO.clamp(lo, hi).length();
        bounds.push([lo.x as f32, lo.y as f32, lo.z as f32, near as f32]);
        bounds.push([hi.x as f32, hi.y as f32, hi.z as f32, 0.0]);
        let Some((x0, x1, y0, y1)) = screen_box(&corners, camera, forward, size) else {
            continue;
        };
        for ty in y0 / TILE..=y1 / TILE {
            for tx in x0 / TILE..=x1 / TILE {
                keyed.push((ty * tiles.0 + tx, near as f32, index as u32));
            }
        }
    }
    keyed.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut lists = TileLists {
        tiles: vec![[0, 0]; (tiles.0 * tiles.1) as usize],
        entries: keyed.iter().map(|k| k.2).collect(),
        bounds,
    };
    for (i, k) in keyed.iter().enumerate() {
        let tile = &mut lists.tiles[k.0 as usize];
        if tile[1] == 0 {
            tile[0] = i as u32;
        }
        tile[1] += 1;
    }
    lists
}

/// The pixels (inclusive ranges of x and y) whose centres' rays may meet the hull of `corners`,
/// a pixel more on each side; every pixel where a corner is not in front of the near plane; None
/// where the hull is off screen.
fn screen_box(corners: &[DVec3], camera: &RayCamera, forward: DVec3, size: (u32, u32)) -> Option<(u32, u32, u32, u32)> {
    let (w, h) = (size.0 as f64, size.1 as f64);
    let all = Some((0, size.0 - 1, 0, size.1 - 1));
    let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for c in corners {
        let z = c.dot(forward);
        if z.is_nan() || z <= camera.near {
            return all;
        }
        // A ray through screen point (sx, sy) is forward + sx right + sy up; pixel x's centre is
        // at sx = 2 (x + 0.5) / w - 1, pixel y's at sy = 1 - 2 (y + 0.5) / h.
        let sx = c.dot(camera.right) / (z * camera.right.length_squared());
        let sy = c.dot(camera.up) / (z * camera.up.length_squared());
        let (x, y) = ((sx + 1.0) * 0.5 * w - 0.5, (1.0 - sy) * 0.5 * h - 0.5);
        x_lo = x_lo.min(x);
        x_hi = x_hi.max(x);
        y_lo = y_lo.min(y);
        y_hi = y_hi.max(y);
    }
    let (x0, x1) = ((x_lo - 1.0).ceil().max(0.0), (x_hi + 1.0).floor().min(w - 1.0));
    let (y0, y1) = ((y_lo - 1.0).ceil().max(0.0), (y_hi + 1.0).floor().min(h - 1.0));
    (x0 <= x1 && y0 <= y1).then_some((x0 as u32, x1 as u32, y0 as u32, y1 as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(p: DVec3, top: DVec3) -> ShellVertex {
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        ShellVertex { bottom: f(p), top: f(top) }
    }

    fn camera() -> RayCamera {
        // Looking down -z; a 90 degree field of view.
        RayCamera { eye: DVec3::ZERO, right: DVec3::X, up: DVec3::Y, near: 0.01, far: 100.0 }
    }

    fn prism(first: u32) -> ReferencePrism {
        ReferencePrism { vertices: [first, first + 1, first + 2, 0], ..Default::default() }
    }

    /// A small prism around the view direction at depth `z`, shifted by `dx` (at unit depth).
    fn small(z: f64, dx: f64) -> Vec<ShellVertex> {
        [(0.0, 0.0), (0.01, 0.0), (0.0, 0.01)]
            .map(|(x, y)| vertex(DVec3::new((dx + x) * z, y * z, -z), DVec3::new((dx + x) * z, y * z, -z - 0.1)))
            .to_vec()
    }

    #[test]
    fn lists_hold_the_tiles_a_prism_covers_nearest_first() {
        let mut vertices = small(5.0, 0.0);
        vertices.extend(small(2.0, 0.0));
        vertices.extend(small(3.0, 0.9));
        let lists = bin(&[prism(0), prism(3), prism(6)], &vertices, &camera(), (64, 64));
        assert_eq!(lists.tiles.len(), 64);
        // Screen centre: pixels 31-32; the first two prisms fall in tiles (3..=4, 3..=4).
        let centre = lists.tiles[3 * 8 + 3];
        let listed = &lists.entries[centre[0] as usize..(centre[0] + centre[1]) as usize];
        assert_eq!(listed, [1, 0], "nearest first");
        // The third lies near the right edge (sx 0.9: pixel ~60), not in the centre's tiles.
        let edge = lists.tiles[3 * 8 + 7];
        assert_eq!(&lists.entries[edge[0] as usize..(edge[0] + edge[1]) as usize], [2]);
        // Least distances: 2 for the second, about 4 for the third (off to the side), 5 for the first.
        assert!(lists.bounds[2][3] < lists.bounds[4][3] && lists.bounds[4][3] < lists.bounds[0][3]);
        // Leaving the nearest out keeps the others in order.
        let kept = lists.only(&[true, false, true]);
        let centre = kept.tiles[3 * 8 + 3];
        assert_eq!(&kept.entries[centre[0] as usize..(centre[0] + centre[1]) as usize], [0]);
        assert_eq!(kept.tiles[3 * 8 + 7][1], 1);
    }

    #[test]
    fn a_prism_through_the_near_plane_takes_every_tile_and_one_behind_none() {
        let through = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.1, 0.0, -1.0), DVec3::new(0.0, 0.1, -1.0)]
            .map(|p| vertex(p, p - DVec3::Z * 0.1))
            .to_vec();
        let lists = bin(&[prism(0)], &through, &camera(), (20, 12));
        assert_eq!(lists.tiles.len(), 6);
        assert!(lists.tiles.iter().all(|t| t[1] == 1));
        let off = small(2.0, 3.0);
        let lists = bin(&[prism(0)], &off, &camera(), (20, 12));
        assert!(lists.entries.is_empty());
    }
}
