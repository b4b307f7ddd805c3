//! Scene types of hypertextures (Gilet & Dischler 2009, section 4): a soft object, a vector field,
//! noises filtered by shape transfer functions, and an RGBA transfer function on density. Value
//! ranges are checked while parsing; list lengths and control-point order by `check` (positioned
//! through `Mark`s).

use std::sync::Arc;

use glam::{DMat4, DVec3};
use serde::Deserialize;

use crate::mesh::points::PointSet;
use crate::mesh::shape::MeshShape;

use super::values::{self as v, Mark};

/// Most noises one hypertexture combines.
pub(crate) const MAX_NOISES: usize = 8;
/// Most control points of a curve or ramp.
pub(crate) const MAX_POINTS: usize = 64;
/// Most values of a sampled table.
pub(crate) const MAX_TABLE: usize = 256;
/// Most rows (densities) of a 2D shape transfer function.
pub(crate) const MAX_ROWS: usize = 64;

/// `hypertextures: { "name": (object: .., field: .., noises: [..], color: ..) }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hypertexture {
    pub(crate) object: Mark<SoftObject>,
    #[serde(default)]
    pub(crate) field: Field,
    /// Combined in order into the distortion factor k (eq. 5); 1 to `MAX_NOISES`.
    pub noises: Mark<Vec<Noise>>,
    /// Colour and opacity by density.
    pub(crate) color: ColorTransfer,
    /// World length over which the transfer function's opacity is reached.
    #[serde(default = "default_opacity_length", deserialize_with = "v::positive")]
    pub(crate) opacity_length: f64,
    /// Perlin's bias applied to the density, `d^(ln b / ln 0.5)`: below 0.5 it thins the soft
    /// region, above it thickens it; 0.5 changes nothing. In (0, 1).
    #[serde(default = "identity_modulation", deserialize_with = "v::open_unit")]
    pub(crate) bias: f64,
    /// Perlin's gain applied after the bias: above 0.5 it sharpens the soft region towards a
    /// step at density 0.5, below it flattens it; 0.5 changes nothing. In (0, 1).
    #[serde(default = "identity_modulation", deserialize_with = "v::open_unit")]
    pub(crate) gain: f64,
}

fn identity_modulation() -> f64 {
    0.5
}

fn default_opacity_length() -> f64 {
    0.05
}

/// Soft objects in their node's frame: density 1 at the core falling linearly to 0 on the boundary.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SoftObject {
    /// `1 - |x| / radius`.
    Sphere {
        /// Radius, > 0.
        #[serde(deserialize_with = "v::positive")]
        radius: f64,
    },
    /// `1 - |x / radii|`.
    Ellipsoid {
        /// Semi-axes along x, y and z, each > 0.
        #[serde(deserialize_with = "v::positive3")]
        radii: DVec3,
    },
    /// Axis z: `1 - (distance to the core circle of radius major) / minor`.
    Torus {
        /// Radius of the core circle, > 0.
        #[serde(deserialize_with = "v::positive")]
        major: f64,
        /// Radius of the tube, > 0 and below `major`.
        #[serde(deserialize_with = "v::positive")]
        minor: f64,
    },
    /// Edge lengths `size`, centred: `1 - max_i |x_i| / (size_i / 2)`.
    Box {
        /// Edge lengths along x, y and z, each > 0.
        #[serde(deserialize_with = "v::positive3")]
        size: DVec3,
    },
    /// A closed triangle mesh (OBJ, relative to the scene file) baked into a grid of
    /// `resolution^3` samples: inside distance to the surface over the largest inside distance.
    Mesh {
        /// The OBJ or glTF file: a closed mesh of at most 16 parts.
        path: Mark<String>,
        /// Samples per axis, 4..=128 (default 64).
        #[serde(default = "default_grid", deserialize_with = "v::grid_resolution")]
        resolution: u32,
        /// Loaded and checked by `scene::load`.
        #[serde(skip)]
        shape: Option<Arc<MeshShape>>,
    },
    /// A point set (PLY or OBJ `v` lines, relative to the scene file; Gilet & Dischler 2009,
    /// section 5.1), each point the centre of a kernel `(1 - r^2 / R^2)^3` of radius R: the
    /// density is the sum of the kernels over `saturation`, clamped to 1, baked into a grid of
    /// `resolution^3` samples.
    Points {
        /// The PLY (ASCII or binary little-endian: `x`, `y`, `z`, optional `radius`) or OBJ file.
        path: Mark<String>,
        /// The kernel radius R (node frame); a PLY `radius` property scales it per point.
        #[serde(deserialize_with = "v::positive")]
        radius: f64,
        /// The kernel sum read as density 1 (the core): lower makes the object denser.
        #[serde(default = "one", deserialize_with = "v::positive")]
        saturation: f64,
        /// Grid samples per axis (as a mesh object's).
        #[serde(default = "default_grid", deserialize_with = "v::grid_resolution")]
        resolution: u32,
        /// Loaded and checked by `scene::load`.
        #[serde(skip)]
        set: Option<Arc<PointSet>>,
    },
}

fn default_grid() -> u32 {
    64
}

impl SoftObject {
    /// Where the density can be positive: (min, max) in the node's frame.
    pub(crate) fn bounds(&self) -> (DVec3, DVec3) {
        let h = match self {
            SoftObject::Sphere { radius } => DVec3::splat(*radius),
            SoftObject::Ellipsoid { radii } => *radii,
            SoftObject::Torus { major, minor } => DVec3::new(major + minor, major + minor, *minor),
            SoftObject::Box { size } => *size * 0.5,
            SoftObject::Mesh { shape, .. } => {
                return shape.as_ref().map_or((DVec3::ZERO, DVec3::ZERO), |s| (s.lo, s.hi));
            }
            SoftObject::Points { set, radius, .. } => {
                return set.as_ref().map_or((DVec3::ZERO, DVec3::ZERO), |s| s.bounds(*radius));
            }
        };
        (-h, h)
    }
}

/// The vector field V of eq. 3 and 4 (the paper's Figure 8).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Field {
    /// Towards the closest point of the object's boundary (`x + V` lies on it).
    #[default]
    ClosestSurface,
    /// Away from `center` inside the object (towards it outside), with the length of the
    /// closest-surface vector: the closest-surface field of a sphere seen from a shifted centre.
    FromCentre {
        /// The centre, in the node's frame.
        #[serde(deserialize_with = "v::vec3")]
        center: DVec3,
    },
    /// The same vector everywhere (its length matters where noises are shifted by it).
    Constant {
        /// The vector, non-zero.
        #[serde(deserialize_with = "v::direction")]
        direction: DVec3,
    },
    /// The closest-surface vector plus `twist` times its length around `axis` (through `center`).
    Swirl {
        /// The axis's direction, non-zero (default `(0, 0, 1)`).
        #[serde(default = "z_axis", deserialize_with = "v::direction")]
        axis: DVec3,
        /// A point on the axis (default the origin).
        #[serde(default, deserialize_with = "v::vec3")]
        center: DVec3,
        /// Length of the part around the axis, times the closest-surface vector's, finite (default 1).
        #[serde(default = "one", deserialize_with = "v::finite")]
        twist: f64,
    },
    /// Another field (not itself perturbed) with its direction perturbed by a vector noise of
    /// `amount` times its length and its length scaled by `1 + magnitude * noise`, noises at
    /// `frequency` (cycles per unit of the node's frame).
    Perturbed {
        /// The field perturbed.
        field: Box<Mark<Field>>,
        /// Direction perturbation, a fraction of the field's length, >= 0 (default 0.5).
        #[serde(default = "half", deserialize_with = "v::non_negative")]
        amount: f64,
        /// Noise cycles per unit of the node's frame, > 0.
        #[serde(deserialize_with = "v::positive")]
        frequency: f64,
        /// Length perturbation, in [0, 1] (default 0).
        #[serde(default, deserialize_with = "v::unit")]
        magnitude: f64,
        /// Seed of the perturbing noises (default 0).
        #[serde(default)]
        seed: u32,
    },
}

fn z_axis() -> DVec3 {
    DVec3::Z
}
fn one() -> f64 {
    1.0
}
fn half() -> f64 {
    0.5
}
fn yes() -> bool {
    true
}

/// One noise of eq. 5: `t = T((1 + noise(frequency (x + shift V))) / 2)`, whose term
/// `amplitude t` combines into k by its [`Operator`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Noise {
    /// The shape transfer function `T` filtering the noise.
    pub shape: ShapeTransfer,
    /// The largest shift (world depth of the detail, in the node's frame).
    #[serde(deserialize_with = "v::non_negative")]
    pub(crate) amplitude: f64,
    /// Noise cycles per unit: larger is smaller detail.
    #[serde(deserialize_with = "v::positive")]
    pub(crate) frequency: f64,
    /// r: how far along V the noise is evaluated (0: at x; 1: at x + V).
    #[serde(default, deserialize_with = "v::unit")]
    pub(crate) shift: f64,
    #[serde(default)]
    pub(crate) operator: Operator,
    #[serde(default)]
    pub(crate) seed: u32,
    /// Animation: noise cycles per second along time (4D noise; 0: still).
    #[serde(default, deserialize_with = "v::finite")]
    pub speed: f64,
    /// Periodic noise: it repeats every `(x, y, z)` (node frame), the frequency adjusted per axis
    /// so that each period holds a whole multiple of 3 noise cells (see `simplex3_tiled`).
    #[serde(default)]
    pub(crate) period: Option<Mark<[f64; 3]>>,
    /// `false` switches the noise off (kept in the file; the preview's panel toggles it).
    #[serde(default = "yes")]
    pub(crate) enabled: bool,
}

/// The largest noise-cell count per period (keeps the wrapped corner class in i32).
pub(crate) const MAX_PERIOD_CELLS: f64 = 3.0 * 4096.0;

impl Noise {
    /// Per-axis frequency factors and tile counts `(a, b, c)` of a periodic noise (periods of
    /// 3a, 3b, 3c cells): ones and zeros when it is not periodic.
    pub(crate) fn tiling(&self) -> ([f32; 4], [u32; 4]) {
        let Some(period) = &self.period else { return ([1.0; 4], [0; 4]) };
        let mut scale = [1.0f32; 4];
        let mut tile = [0u32; 4];
        for i in 0..3 {
            let cells = self.frequency * period.value[i];
            let a = (cells / 3.0).round().max(1.0);
            tile[i] = a as u32;
            scale[i] = (3.0 * a / cells) as f32;
        }
        (scale, tile)
    }
}

/// How a noise's term `amplitude t` combines into the distortion factor k.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Operator {
    /// `k += amplitude t` (the default).
    #[default]
    Sum,
    /// The paper's blending (Gilet & Dischler 2009, section 4.1): `v1 (1 - v2) + v2` with `v1`
    /// the k so far and `v2 = amplitude t`, both in units of the largest amplitude `A` of the
    /// hypertexture's noises (so `v2` lies in [0, 1]): `k = k (1 - amplitude t / A) + amplitude t`.
    Blend,
    /// `k = k (1 - t) + amplitude t`: a lerp from k towards the amplitude by `t`, so where
    /// `t = 1` the noise replaces what came before whatever its amplitude.
    Mix,
}

/// A 1D shape transfer function on [0, 1] with values in [0, 1].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ShapeTransfer {
    /// Control points `(x, y, slope)` joined by cubic Hermite segments (clamped to [0, 1]);
    /// constant beyond the first and last points.
    Curve(Mark<Vec<Mark<CurvePoint>>>),
    /// Values at evenly spaced x from 0 to 1, joined linearly.
    Table(Mark<TableValues>),
    /// A 2D shape transfer function (the paper's eq. 6, Figure 7): rows of values at evenly
    /// spaced noise values from 0 to 1, the rows at evenly spaced object densities O(x) from 0
    /// (first row) to 1 (last), joined bilinearly.
    Grid(Mark<GridRows>),
    /// A 2D shape transfer function from a grayscale PNG image (relative to the scene file; its
    /// first channel): columns are noise values from 0 (left) to 1, rows densities from 0 (top)
    /// to 1, as a `Grid` whose rows are the image's.
    Image {
        /// The PNG file, relative to the scene file.
        path: Mark<String>,
        /// Filled by `scene::load` from the image.
        #[serde(skip)]
        rows: Vec<Vec<f64>>,
    },
}

impl ShapeTransfer {
    /// The rows of a 2D function (`Grid` or `Image`); `None` for 1D ones.
    pub fn rows(&self) -> Option<&[Vec<f64>]> {
        match self {
            ShapeTransfer::Grid(rows) => Some(&rows.0),
            ShapeTransfer::Image { rows, .. } => Some(rows),
            _ => None,
        }
    }
}

/// The rows of a `Grid` shape transfer function, each value in [0, 1].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct GridRows(#[serde(deserialize_with = "v::unit_rows")] pub Vec<Vec<f64>>);

/// A control point `(x, y, slope)` of a `Curve`: x and y in [0, 1], slope finite.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvePoint(
    #[serde(deserialize_with = "v::unit")] pub f64,
    #[serde(deserialize_with = "v::unit")] pub f64,
    #[serde(deserialize_with = "v::finite")] pub f64,
);

/// The values of a `Table` shape transfer function, each in [0, 1].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct TableValues(#[serde(deserialize_with = "v::unit_list")] pub Vec<f64>);

/// Colour (linear rgb) and opacity per opacity length, by density.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ColorTransfer {
    /// Control points `(density, (r, g, b, a))` joined linearly.
    Ramp(Mark<Vec<Mark<RampPoint>>>),
    /// Transparent below `threshold`, `color` and `opacity` from it on: an iso-surface look.
    Step {
        /// The density from which the colour shows, in [0, 1].
        #[serde(deserialize_with = "v::unit")]
        threshold: f64,
        /// Linear RGB in [0, 1].
        #[serde(deserialize_with = "v::color")]
        color: [f32; 3],
        /// Opacity per opacity length, in [0, 1] (default 1).
        #[serde(default = "one", deserialize_with = "v::unit")]
        opacity: f64,
    },
}

/// A control point `(density, (r, g, b, a))` of a `Ramp`, all in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RampPoint(
    #[serde(deserialize_with = "v::unit")] pub f64,
    #[serde(deserialize_with = "v::rgba")] pub [f64; 4],
);

impl Hypertexture {
    /// The largest shift `k` can reach: the sum of the enabled noises' amplitudes (Blend and Mix
    /// never exceed it).
    pub(crate) fn max_shift(&self) -> f64 {
        self.enabled_noises().map(|n| n.amplitude).sum()
    }

    /// The noises switched on, in order: those combined into k.
    pub(crate) fn enabled_noises(&self) -> impl Iterator<Item = &Noise> {
        self.noises.iter().filter(|n| n.enabled)
    }

    /// The object's bounds enlarged by the largest shift, so no detail is clipped.
    pub(crate) fn bounds(&self) -> (DVec3, DVec3) {
        let (lo, hi) = self.object.bounds();
        let a = DVec3::splat(self.max_shift());
        (lo - a, hi + a)
    }

    /// The eight corners of the enlarged bounds through `to_world`.
    pub(crate) fn world_corners(&self, to_world: &DMat4) -> [DVec3; 8] {
        let (lo, hi) = self.bounds();
        std::array::from_fn(|i| {
            let pick = |bit: usize, a: f64, b: f64| if i & bit == 0 { a } else { b };
            to_world.transform_point3(DVec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            ))
        })
    }
}

/// The length of the diagonal of the box holding `corners`: no ray crosses the bounds on a
/// longer stretch.
pub(crate) fn diagonal(corners: &[DVec3]) -> f64 {
    let lo = corners.iter().fold(DVec3::INFINITY, |a, &c| a.min(c));
    let hi = corners.iter().fold(DVec3::NEG_INFINITY, |a, &c| a.max(c));
    (hi - lo).length()
}

/// Checks that need whole lists: counts, control-point order. Each failure is (mark, message).
pub(super) fn check(h: &Hypertexture, fail: &mut dyn FnMut(usize, String)) {
    if let SoftObject::Torus { major, minor } = &h.object.value {
        if minor >= major {
            fail(h.object.seq, format!("expected a torus minor radius below the major radius ({major})"));
        }
    }
    if let Field::Perturbed { field, .. } = &h.field {
        if matches!(field.value, Field::Perturbed { .. }) {
            fail(
                field.seq,
                "expected ClosestSurface, FromCentre, Constant or Swirl: a perturbed field is perturbed once"
                    .into(),
            );
        }
    }
    let n = h.noises.len();
    if n == 0 || n > MAX_NOISES {
        fail(h.noises.seq, format!("expected 1 to {MAX_NOISES} noises, found {n}"));
    } else if h.enabled_noises().next().is_none() {
        fail(h.noises.seq, "expected at least one noise switched on (`enabled: true`)".into());
    }
    for noise in h.noises.iter() {
        if let Some(p) = &noise.period {
            if p.value.iter().any(|&x| !(x.is_finite() && x > 0.0)) {
                fail(p.seq, "expected positive finite periods (x, y, z)".into());
            } else if p.value.iter().any(|&x| noise.frequency * x > MAX_PERIOD_CELLS) {
                fail(
                    p.seq,
                    format!(
                        "expected periods of at most {MAX_PERIOD_CELLS} noise cells (frequency x period)"
                    ),
                );
            } else if noise.speed != 0.0 {
                fail(
                    p.seq,
                    "a periodic noise cannot be animated: expected `speed: 0` (4D noise has no period)"
                        .into(),
                );
            }
        }
        match &noise.shape {
            ShapeTransfer::Curve(points) => {
                check_points(points, MAX_POINTS, |p| p.0, "curve", fail);
            }
            ShapeTransfer::Table(values) => {
                let n = values.0.len();
                if !(2..=MAX_TABLE).contains(&n) {
                    fail(values.seq, format!("expected a table of 2 to {MAX_TABLE} values, found {n}"));
                }
            }
            // Its size is checked when the image is loaded.
            ShapeTransfer::Image { .. } => {}
            ShapeTransfer::Grid(rows) => {
                let n = rows.0.len();
                let width = rows.0.first().map_or(0, Vec::len);
                if !(2..=MAX_ROWS).contains(&n) {
                    fail(rows.seq, format!("expected a grid of 2 to {MAX_ROWS} rows (densities), found {n}"));
                } else if !(2..=MAX_TABLE).contains(&width) {
                    fail(rows.seq, format!("expected grid rows of 2 to {MAX_TABLE} values, found {width}"));
                } else if let Some(i) = rows.0.iter().position(|r| r.len() != width) {
                    let found = rows.0[i].len();
                    fail(
                        rows.seq,
                        format!("grid row {} has {found} values: expected every row as long as the first ({width})", i + 1),
                    );
                }
            }
        }
    }
    if let ColorTransfer::Ramp(points) = &h.color {
        check_points(points, MAX_POINTS, |p| p.0, "ramp", fail);
    }
}

fn check_points<T>(
    points: &Mark<Vec<Mark<T>>>,
    max: usize,
    x: impl Fn(&T) -> f64,
    what: &str,
    fail: &mut dyn FnMut(usize, String),
) {
    let n = points.len();
    if !(2..=max).contains(&n) {
        fail(points.seq, format!("expected a {what} of 2 to {max} control points, found {n}"));
        return;
    }
    for w in points.windows(2) {
        let (a, b) = (x(&w[0]), x(&w[1]));
        if b <= a {
            let how = if b == a { "repeats" } else { "comes before" };
            fail(
                w[1].seq,
                format!("control point at x = {b} {how} the previous one (x = {a}): expected control points sorted by x, each x once"),
            );
        }
    }
}
