//! Clicking in the view selects the object under the pointer: the pixel's ray (a pinhole through
//! the pixel's centre, as the ray casters' camera) against each textured object's shell, its base
//! triangles and their tops (base plus height vectors); the nearest hit wins. Hypertexture and
//! volume objects have no shell and are selected with `Tab`.

use glam::DVec3;

use crate::scene::{Camera, SceneObject};

/// The object whose shell the ray through pixel `(x, y)` of an image of `size` meets first, by
/// its index in `objects`.
pub(crate) fn pick(
    objects: &[&SceneObject],
    cam: &Camera,
    size: (u32, u32),
    (x, y): (f64, f64),
) -> Option<usize> {
    let forward = (cam.target - cam.eye).normalize_or_zero();
    let right = forward.cross(cam.up).normalize_or_zero();
    let up = right.cross(forward);
    let focal = 0.5 * size.1 as f64 / (0.5 * cam.fov_y.to_radians()).tan();
    let dir = forward * focal + right * (x - 0.5 * size.0 as f64) + up * (0.5 * size.1 as f64 - y);
    let mut best: Option<(f64, usize)> = None;
    for (i, o) in objects.iter().enumerate() {
        let s = &o.surface;
        for tri in &s.triangles {
            let [a, b, c] = tri.map(|v| v as usize);
            let top = |v: usize| s.positions[v] + s.heights[v];
            for (p, q, r) in [(s.positions[a], s.positions[b], s.positions[c]), (top(a), top(b), top(c))] {
                if let Some(t) = hit(cam.eye, dir, p, q, r) {
                    if best.is_none_or(|(d, _)| t < d) {
                        best = Some((t, i));
                    }
                }
            }
        }
    }
    best.map(|(_, i)| i)
}

/// Where (in units of `dir`) the ray from `o` along `dir` meets triangle `(a, b, c)`, in front.
fn hit(o: DVec3, dir: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_meets_a_triangle_inside_and_in_front_only() {
        let (a, b, c) = (DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, -1.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        let o = DVec3::new(0.0, 0.0, 5.0);
        assert_eq!(hit(o, DVec3::new(0.0, 0.0, -1.0), a, b, c), Some(5.0));
        assert_eq!(hit(o, DVec3::new(0.0, 0.0, 1.0), a, b, c), None, "behind");
        assert_eq!(hit(o, DVec3::new(0.5, 0.5, -1.0), a, b, c), None, "beside");
    }
}
