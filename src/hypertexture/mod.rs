//! Hypertextures (Gilet & Dischler 2009) packed for the kernels: the soft object and vector field
//! as `HyperParams` fields, one `HyperNoise` per noise, and every transfer function as control
//! points that `bake_transfer.wgsl` samples into tables (the noises' shape tables first, one per
//! noise or one per row of a 2D shape transfer function, then the red, green, blue and opacity
//! tables of the colour transfer function).

pub mod mesh;
pub mod points;
pub mod splats;

use glam::DVec3;

use crate::cpu::bake_transfer::{HERMITE, LINEAR, TRANSFER_SIZE};
pub(crate) use crate::cpu::hypertexture::animated;
use crate::scene::hypertexture::{ColorTransfer, Field, Operator, ShapeTransfer, SoftObject};
use crate::scene::Hypertexture;
use crate::types::{HyperNoise, HyperParams, TransferFunction, TransferPoint};
use crate::types::{OPERATOR_BLEND, OPERATOR_MIX, OPERATOR_SUM};

pub(crate) use crate::types::{
    FIELD_CLOSEST_SURFACE, FIELD_CONSTANT, FIELD_FROM_CENTRE, FIELD_SWIRL, OBJECT_BOX, OBJECT_ELLIPSOID,
    OBJECT_MESH, OBJECT_POINTS, OBJECT_SPHERE, OBJECT_TORUS,
};

/// The parts of `HyperParams` a hypertexture fixes (the camera, frame and march settings are
/// added by `methods::ray_march`), its noises and its transfer functions.
#[derive(Debug, Clone, PartialEq)]
pub struct Packed {
    pub(crate) object: [f32; 4],
    pub(crate) field: [f32; 4],
    pub(crate) field_center: [f32; 4],
    pub(crate) perturb: [f32; 4],
    /// Object kind, field kind, noise count, perturbation seed.
    pub(crate) kinds: [u32; 4],
    /// The noises, in combining order.
    pub noises: Vec<HyperNoise>,
    /// The shape and colour transfer functions, indexing `points`.
    pub functions: Vec<TransferFunction>,
    /// Control points of the transfer functions.
    pub points: Vec<TransferPoint>,
    /// Object-space bounds enlarged by the largest shift.
    pub bounds: (DVec3, DVec3),
    pub(crate) opacity_length: f64,
    /// Bias and gain of the density (0.5: none).
    pub(crate) modulation: [f32; 4],
    /// The largest shift the noises reach (object space).
    pub(crate) max_shift: f64,
    /// Mesh objects: the mesh and where its grid samples lie.
    pub mesh: Option<(std::sync::Arc<crate::mesh::shape::MeshShape>, crate::mesh::shape::GridSpec)>,
    /// Point-set objects: the points, their kernels and where their grid samples lie.
    pub(crate) point_set: Option<points::PointObject>,
}

fn f4(v: DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

pub(crate) fn pack(h: &Hypertexture) -> Packed {
    let (kind, object) = match &h.object.value {
        SoftObject::Sphere { radius } => (OBJECT_SPHERE, f4(DVec3::splat(*radius), 0.0)),
        SoftObject::Ellipsoid { radii } => (OBJECT_ELLIPSOID, f4(*radii, 0.0)),
        SoftObject::Torus { major, minor } => (OBJECT_TORUS, f4(DVec3::new(*major, *minor, 0.0), 0.0)),
        SoftObject::Box { size } => (OBJECT_BOX, f4(*size * 0.5, 0.0)),
        SoftObject::Mesh { .. } => (OBJECT_MESH, [0.0; 4]),
        SoftObject::Points { .. } => (OBJECT_POINTS, [0.0; 4]),
    };
    let point_set = match &h.object.value {
        SoftObject::Points { set: Some(set), radius, saturation, resolution, .. } => {
            Some(points::PointObject {
                set: set.clone(),
                radius: *radius,
                saturation: *saturation,
                spec: set.grid(*radius, *resolution, h.max_shift()),
            })
        }
        _ => None,
    };
    let mesh = match &h.object.value {
        SoftObject::Mesh { shape: Some(shape), resolution, .. } => {
            Some((shape.clone(), shape.grid(*resolution, h.max_shift())))
        }
        _ => None,
    };
    let mut p = Packed {
        object,
        field: [0.0; 4],
        field_center: [0.0; 4],
        perturb: [0.0; 4],
        kinds: [kind, FIELD_CLOSEST_SURFACE, h.enabled_noises().count() as u32, 0],
        noises: Vec::new(),
        functions: Vec::new(),
        points: Vec::new(),
        bounds: h.bounds(),
        opacity_length: h.opacity_length,
        modulation: [h.bias as f32, h.gain as f32, 0.0, 0.0],
        max_shift: h.max_shift(),
        mesh,
        point_set,
    };
    let base = match &h.field {
        Field::Perturbed { field, amount, frequency, magnitude, seed } => {
            p.perturb = [*amount as f32, *frequency as f32, *magnitude as f32, 0.0];
            p.kinds[3] = *seed;
            &field.value
        }
        f => f,
    };
    match base {
        Field::FromCentre { center } => {
            p.kinds[1] = FIELD_FROM_CENTRE;
            p.field = f4(*center, 0.0);
        }
        Field::Constant { direction } => {
            p.kinds[1] = FIELD_CONSTANT;
            p.field = f4(*direction, 0.0);
        }
        Field::Swirl { axis, center, twist } => {
            p.kinds[1] = FIELD_SWIRL;
            p.field = f4(axis.normalize(), *twist);
            p.field_center = f4(*center, 0.0);
        }
        // Validation refuses a perturbed field inside another.
        Field::ClosestSurface | Field::Perturbed { .. } => {}
    }
    // Blend's unit: the largest term a noise can add.
    let unit = h.enabled_noises().map(|n| n.amplitude).fold(0.0, f64::max) as f32;
    for n in h.enabled_noises() {
        let table = p.functions.len() as u32;
        let rows = n.shape.rows().map_or(1, |r| r.len() as u32);
        let (mut scale, tile) = n.tiling();
        scale[3] = unit;
        p.noises.push(HyperNoise {
            scale,
            tile,
            amplitude: n.amplitude as f32,
            frequency: n.frequency as f32,
            shift: n.shift as f32,
            combine: match n.operator {
                Operator::Sum => OPERATOR_SUM,
                Operator::Blend => OPERATOR_BLEND,
                Operator::Mix => OPERATOR_MIX,
            },
            seed: n.seed,
            speed: n.speed as f32,
            table,
            rows,
        });
        match &n.shape {
            ShapeTransfer::Curve(points) => {
                p.function(HERMITE, points.iter().map(|c| (c.0, c.1, c.2)));
            }
            ShapeTransfer::Table(values) => p.table(&values.0),
            // One table per row: the lookup interpolates between rows by density.
            ShapeTransfer::Grid(_) | ShapeTransfer::Image { .. } => {
                n.shape.rows().unwrap_or_default().iter().for_each(|row| p.table(row))
            }
        }
    }
    match &h.color {
        ColorTransfer::Ramp(points) => {
            for c in 0..4 {
                p.function(LINEAR, points.iter().map(|q| (q.0, q.1[c], 0.0)));
            }
        }
        ColorTransfer::Step { threshold, color, opacity } => {
            // Zero up to the table entry at or below the threshold, the value from the next one:
            // the tables' linear filtering then blurs the step over 1/255 of density.
            let cell = 1.0 / (TRANSFER_SIZE - 1) as f64;
            let below = (threshold / cell).floor() * cell;
            let values = [color[0] as f64, color[1] as f64, color[2] as f64, *opacity];
            for value in values {
                let mut pts = vec![(below, 0.0, 0.0), (below + cell, value, 0.0)];
                if below > 0.0 {
                    pts.insert(0, (0.0, 0.0, 0.0));
                }
                p.function(LINEAR, pts.into_iter());
            }
        }
    }
    p
}

impl Packed {
    /// The largest shift as the kernels test it (rounding slack added): no point farther from
    /// the object can have density, which the march and the splat lattice both rely on.
    pub(crate) fn tested_shift(&self) -> f64 {
        self.max_shift * (1.0 + 1e-4) + 1e-6
    }

    /// The `HyperParams` the hypertexture fixes at `time` (object, field, noise count, reach of
    /// the noises, mesh grid, enlarged bounds, opacity length); the camera and march fields are
    /// the method's to fill.
    pub(crate) fn params(&self, time: f64) -> HyperParams {
        let (lo, hi) = self.bounds;
        let mut params = HyperParams {
            bounds_min: [lo.x as f32, lo.y as f32, lo.z as f32, 0.0],
            bounds_max: [hi.x as f32, hi.y as f32, hi.z as f32, self.opacity_length as f32],
            object: self.object,
            field: self.field,
            field_center: self.field_center,
            perturb: self.perturb,
            kinds: self.kinds,
            march: [0.0, 0.0, self.tested_shift() as f32, time as f32],
            modulation: self.modulation,
            ..Default::default()
        };
        let grid = self.mesh.as_ref().map(|(_, g)| g).or(self.point_set.as_ref().map(|p| &p.spec));
        if let Some(g) = grid {
            params.grid_min = [g.lo.x as f32, g.lo.y as f32, g.lo.z as f32, g.n[0] as f32];
            params.grid_max = [g.hi.x as f32, g.hi.y as f32, g.hi.z as f32, 0.0];
        }
        params
    }

    /// The cache key of the object's grid (mesh and point-set objects).
    pub(crate) fn grid_key(&self) -> Option<u64> {
        match (&self.mesh, &self.point_set) {
            (Some((shape, spec)), _) => Some(crate::gpu::cache::key(&(shape.hash, spec))),
            (_, Some(p)) => Some(p.key()),
            _ => None,
        }
    }

    /// The kernel that bakes the object's grid (mesh and point-set objects).
    pub(crate) fn grid_kernel(&self) -> Option<&'static str> {
        match (&self.mesh, &self.point_set) {
            (Some(_), _) => Some("bake/bake_mesh_grid.wgsl"),
            (_, Some(_)) => Some("bake/bake_point_grid.wgsl"),
            _ => None,
        }
    }

    /// GPU bytes of the object's grid and what its bake uploads.
    pub(crate) fn grid_bytes(&self) -> u64 {
        self.mesh.as_ref().map_or(0, |(_, g)| g.samples() * 16)
            + self.point_set.as_ref().map_or(0, points::PointObject::bytes)
    }

    /// Bakes the object's grid: `bake_mesh_grid.wgsl` for a mesh, `bake_point_grid.wgsl` for a
    /// point set; `None` for the other objects.
    pub(crate) fn bake_grid(&self, ctx: &crate::gpu::GpuContext) -> crate::Result<Option<mesh::MeshGrid>> {
        match (&self.mesh, &self.point_set) {
            (Some((shape, spec)), _) => mesh::bake(ctx, shape, spec).map(Some),
            (_, Some(p)) => points::bake(ctx, p).map(Some),
            _ => Ok(None),
        }
    }

    /// Values at evenly spaced x from 0 to 1, joined linearly.
    fn table(&mut self, values: &[f64]) {
        let last = (values.len() - 1).max(1) as f64;
        self.function(LINEAR, values.iter().enumerate().map(|(i, &y)| (i as f64 / last, y, 0.0)));
    }

    fn function(&mut self, kind: u32, points: impl Iterator<Item = (f64, f64, f64)>) {
        let first = self.points.len() as u32;
        self.points.extend(points.map(|(x, y, slope)| TransferPoint {
            x: x as f32,
            y: y as f32,
            slope: slope as f32,
            _pad: 0.0,
        }));
        let count = self.points.len() as u32 - first;
        self.functions.push(TransferFunction { first, count, kind, _pad: 0 });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::bake_transfer::bake_transfer;

    fn parse(text: &str) -> Hypertexture {
        let scene = format!(
            "Scene(output: (width: 8, height: 8), camera: (eye: (0, -3, 0), target: (0, 0, 0)), \
             hypertextures: {{ \"h\": {text} }})"
        );
        crate::scene::parse(&scene, std::path::Path::new("t.ron")).unwrap().hypertextures["h"].clone()
    }

    /// A step colour transfer is transparent below its threshold and opaque from one table entry
    /// above it; a Hermite curve passes through its control points.
    #[test]
    fn tables_follow_the_control_points() {
        let h = parse(
            "(object: Sphere(radius: 1.0), noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 1.0, 0.0), \
             (1.0, 0.2, -1.0)]), amplitude: 0.1, frequency: 2.0)], color: Step(threshold: 0.3, \
             color: (1.0, 0.5, 0.25), opacity: 0.8))",
        );
        let p = pack(&h);
        assert_eq!(p.functions.len(), 5);
        let t = bake_transfer(&p.functions, &p.points);
        let at = |table: usize, x: f64| crate::cpu::hypertexture::transfer_lookup(&t, table as u32, x);
        assert!(
            (at(0, 0.5) - 1.0).abs() < 1e-3 && at(0, 0.0).abs() < 1e-9 && (at(0, 1.0) - 0.2).abs() < 1e-6
        );
        let cell = 1.0 / 255.0;
        assert_eq!(at(4, 0.3 - cell), 0.0);
        // (Control points are f32: the entry just past the step is 0.8 to 2e-6.)
        assert!((at(4, 0.3 + cell) - 0.8).abs() < 1e-5 && (at(2, 0.9) - 0.5).abs() < 1e-6);
        assert_eq!(p.bounds.1, DVec3::splat(1.1));
    }
}
