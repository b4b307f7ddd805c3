//! The frame's camera and light as methods plan against them.

use glam::{DMat4, DVec3, DVec4};

use crate::error::{Error, Result};
use crate::scene::{Camera, Light, Scene, SceneObject};
use crate::types::FrameParams;

/// The camera as the kernels see it (see `ReferenceParams`).
#[derive(Debug, Clone, Copy)]
pub struct RayCamera {
    /// The camera's position, world space.
    pub eye: DVec3,
    /// Right and up scaled by the half extents of the image at unit distance.
    pub right: DVec3,
    /// The camera's up, scaled as `right`.
    pub up: DVec3,
    /// Distance of the near plane.
    pub near: f64,
    /// Distance of the far plane.
    pub far: f64,
}

/// The camera, with the depth range of everything drawn for the projection's near and far planes.
#[derive(Debug, Clone)]
pub(crate) struct View {
    pub(crate) eye: DVec3,
    pub(crate) forward: DVec3,
    pub(crate) up: DVec3,
    pub(crate) fov_y: f64,
    pub(crate) near: f64,
    pub(crate) far: f64,
    /// Focal length in pixels (half the image height over tan(fov_y / 2)).
    pub(crate) focal: f64,
    /// The rendered size (for the ray casters' camera).
    pub(crate) size: (u32, u32),
}

impl View {
    pub(crate) fn new(scene: &Scene, cam: &Camera, objects: &[SceneObject]) -> Result<Self> {
        let forward = (cam.target - cam.eye).normalize_or_zero();
        if forward == DVec3::ZERO || forward.cross(cam.up).length_squared() < 1e-12 {
            return Err(Error::Invalid(format!(
                "{}: the camera's eye and target coincide, or `up` is parallel to the view direction",
                scene.path.display()
            )));
        }
        let mut far: f64 = 1e-3;
        for o in objects {
            if !o.surface.positions.is_empty() {
                // Only the corner boxes that may hold the farthest corner are scanned.
                far = far.max(o.prepared().farthest(&o.surface, cam.eye, forward).unwrap_or(far));
            }
            let hyper = o.hypertexture.as_ref().and_then(|n| Some((n, scene.hypertextures.get(&n.name)?)));
            if let Some((node, h)) = hyper {
                for c in h.world_corners(&node.to_world) {
                    far = far.max((c - cam.eye).dot(forward));
                }
            }
            for c in o.volume.iter().flat_map(|v| v.corners()) {
                far = far.max((c - cam.eye).dot(forward));
            }
        }
        far *= 1.01;
        let near = (far * 1e-4).max(1e-6);
        Ok(Self { eye: cam.eye, forward, up: cam.up, fov_y: cam.fov_y, near, far, focal: 1.0, size: (1, 1) })
    }

    /// The camera as ray casting kernels see it: a pixel's ray is `forward + sx right + sy up`.
    pub(crate) fn camera(&self) -> RayCamera {
        let right_dir = self.forward.cross(self.up).normalize();
        let up_dir = right_dir.cross(self.forward);
        let half = (0.5 * self.fov_y.to_radians()).tan();
        let aspect = self.size.0 as f64 / self.size.1 as f64;
        RayCamera {
            eye: self.eye,
            right: right_dir * half * aspect,
            up: up_dir * half,
            near: self.near,
            far: self.far,
        }
    }

    pub(crate) fn forward_f32(&self) -> [f32; 3] {
        self.forward.as_vec3().to_array()
    }

    pub(crate) fn frame_params(&self, scene: &Scene, size: (u32, u32), light: &FrameLight) -> FrameParams {
        let view = view_matrix(self.forward, self.up);
        let proj = projection(self.fov_y.to_radians(), size.0 as f64 / size.1 as f64, self.near, self.far);
        let (f, l, c, b) = (self.forward_f32(), light.direction, light.color, scene.background);
        FrameParams {
            view_proj: (proj * view).as_mat4().to_cols_array_2d(),
            forward: [f[0], f[1], f[2], self.near as f32],
            light_dir: [l[0], l[1], l[2], scene.ambient],
            light_color: [c[0], c[1], c[2], 1.0],
            background: [b[0], b[1], b[2], 1.0],
            viewport: [size.0 as f32, size.1 as f32, 1.0 / size.0 as f32, 1.0 / size.1 as f32],
        }
    }
}

/// The scene's first light (towards the light, colour times intensity) and ambient term.
pub struct FrameLight {
    pub(crate) direction: [f32; 3],
    pub(crate) color: [f32; 3],
    pub(crate) ambient: f32,
}

impl FrameLight {
    pub(crate) fn of(scene: &Scene) -> Self {
        let (direction, color) = match scene.lights.first() {
            Some(Light::Directional { direction, color, intensity }) => {
                (-direction.normalize(), color.map(|c| c * intensity))
            }
            None => (DVec3::new(0.3, 0.4, 1.0).normalize(), [1.0; 3]),
        };
        Self { direction: direction.as_vec3().to_array(), color, ambient: scene.ambient }
    }
}

/// Right-handed view rotation (the camera at the origin looks down -z in view space).
fn view_matrix(forward: DVec3, up: DVec3) -> DMat4 {
    let s = forward.cross(up).normalize();
    let u = s.cross(forward);
    DMat4::from_cols(
        DVec4::new(s.x, u.x, -forward.x, 0.0),
        DVec4::new(s.y, u.y, -forward.y, 0.0),
        DVec4::new(s.z, u.z, -forward.z, 0.0),
        DVec4::W,
    )
}

/// Perspective projection to wgpu clip space (depth 0 at `near`, 1 at `far`).
fn projection(fov_y: f64, aspect: f64, near: f64, far: f64) -> DMat4 {
    let h = 1.0 / (0.5 * fov_y).tan();
    let r = far / (near - far);
    DMat4::from_cols(
        DVec4::new(h / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, h, 0.0, 0.0),
        DVec4::new(0.0, 0.0, r, -1.0),
        DVec4::new(0.0, 0.0, r * near, 0.0),
    )
}
