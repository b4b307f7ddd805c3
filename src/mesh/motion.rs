//! Animation of a base surface and its height vectors over time (Meyer & Neyret 1998, section 5):
//! a travelling wave deforms the base surface (a waving flag) and wind sways the height vectors
//! (grass). Applied in the node's own space before its transform; texel content is untouched.

use glam::DVec3;

use super::BaseSurface;

/// A travelling wave: each vertex moves along its height vector's direction by
/// `amplitude * sin(2 pi (p . direction / wavelength - speed * t))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Wave {
    pub(crate) amplitude: f64,
    pub(crate) wavelength: f64,
    /// Wavelengths per second.
    pub(crate) speed: f64,
    /// Direction the wave travels in (unit).
    pub(crate) direction: DVec3,
}

/// Wind: each height vector leans towards `direction` by `strength * sin(2 pi (frequency * t -
/// p . direction / wavelength))` (a fraction of its length) and keeps its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Wind {
    pub(crate) strength: f64,
    /// Sways per second.
    pub(crate) frequency: f64,
    /// Distance between gusts along `direction`.
    pub(crate) wavelength: f64,
    /// Direction the wind blows towards (unit).
    pub(crate) direction: DVec3,
}

const TAU: f64 = std::f64::consts::TAU;

impl Wave {
    pub(crate) fn offset(&self, p: DVec3, t: f64) -> f64 {
        self.amplitude * (TAU * (p.dot(self.direction) / self.wavelength - self.speed * t)).sin()
    }
}

impl Wind {
    pub(crate) fn lean(&self, p: DVec3, t: f64) -> f64 {
        self.strength * (TAU * (self.frequency * t - p.dot(self.direction) / self.wavelength)).sin()
    }
}

/// `base` at time `t`: positions moved by the wave, then heights leaned by the wind.
pub(crate) fn animate(base: &mut BaseSurface, wave: Option<&Wave>, wind: Option<&Wind>, t: f64) {
    for (p, h) in base.positions.iter_mut().zip(&mut base.heights) {
        let rest = *p;
        if let Some(w) = wave {
            *p += h.normalize_or_zero() * w.offset(rest, t);
        }
        if let Some(w) = wind {
            let length = h.length();
            let leaned = *h + w.direction * (w.lean(rest, t) * length);
            *h = leaned.normalize_or_zero() * length;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn strip() -> BaseSurface {
        let positions: Vec<DVec3> = (0..5).map(|i| DVec3::new(i as f64 * 0.25, 0.0, 0.0)).collect();
        BaseSurface {
            heights: vec![DVec3::new(0.0, 0.0, 0.2); positions.len()],
            positions,
            triangles: vec![],
            corner_uvs: vec![[DVec2::ZERO; 3]],
        }
    }

    #[test]
    fn the_wave_travels_and_the_wind_keeps_lengths() {
        let wave = Wave { amplitude: 0.1, wavelength: 1.0, speed: 0.5, direction: DVec3::X };
        let wind = Wind { strength: 0.5, frequency: 1.0, wavelength: 2.0, direction: DVec3::Y };
        let mut a = strip();
        animate(&mut a, Some(&wave), Some(&wind), 0.5);
        for (i, (p, h)) in a.positions.iter().zip(&a.heights).enumerate() {
            let x = i as f64 * 0.25;
            // Along the (vertical) height direction by the wave's offset at the rest position.
            assert!((p.z - 0.1 * (TAU * (x - 0.25)).sin()).abs() < 1e-12 && p.x == x, "{p}");
            assert!((h.length() - 0.2).abs() < 1e-12);
            assert!((h.y / h.z - wind.lean(DVec3::new(x, 0.0, 0.0), 0.5)).abs() < 1e-12, "{h}");
        }
        // One period later the surface is where it was.
        let mut b = strip();
        animate(&mut b, Some(&wave), Some(&wind), 0.5 + 2.0);
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert!((*p - *q).length() < 1e-9);
        }
    }
}
