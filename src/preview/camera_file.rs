//! The preview's camera as scene-file text: the `camera: (...)` value written back into the scene
//! file when the user saves the view.

use crate::scene::Camera;

/// `camera: (...)` with `cam`'s values, as written into scene files.
pub(crate) fn format_camera(cam: &Camera) -> String {
    let v = |p: glam::DVec3| format!("({:.4}, {:.4}, {:.4})", p.x, p.y, p.z);
    format!("(eye: {}, target: {}, up: {}, fov_y: {:.3})", v(cam.eye), v(cam.target), v(cam.up), cam.fov_y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use std::path::Path;

    #[test]
    fn the_written_camera_reads_back() {
        let cam = Camera { eye: DVec3::new(1.0, 2.0, 3.0), target: DVec3::ZERO, up: DVec3::Z, fov_y: 30.0 };
        let text = format!(
            "Scene(\n    output: (width: 8, height: 8),\n    camera: {},\n    nodes: [],\n)\n",
            format_camera(&cam)
        );
        let scene = crate::scene::parse(&text, Path::new("c.ron")).unwrap();
        assert_eq!(*scene.camera, cam);
    }
}
