//! A baked volume's level 0 decoded to f64, and the volume sampler's trilinear filtering: what
//! the CPU twins sample (the Reference's and ShellMarch's traces, the world export's resampling).

use glam::DVec3;

/// Level 0 of a baked volume, decoded: x fastest, then y, then z.
pub(crate) struct DecodedTexel {
    pub(crate) resolution: [u32; 3],
    pub(crate) texels: Vec<[f64; 4]>,
}

impl DecodedTexel {
    /// Trilinear filtering as the volume sampler does it: texel centres at `(i + 0.5) / n`,
    /// repeating in s and t, clamped in w.
    pub(crate) fn sample(&self, uvw: DVec3) -> [f64; 4] {
        let [nx, ny, nz] = self.resolution.map(|n| n as i64);
        let axis = |c: f64, n: i64, wrap: bool| {
            let x = c * n as f64 - 0.5;
            let i0 = x.floor();
            let f = x - i0;
            let i0 = i0 as i64;
            let fix = |i: i64| if wrap { i.rem_euclid(n) } else { i.clamp(0, n - 1) };
            (fix(i0), fix(i0 + 1), f)
        };
        let (x0, x1, fx) = axis(uvw.x, nx, true);
        let (y0, y1, fy) = axis(uvw.y, ny, true);
        let (z0, z1, fz) = axis(uvw.z, nz, false);
        let at = |x: i64, y: i64, z: i64| self.texels[((z * ny + y) * nx + x) as usize];
        let mut out = [0.0; 4];
        for (z, wz) in [(z0, 1.0 - fz), (z1, fz)] {
            for (y, wy) in [(y0, 1.0 - fy), (y1, fy)] {
                for (x, wx) in [(x0, 1.0 - fx), (x1, fx)] {
                    let t = at(x, y, z);
                    for c in 0..4 {
                        out[c] += wx * wy * wz * t[c];
                    }
                }
            }
        }
        out
    }
}
