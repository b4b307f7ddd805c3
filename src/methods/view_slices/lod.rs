//! Level of detail of view slicing (`lod: Auto`, after Meyer & Neyret 1998): the plane count
//! and the texel's MIP level from the object's size on screen. Per prism, the world size of a
//! pixel at the prism's nearest depth against the world size of a texel voxel there; the object
//! takes the finest need of all its prisms, so no part of it is drawn coarser than a pixel.

use crate::mesh::shell::Shell;
use glam::DVec3;

/// Planes per pixel of depth extent (or per texel voxel, when a voxel covers more than a
/// pixel): two samples per pixel along the view axis.
pub(crate) const PLANES_PER_SAMPLE: f64 = 2.0;

/// The fewest planes `lod: Auto` draws (unless `planes` is fewer).
pub(crate) const MIN_LOD_PLANES: u32 = 8;

/// What `lod: Auto` chose for an object, with the sizes it chose from (`voltex plan`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LodChoice {
    /// Planes drawn (at most the scene's `planes`).
    pub planes: u32,
    /// MIP level of the texel volume (0: full resolution).
    pub level: u32,
    /// World size of a pixel at the depth that decided, and of the largest and smallest texel
    /// voxel axis there (level 0).
    pub pixel: f64,
    /// The largest texel voxel axis (world units, level 0).
    pub(crate) voxel_max: f64,
    /// The smallest texel voxel axis (world units, level 0).
    pub(crate) voxel_min: f64,
}

/// World lengths of one voxel of a `res` texel along s, t and w over prism `p` (the bottom
/// triangle's texture mapping and the mean height); `None` for a degenerate prism.
fn voxel_sizes(shell: &Shell, p: &crate::types::Prism, res: [u32; 3]) -> Option<[f64; 3]> {
    let v = p.vertices.map(|i| shell.vertices.get(i as usize).copied());
    let (a, b, c) = (v[0]?, v[1]?, v[2]?);
    let pos = |q: [f32; 4]| DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64);
    let (e1, e2) = (pos(b.bottom) - pos(a.bottom), pos(c.bottom) - pos(a.bottom));
    let uv = [[p.uv01[0], p.uv01[1]], [p.uv01[2], p.uv01[3]], [p.uv2[0], p.uv2[1]]].map(|x| x.map(f64::from));
    let (du1, dv1) = (uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]);
    let (du2, dv2) = (uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]);
    let det = du1 * dv2 - du2 * dv1;
    if det.abs() < 1e-12 {
        return None;
    }
    // [dP/du dP/dv] = [e1 e2] inverse([du1 du2; dv1 dv2]).
    let dp_du = (e1 * dv2 - e2 * dv1) / det;
    let dp_dv = (e2 * du1 - e1 * du2) / det;
    let height = [a, b, c].iter().map(|v| (pos(v.top) - pos(v.bottom)).length()).sum::<f64>() / 3.0;
    let sizes = [dp_du.length() / res[0] as f64, dp_dv.length() / res[1] as f64, height / res[2] as f64];
    sizes.iter().all(|s| s.is_finite() && *s > 0.0).then_some(sizes)
}

/// The level of detail of `shell` (camera-relative) seen along `forward` with a focal length of
/// `focal` pixels: the coarsest texel MIP level (below `levels`) whose voxels cover at most a
/// pixel at every prism's nearest depth, and [`PLANES_PER_SAMPLE`] planes per pixel, or per
/// voxel where a voxel is larger, of the depth range, in `MIN_LOD_PLANES..=max_planes`.
pub(crate) fn choose(
    shell: &Shell,
    forward: [f32; 3],
    focal: f64,
    near: f64,
    res: [u32; 3],
    levels: u32,
    max_planes: u32,
) -> LodChoice {
    let n = DVec3::new(forward[0] as f64, forward[1] as f64, forward[2] as f64);
    // The prism needing the finest level: (log2 of its pixel over its largest voxel, pixel, voxels).
    let mut best: Option<(f64, f64, f64, f64)> = None;
    let mut spacing = f64::INFINITY;
    for p in shell.prisms.iter() {
        let Some(v) = voxel_sizes(shell, p, res) else { continue };
        let depth = p.vertices[..3]
            .iter()
            .flat_map(|&i| {
                let sv = &shell.vertices[i as usize];
                [sv.bottom, sv.top]
            })
            .map(|q| n.dot(DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64)))
            .fold(f64::INFINITY, f64::min)
            .max(near);
        let pixel = depth / focal;
        let (v_max, v_min) = (v[0].max(v[1]).max(v[2]), v[0].min(v[1]).min(v[2]));
        // Levels whose voxels still fit in a pixel: 2^level v_max <= pixel.
        let need = (pixel / v_max).log2();
        if best.is_none_or(|b| need < b.0) {
            best = Some((need, pixel, v_max, v_min));
        }
        spacing = spacing.min(pixel.max(v_min) / PLANES_PER_SAMPLE);
    }
    // No prism with a texture mapping: full detail.
    let Some((need, pixel, voxel_max, voxel_min)) = best else {
        return LodChoice { planes: max_planes, level: 0, pixel: 0.0, voxel_max: 0.0, voxel_min: 0.0 };
    };
    let (lo, hi) = shell.depth_range(forward);
    let extent = (hi - lo.max(near)).max(0.0);
    let planes = (extent / spacing).ceil().min(max_planes as f64) as u32;
    LodChoice {
        planes: planes.max(MIN_LOD_PLANES).min(max_planes),
        // A bilinear sample at level l spans 2^(l+1) voxels (the tent over two of its texels),
        // so the filter is a pixel wide at l = need - 1: the nearest level to that (as a GPU's
        // nearest-MIP choice rounds), not the coarsest whose voxel fits in a pixel.
        level: ((need - 1.0).round().max(0.0) as u32).min(levels.saturating_sub(1)),
        pixel,
        voxel_max,
        voxel_min,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::{Prism, ShellVertex};

    /// A 1 x `length` floor seen from the camera (forward +z): x in [-0.5, 0.5], depth in
    /// [`near_depth`, `near_depth` + `length`], uv spanning [0, 1]^2 once, heights 0.25 along -y
    /// (across the view, so the depth range is the floor's).
    fn floor(near_depth: f32, length: f32) -> Shell {
        let corner = |x: f32, z: f32| ShellVertex { bottom: [x, 0.0, z, 1.0], top: [x, -0.25, z, 1.0] };
        let d = near_depth;
        let vertices =
            vec![corner(-0.5, d), corner(0.5, d), corner(-0.5, d + length), corner(0.5, d + length)];
        let prism = |ids: [u32; 3], uv: [[f32; 2]; 3]| Prism {
            vertices: [ids[0], ids[1], ids[2], 0],
            uv01: [uv[0][0], uv[0][1], uv[1][0], uv[1][1]],
            uv2: [uv[2][0], uv[2][1], 0.0, 0.0],
        };
        let prisms = vec![
            prism([0, 1, 2], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
            prism([1, 3, 2], [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        ];
        Shell::from_parts(vertices, prisms, vec![[0.0; 4]; 2])
    }

    const RES: [u32; 3] = [64, 64, 16];
    const FOCAL: f64 = 100.0;

    fn at(near_depth: f32, max_planes: u32) -> LodChoice {
        choose(&floor(near_depth, 4.0), [0.0, 0.0, 1.0], FOCAL, 1e-3, RES, 7, max_planes)
    }

    /// Voxels: 1/64 across (s), 4/64 along the depth (t), 0.25/16 high (w). A pixel at depth z
    /// is z/100: the level is floor(log2(pixel / (4/64))), the planes 4 over half of
    /// max(pixel, 1/64).
    #[test]
    fn the_choice_follows_the_projected_size() {
        let c = at(10.0, 1000);
        assert!((c.voxel_max - 4.0 / 64.0).abs() < 1e-6 && (c.voxel_min - 1.0 / 64.0).abs() < 1e-6, "{c:?}");
        assert!((c.pixel - 0.1).abs() < 1e-6, "{c:?}");
        // Pixel 0.1 = 1.6 voxels along t: level 0; 4 / 0.05 = 80 planes.
        assert_eq!(c.level, 0);
        assert!(c.planes.abs_diff(80) <= 1, "{c:?}");
        // Twice as far: half the planes, one level coarser; and again.
        for (depth, planes, level) in [(20.0, 40, 1), (40.0, 20, 2)] {
            let c = at(depth, 1000);
            assert_eq!(c.level, level, "{c:?}");
            assert!(c.planes.abs_diff(planes) <= 1, "{c:?}");
        }
        // Halving the distance doubles the planes until the clamp.
        let (far, near) = (at(30.0, 1000), at(15.0, 1000));
        assert!(near.planes.abs_diff(2 * far.planes) <= 2, "{far:?} {near:?}");
        assert_eq!(at(2.0, 300).planes, 300);
        assert_eq!(at(1e4, 300).planes, MIN_LOD_PLANES);
        assert_eq!(at(1e4, 300).level, 6, "clamped to the last of 7 levels");
        assert_eq!(at(1e4, 4).planes, 4, "never more than the scene's planes");
        // Closer than a voxel per pixel: two planes per finest voxel (w and s: 1/64), 512.
        assert!(at(0.5, 1000).planes.abs_diff(512) <= 1);
    }
}
