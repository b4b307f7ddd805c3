//! CPU twin (f64) of `wgsl/export/resample_world.wgsl`: a textured object's world voxels, leaf by
//! leaf. Per voxel, `samples^3` sub-points spread over its cell; per sub-point, every prism listed
//! for the leaf maps it back to (s, t, w) by the exact inverse prism map
//! (`cpu::prism_map::inverse`, the Reference's) and the texel is filtered trilinearly there; the
//! first prism that holds it counts (a point on a side two prisms share counts once). The voxel
//! holds the extinction whose transmittance across it is the sub-points' mean (at most their
//! mean extinction) and the opacity-weighted colour.

use glam::DVec3;

use crate::cpu::decoded_texel::DecodedTexel;
use crate::cpu::prism_map::{self, PrismCorners};
use crate::render::export::world::{WorldShell, LEAF_VOXELS};

/// As the Reference's trace: opacity stays below 1, and a fainter sample adds nothing.
const MAX_ALPHA: f64 = 0.999999;
const MIN_ALPHA: f64 = 1e-6;

/// Twin of the kernel: per leaf of `shell`, 512 voxels in OpenVDB's order (x slowest, z fastest),
/// each (extinction per world unit, colour); `texel` the baked volume ([`world::texel`]: x
/// fastest, then y, then z).
///
/// [`world::texel`]: crate::render::export::world::texel
pub fn resample_world(shell: &WorldShell, texel: &[[f32; 4]]) -> Vec<[f64; 4]> {
    let texel = DecodedTexel {
        resolution: shell.request.resolution,
        texels: texel.iter().map(|v| v.map(f64::from)).collect(),
    };
    let s = &shell.surface;
    let origin = shell.anchor_world();
    let prisms: Vec<PrismCorners> = s
        .triangles
        .iter()
        .map(|&ids| {
            let v = ids.map(|i| i as usize);
            PrismCorners {
                bottom: v.map(|i| s.positions[i] - origin),
                top: v.map(|i| s.positions[i] + s.heights[i] - origin),
                ids,
            }
        })
        .collect();
    let n = shell.samples as usize;
    let mut out = Vec::with_capacity(shell.leaves.len() * LEAF_VOXELS);
    for (k, leaf) in shell.leaves.iter().enumerate() {
        let list = &shell.prism_ids[shell.firsts[k] as usize..shell.firsts[k + 1] as usize];
        for m in 0..LEAF_VOXELS {
            let ijk = *leaf + glam::IVec3::new((m >> 6) as i32, ((m >> 3) & 7) as i32, (m & 7) as i32);
            let centre = (ijk - shell.anchor).as_dvec3() * shell.voxel;
            let (mut sigma, mut covered, mut emitted) = (0.0, 0.0, DVec3::ZERO);
            for q in 0..n * n * n {
                let sub =
                    (DVec3::new((q % n) as f64, (q / n % n) as f64, (q / (n * n)) as f64) + 0.5) / n as f64;
                let p = centre + (sub - 0.5) * shell.voxel;
                for &t in list {
                    let Some((b, w)) = prism_map::inverse(p, &prisms[t as usize]) else { continue };
                    let uv = s.corner_uvs[t as usize];
                    let st = uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2];
                    let v = texel.sample(DVec3::new(st.x, st.y, w));
                    let a = v[3].clamp(0.0, MAX_ALPHA);
                    if a > MIN_ALPHA {
                        let s_k = -(1.0 - a).ln() / shell.opacity_length;
                        let opacity = -(-s_k * shell.voxel).exp_m1();
                        sigma += s_k;
                        covered += opacity;
                        emitted += DVec3::new(v[0], v[1], v[2]) / a * opacity;
                    }
                    break;
                }
            }
            let count = (n * n * n) as f64;
            let density = (sigma / count).min(-(-covered / count).ln_1p() / shell.voxel);
            let colour = if covered > 0.0 { emitted / covered } else { DVec3::ZERO };
            out.push([density, colour.x, colour.y, colour.z]);
        }
    }
    out
}
