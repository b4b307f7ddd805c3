//! CPU twin (f64) of `wgsl/shared/{fields,transfer,hypertexture}.wgsl`: soft objects, vector
//! fields, table lookups, the hypertexture density (Gilet & Dischler 2009, eq. 3 to 5) and its
//! colour, read from the same packed parameters the kernels read.

use glam::{DVec2, DVec3, DVec4};

use super::bake_transfer::TRANSFER_SIZE;
use super::noise_simplex::{simplex3, simplex3_tiled, simplex4};
use crate::types::{HyperNoise, HyperParams, OPERATOR_BLEND, OPERATOR_MIX};
use crate::types::{
    FIELD_CONSTANT, FIELD_FROM_CENTRE, FIELD_SWIRL, OBJECT_BOX, OBJECT_ELLIPSOID, OBJECT_MESH, OBJECT_POINTS,
    OBJECT_TORUS,
};

/// Vectors shorter than this have no direction (mirrors `TINY`).
pub(crate) const TINY: f64 = 1e-12;

/// A packed hypertexture and its sampled transfer tables, as the kernels see them.
#[derive(Clone, Copy)]
pub struct Model<'a> {
    /// The object's parameters.
    pub params: &'a HyperParams,
    /// Its noises.
    pub noises: &'a [HyperNoise],
    /// The sampled transfer tables.
    pub tables: &'a [f64],
    /// Mesh and point-set objects: the baked grid's samples (a point set's: then its densities)
    /// and its largest inside distance.
    pub grid: Option<(&'a [[f32; 4]], f32)>,
}

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

pub(crate) fn unit_or_zero(v: DVec3) -> DVec3 {
    let len = v.length();
    if len > TINY {
        v / len
    } else {
        DVec3::ZERO
    }
}

/// Table `table` at `x`, linearly interpolated (clamped to [0, 1]).
pub(crate) fn transfer_lookup(tables: &[f64], table: u32, x: f64) -> f64 {
    let u = x.clamp(0.0, 1.0) * (TRANSFER_SIZE - 1) as f64;
    let i = (u as usize).min(TRANSFER_SIZE - 2);
    let base = table as usize * TRANSFER_SIZE + i;
    let f = u - i as f64;
    tables[base] * (1.0 - f) + tables[base + 1] * f
}

impl Model<'_> {
    /// The mesh grid at x (clamped to the grid), trilinear: vector to the closest surface point
    /// and signed distance (mirrors `mesh_sample`).
    pub(crate) fn mesh_sample(&self, x: DVec3) -> (DVec3, f64) {
        self.grid_sample(x, 0)
    }

    /// The grid block starting at `base` at x, trilinear (mirrors `grid_sample`).
    fn grid_sample(&self, x: DVec3, base: usize) -> (DVec3, f64) {
        let (cells, _) = self.grid.expect("a mesh or point-set object's grid");
        let cells = &cells[base..];
        let n = self.params.grid_min[3] as usize;
        let lo = v3(self.params.grid_min);
        let u = ((x - lo) / (v3(self.params.grid_max) - lo)).clamp(DVec3::ZERO, DVec3::ONE) * (n - 1) as f64;
        let i = u.to_array().map(|c| (c as usize).min(n - 2));
        let f = u - DVec3::new(i[0] as f64, i[1] as f64, i[2] as f64);
        let mut acc = DVec4::ZERO;
        for corner in 0..8 {
            let b = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
            let w: f64 = (0..3).map(|a| if b[a] == 1 { f[a] } else { 1.0 - f[a] }).product();
            let c = cells[(i[0] + b[0]) + n * ((i[1] + b[1]) + n * (i[2] + b[2]))];
            acc += DVec4::from_array(c.map(|v| v as f64)) * w;
        }
        (acc.truncate(), acc.w)
    }

    /// O(x), the soft object's density in [0, 1].
    pub fn object_density(&self, x: DVec3) -> f64 {
        let s = v3(self.params.object);
        let d = match self.params.kinds[0] {
            OBJECT_ELLIPSOID => 1.0 - (x / s).length(),
            OBJECT_TORUS => 1.0 - DVec2::new(DVec2::new(x.x, x.y).length() - s.x, x.z).length() / s.y,
            OBJECT_BOX => 1.0 - (x.abs() / s).max_element(),
            OBJECT_MESH => self.mesh_sample(x).1 / self.grid.map_or(1.0, |g| g.1 as f64),
            OBJECT_POINTS => {
                let n = self.params.grid_min[3] as usize;
                self.grid_sample(x, n * n * n).0.x
            }
            _ => 1.0 - x.length() / s.x,
        };
        d.clamp(0.0, 1.0)
    }

    /// A lower bound of the distance from x to where the density is positive.
    pub(crate) fn support_distance(&self, x: DVec3) -> f64 {
        let s = v3(self.params.object);
        match self.params.kinds[0] {
            OBJECT_ELLIPSOID => ((x / s).length() - 1.0) * s.min_element(),
            OBJECT_TORUS => DVec2::new(DVec2::new(x.x, x.y).length() - s.x, x.z).length() - s.y,
            OBJECT_BOX => {
                let q = x.abs() - s;
                q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
            }
            OBJECT_MESH => {
                let out = (v3(self.params.grid_min) - x).max(x - v3(self.params.grid_max));
                if out.cmpgt(DVec3::ZERO).any() {
                    out.max(DVec3::ZERO).length()
                } else {
                    -self.mesh_sample(x).1 * 0.57735
                }
            }
            OBJECT_POINTS => {
                let (lo, hi) = (v3(self.params.grid_min), v3(self.params.grid_max));
                let out = (lo - x).max(x - hi);
                if out.cmpgt(DVec3::ZERO).any() {
                    return out.max(DVec3::ZERO).length();
                }
                let cell = (hi.x - lo.x) / (self.params.grid_min[3] as f64 - 1.0);
                -self.mesh_sample(x).1 - 2.0 * 3f64.sqrt() * cell
            }
            _ => x.length() - s.x,
        }
    }

    /// The closest point of the object's boundary (ellipsoid: radial projection).
    pub(crate) fn closest_surface_point(&self, x: DVec3) -> DVec3 {
        let s = v3(self.params.object);
        match self.params.kinds[0] {
            OBJECT_ELLIPSOID => {
                let k = (x / s).length();
                if k > TINY {
                    x / k
                } else {
                    x
                }
            }
            OBJECT_TORUS => {
                let r = DVec2::new(x.x, x.y).length();
                let around = if r > TINY { DVec2::new(x.x, x.y) / r } else { DVec2::X };
                let ring = DVec3::new(around.x * s.x, around.y * s.x, 0.0);
                let q = x - ring;
                let len = q.length();
                if len > TINY {
                    ring + q * (s.y / len)
                } else {
                    x
                }
            }
            OBJECT_BOX => {
                let a = x.abs();
                if a.cmpgt(s).any() {
                    return x.clamp(-s, s);
                }
                let gap = s - a;
                let side = |c: f64| if c >= 0.0 { 1.0 } else { -1.0 };
                let mut p = x;
                if gap.x <= gap.y && gap.x <= gap.z {
                    p.x = side(x.x) * s.x;
                } else if gap.y <= gap.z {
                    p.y = side(x.y) * s.y;
                } else {
                    p.z = side(x.z) * s.z;
                }
                p
            }
            OBJECT_MESH | OBJECT_POINTS => {
                let c = x.clamp(v3(self.params.grid_min), v3(self.params.grid_max));
                c + self.mesh_sample(c).0
            }
            _ => {
                let len = x.length();
                if len > TINY {
                    x * (s.x / len)
                } else {
                    x
                }
            }
        }
    }

    /// The unperturbed vector field.
    pub(crate) fn base_field(&self, x: DVec3) -> DVec3 {
        let c = self.closest_surface_point(x) - x;
        let f = self.params.field;
        match self.params.kinds[1] {
            FIELD_FROM_CENTRE => {
                let side = if self.object_density(x) > 0.0 { 1.0 } else { -1.0 };
                unit_or_zero(x - v3(f)) * (side * c.length())
            }
            FIELD_CONSTANT => v3(f),
            FIELD_SWIRL => {
                let around = unit_or_zero(v3(f).cross(x - v3(self.params.field_center)));
                c + around * (f[3] as f64 * c.length())
            }
            _ => c,
        }
    }

    /// V(x), with the perturbation of direction and magnitude when it is on.
    pub fn vector_field(&self, x: DVec3) -> DVec3 {
        let mut v = self.base_field(x);
        let p = self.params.perturb.map(|c| c as f64);
        if p[1] > 0.0 {
            let q = x * p[1];
            let seed = self.params.kinds[3];
            let n = DVec3::new(
                simplex3(q, seed),
                simplex3(q, seed.wrapping_add(1)),
                simplex3(q, seed.wrapping_add(2)),
            );
            v = (v + n * (p[0] * v.length())) * (1.0 + p[2] * simplex3(q, seed.wrapping_add(3)));
        }
        v
    }

    /// The distortion factor k of eq. 5 at x, given V(x).
    pub fn distortion(&self, x: DVec3, v: DVec3) -> f64 {
        let mut k = 0.0;
        let noises = &self.noises[..self.params.kinds[2] as usize];
        let animated = animated(noises);
        let time = self.params.march[3] as f64;
        let density = self.object_density(x);
        for n in noises {
            let scale = DVec3::new(n.scale[0] as f64, n.scale[1] as f64, n.scale[2] as f64);
            let q = (x + v * n.shift as f64) * n.frequency as f64 * scale;
            let noise = if animated {
                simplex4(DVec4::new(q.x, q.y, q.z, n.speed as f64 * time), n.seed)
            } else {
                simplex3_tiled(q, n.seed, n.tile.map(|t| t as i32)[..3].try_into().unwrap())
            };
            let t = self.shape_lookup(n, 0.5 + 0.5 * noise, density);
            let term = n.amplitude as f64 * t;
            let unit = n.scale[3] as f64;
            k = match n.combine {
                OPERATOR_BLEND => k * (1.0 - if unit > 0.0 { term / unit } else { 0.0 }) + term,
                OPERATOR_MIX => k * (1.0 - t) + term,
                _ => k + term,
            };
        }
        k
    }

    /// The hypertexture density O(x - k V/|V|); 0 without evaluating the noises farther than the
    /// largest shift from the object.
    pub fn hyper_density(&self, x: DVec3) -> f64 {
        if self.support_distance(x) > self.params.march[2] as f64 {
            return 0.0;
        }
        let v = self.vector_field(x);
        self.modulate(self.object_density(x - unit_or_zero(v) * self.distortion(x, v)))
    }

    /// The density modulation functions (`bias`, `gain`: 0.5 is the identity).
    pub(crate) fn modulate(&self, density: f64) -> f64 {
        let [b, g, ..] = self.params.modulation.map(|m| m as f64);
        if b == 0.5 && g == 0.5 {
            return density;
        }
        perlin_gain(g, perlin_bias(b, density.clamp(0.0, 1.0)))
    }

    /// A noise's shape transfer function at noise value u (2D: bilinear with the density o).
    pub(crate) fn shape_lookup(&self, n: &HyperNoise, u: f64, o: f64) -> f64 {
        if n.rows <= 1 {
            return transfer_lookup(self.tables, n.table, u);
        }
        let r = o.clamp(0.0, 1.0) * (n.rows - 1) as f64;
        let row = (r as u32).min(n.rows - 2);
        let a = transfer_lookup(self.tables, n.table + row, u);
        let b = transfer_lookup(self.tables, n.table + row + 1, u);
        a + (b - a) * (r - row as f64)
    }

    /// The first colour table: after the last noise's shape tables.
    pub(crate) fn color_tables(&self) -> u32 {
        let last = &self.noises[self.params.kinds[2] as usize - 1];
        last.table + last.rows.max(1)
    }

    /// Straight colour and opacity per opacity length at a density.
    pub fn hyper_color(&self, density: f64) -> [f64; 4] {
        let first = self.color_tables();
        std::array::from_fn(|c| transfer_lookup(self.tables, first + c as u32, density))
    }
}

/// Perlin's bias: `t^(ln b / ln 0.5)`, so that `perlin_bias(b, 0.5) = b`; 0 and 1 stay.
pub fn perlin_bias(b: f64, t: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    t.powf(b.ln() / 0.5f64.ln())
}

/// Perlin's gain: two biases of `1 - g` mirrored about 0.5, so that `perlin_gain(g, 0.5) = 0.5`.
pub fn perlin_gain(g: f64, t: f64) -> f64 {
    if t < 0.5 {
        0.5 * perlin_bias(1.0 - g, 2.0 * t)
    } else {
        1.0 - 0.5 * perlin_bias(1.0 - g, 2.0 - 2.0 * t)
    }
}

/// Whether a hypertexture's noises are 4D (some noise has a speed): the kernels' override
/// `animated`.
pub(crate) fn animated(noises: &[HyperNoise]) -> bool {
    noises.iter().any(|n| n.speed != 0.0)
}
