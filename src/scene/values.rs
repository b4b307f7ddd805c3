//! Checked scene values. Range checks run inside `Deserialize` so ron attaches the position of the
//! offending value; [`Mark`] positions checks that need the whole scene (see `super::load`).

use glam::DVec3;
use serde::de::{Deserialize, Deserializer, Error};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// Largest magnitude of any number in a scene: beyond it, f32 kernels (and f32 fields such as
/// texel shapes) overflow (the prism checks' `MAX_COORD`).
pub(crate) const MAX_MAGNITUDE: f64 = crate::mesh::prism::MAX_COORD;
/// Smallest magnitude of a non-zero number: below it, f32 kernels flush it to 0 (a denormal) or
/// its square does, and a positive length divides by zero (`opacity_length: 1e-45` made NaN
/// pixels).
pub(crate) const MIN_MAGNITUDE: f64 = 1e-15;

/// A newtype `$name` whose `Deserialize` refuses values outside `$ok` (and beyond what f32
/// kernels hold), with ron's position; method knobs (`methods/<m>/knobs.rs`) define theirs too.
macro_rules! checked_f64 {
    ($name:ident, $ok:expr, $what:literal) => {
        #[derive(Clone, Copy)]
        struct $name(f64);
        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                use serde::de::Error as _;
                use $crate::scene::values::{MAX_MAGNITUDE, MIN_MAGNITUDE};
                let v = f64::deserialize(d)?;
                let ok: fn(f64) -> bool = $ok;
                if v.is_finite() && v.abs() > MAX_MAGNITUDE {
                    Err(D::Error::custom(format!(
                        concat!("expected ", $what, " within ±{:e}, found {:e}"),
                        MAX_MAGNITUDE, v
                    )))
                } else if v != 0.0 && v.abs() < MIN_MAGNITUDE {
                    Err(D::Error::custom(format!(
                        concat!(
                            "expected ",
                            $what,
                            " of 0 or at least {:e} in magnitude (f32 on the GPU), found {:e}"
                        ),
                        MIN_MAGNITUDE, v
                    )))
                } else if v.is_finite() && ok(v) {
                    Ok($name(v))
                } else {
                    Err(D::Error::custom(format!(concat!("expected ", $what, ", found {}"), v)))
                }
            }
        }
    };
}
pub(crate) use checked_f64;

checked_f64!(Finite, |_| true, "a finite number");
checked_f64!(Positive, |v| v > 0.0, "a positive finite number");
checked_f64!(NonNegative, |v| v >= 0.0, "a finite number >= 0");
checked_f64!(Unit, |v| (0.0..=1.0).contains(&v), "a number in [0, 1]");
checked_f64!(OpenUnit, |v| v > 0.0 && v < 1.0, "a number in (0, 1)");
checked_f64!(Anisotropy, |v| v > -1.0 && v < 1.0, "an anisotropy g in (-1, 1)");
checked_f64!(NonZero, |v| v != 0.0, "a finite non-zero number");
checked_f64!(Jitter, |v| (0.0..0.5).contains(&v), "a jitter in [0, 0.5) (fraction of a cell)");
checked_f64!(Distortion, |v| (0.0..0.9).contains(&v), "a distortion in [0, 0.9)");
checked_f64!(FieldOfView, |v| v > 0.0 && v < 180.0, "a field of view in (0, 180) degrees");
checked_f64!(ShadowBias, |v| (0.0..=8.0).contains(&v), "a shadow bias in [0, 8] voxels");

/// A newtype `$name` whose `Deserialize` refuses values outside `$lo..=$hi`.
macro_rules! checked_u32 {
    ($name:ident, $lo:expr, $hi:expr, $what:literal) => {
        #[derive(Clone, Copy)]
        struct $name(u32);
        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                use serde::de::Error as _;
                let v = u32::deserialize(d)?;
                if ($lo..=$hi).contains(&v) {
                    Ok($name(v))
                } else {
                    Err(D::Error::custom(format!(
                        concat!("expected ", $what, " in {}..={}, found {}"),
                        $lo, $hi, v
                    )))
                }
            }
        }
    };
}
pub(crate) use checked_u32;

checked_u32!(OutputSize, 1, 16384, "an output size");
checked_u32!(Resolution, 1, 1024, "a resolution");
checked_u32!(Octaves, 1, 8, "an octave count");
checked_u32!(Supersample, 1, super::MAX_SUPERSAMPLE, "samples per pixel axis");
checked_u32!(Frequency, 1, 1024, "a frequency (lattice cells per tile)");
checked_u32!(Cells, 1, 4096, "a cell count");
checked_u32!(Around, 3, 4096, "a segment count");
checked_u32!(PoleToPole, 2, 4096, "a segment count");
checked_u32!(
    GridResolution,
    4,
    crate::mesh::shape::MAX_RESOLUTION,
    "a mesh grid resolution (samples per axis)"
);

// `deserialize_with` adapters: public types stay plain (f64, DVec3, [f32; 3], u32).
macro_rules! adapter {
    ($fn:ident, $ty:ty, $via:ty, $map:expr) => {
        pub(crate) fn $fn<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
            let map: fn($via) -> $ty = $map;
            <$via as serde::Deserialize>::deserialize(d).map(map)
        }
    };
}
pub(crate) use adapter;

adapter!(positive, f64, Positive, |v| v.0);
adapter!(finite, f64, Finite, |v| v.0);
adapter!(positive3, DVec3, [Positive; 3], |v| DVec3::new(v[0].0, v[1].0, v[2].0));
adapter!(rgba, [f64; 4], [Unit; 4], |v| v.map(|x| x.0));
adapter!(unit_list, Vec<f64>, Vec<Unit>, |v| v.into_iter().map(|x| x.0).collect());
adapter!(unit_rows, Vec<Vec<f64>>, Vec<Vec<Unit>>, |v| v
    .into_iter()
    .map(|r| r.into_iter().map(|x| x.0).collect())
    .collect());
adapter!(opt_positive, Option<f64>, Option<Positive>, |v| v.map(|x| x.0));
adapter!(non_negative, f64, NonNegative, |v| v.0);
adapter!(unit, f64, Unit, |v| v.0);
adapter!(open_unit, f64, OpenUnit, |v| v.0);
adapter!(anisotropy, f64, Anisotropy, |v| v.0);
adapter!(jitter, f64, Jitter, |v| v.0);
adapter!(distortion, f64, Distortion, |v| v.0);
adapter!(fov, f64, FieldOfView, |v| v.0);
adapter!(finite_f32, f32, Finite, |v| v.0 as f32);
adapter!(positive_f32, f32, Positive, |v| v.0 as f32);
adapter!(opt_positive_f32, Option<f32>, Option<Positive>, |v| v.map(|x| x.0 as f32));
adapter!(non_negative_f32, f32, NonNegative, |v| v.0 as f32);
adapter!(unit_f32, f32, Unit, |v| v.0 as f32);
adapter!(shadow_bias, f32, ShadowBias, |v| v.0 as f32);
adapter!(vec3, DVec3, [Finite; 3], |v| DVec3::new(v[0].0, v[1].0, v[2].0));
adapter!(scale3, DVec3, [NonZero; 3], |v| DVec3::new(v[0].0, v[1].0, v[2].0));
adapter!(positive2, [f64; 2], [Positive; 2], |v| [v[0].0, v[1].0]);
adapter!(point_f32, [f32; 3], [Finite; 3], |v| v.map(|x| x.0 as f32));
adapter!(radii_f32, [f32; 3], [Positive; 3], |v| v.map(|x| x.0 as f32));
adapter!(color, [f32; 3], [Unit; 3], |v| v.map(|x| x.0 as f32));
adapter!(light_color, [f32; 3], [NonNegative; 3], |v| v.map(|x| x.0 as f32));
adapter!(opt_color, Option<[f32; 3]>, Option<[Unit; 3]>, |v| v.map(|c| c.map(|x| x.0 as f32)));
adapter!(output_size, u32, OutputSize, |v| v.0);
adapter!(opt_size2, Option<[u32; 2]>, Option<[OutputSize; 2]>, |v| v.map(|s| s.map(|x| x.0)));
adapter!(resolution, [u32; 3], [Resolution; 3], |v| v.map(|x| x.0));
adapter!(octaves, u32, Octaves, |v| v.0);
adapter!(supersample, u32, Supersample, |v| v.0);
adapter!(grid_resolution, u32, GridResolution, |v| v.0);
adapter!(frequency, u32, Frequency, |v| v.0);
adapter!(cells, [u32; 2], [Cells; 2], |v| v.map(|x| x.0));
adapter!(sphere_segments, [u32; 2], (Around, PoleToPole), |v| [v.0 .0, v.1 .0]);
adapter!(torus_segments, [u32; 2], [Around; 2], |v| v.map(|x| x.0));

/// Longest node name: each object's name becomes the EXR attribute `voltex_object_NAME`, and
/// EXR attribute names are at most 255 bytes.
pub(crate) const MAX_NAME_BYTES: usize = 255 - "voltex_object_".len();

/// A node name that can be written as EXR metadata (checked here, not after the render).
pub(super) fn object_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let v = String::deserialize(d)?;
    if let Some(c) = v.chars().find(|&c| c as u32 > 0xff || c == '\0') {
        return Err(D::Error::custom(format!(
            "expected a name of Latin-1 characters without NUL (it is written as EXR metadata), found {c:?}"
        )));
    }
    if v.len() > MAX_NAME_BYTES {
        return Err(D::Error::custom(format!(
            "expected a name of at most {MAX_NAME_BYTES} bytes (it is written as EXR metadata), found {}",
            v.len()
        )));
    }
    Ok(v)
}

/// A sequence's frames: at least one (checked here so the error has the list's position).
pub(super) fn frames<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Mark<String>>, D::Error> {
    let v = Vec::<Mark<String>>::deserialize(d)?;
    if v.is_empty() {
        return Err(D::Error::custom("expected at least one texel name in a sequence, found `[]`"));
    }
    Ok(v)
}

/// A direction: finite and not zero.
pub(super) fn direction<'de, D: Deserializer<'de>>(d: D) -> Result<DVec3, D::Error> {
    let v = vec3(d)?;
    if v.length_squared() > 0.0 {
        Ok(v)
    } else {
        Err(D::Error::custom("expected a non-zero direction"))
    }
}

/// An optional direction: finite and not zero when given.
pub(super) fn opt_direction<'de, D: Deserializer<'de>>(d: D) -> Result<Option<DVec3>, D::Error> {
    match Option::<[Finite; 3]>::deserialize(d)? {
        None => Ok(None),
        Some(v) => match DVec3::new(v[0].0, v[1].0, v[2].0) {
            v if v.length_squared() > 0.0 => Ok(Some(v)),
            _ => Err(D::Error::custom("expected a non-zero direction")),
        },
    }
}

/// Prefix of the ron message of a [`Mark`] failure; the mapping uses the span's end (where the
/// value starts) for these and strips it.
pub(super) const MARK_PREFIX: &str = "\u{1}mark:";

/// Numbering of [`Mark`]s during one parse, and the messages to fail with (second pass).
#[derive(Default)]
pub(super) struct Marking {
    next: usize,
    pub(crate) fail: BTreeMap<usize, String>,
}

thread_local! {
    static MARKING: RefCell<Option<Marking>> = const { RefCell::new(None) };
}

/// Runs `f` with a fresh numbering (and the given failures) active on this thread.
pub(super) fn with_marking<T>(fail: BTreeMap<usize, String>, f: impl FnOnce() -> T) -> T {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            MARKING.with(|m| *m.borrow_mut() = None);
        }
    }
    MARKING.with(|m| *m.borrow_mut() = Some(Marking { next: 0, fail }));
    let _reset = Reset;
    f()
}

/// A value whose position in the scene file can be reported by a check made after parsing.
///
/// Parsing is deterministic, so the n-th mark of a first parse is the n-th mark of a second one;
/// the second parse fails at the marks whose checks failed, and ron attaches the position.
#[derive(Clone, PartialEq)]
pub struct Mark<T> {
    /// The parsed value.
    pub value: T,
    pub(super) seq: usize,
}
impl<T> std::ops::Deref for Mark<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.value
    }
}

impl<T: std::fmt::Debug> std::fmt::Debug for Mark<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.value.fmt(f)
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Mark<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (seq, fail) = MARKING.with(|m| match m.borrow_mut().as_mut() {
            Some(m) => {
                m.next += 1;
                (m.next - 1, m.fail.get(&(m.next - 1)).cloned())
            }
            None => (usize::MAX, None),
        });
        // Fail before reading the value: ron's span then ends where the value starts.
        if let Some(msg) = fail {
            return Err(D::Error::custom(format!("{MARK_PREFIX}{msg}")));
        }
        Ok(Mark { value: T::deserialize(d)?, seq })
    }
}
