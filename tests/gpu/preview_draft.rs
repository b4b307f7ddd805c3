//! The preview's draft frames while a drag goes on: drawn smaller and coarser, and the frame
//! refined when the drag stops is the frame a new preview draws from scratch at full quality.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use voltex::preview::{Outcome, Session};
use voltex::render::RenderOptions;
use voltex::scene::Method;

const SCENE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 32, height: 24),
    camera: (eye: (0.0, -2.5, 2.0), target: (0.0, 0.0, 0.1), up: (0.0, 0.0, 1.0), fov_y: 40.0),
    lights: [Directional(direction: (-0.3, 0.2, -1.0))],
    texels: {
        "balls": (
            resolution: (16, 16, 16),
            opacity_length: 0.05,
            source: Implicit(shapes: [Sphere(center: (0.5, 0.5, 0.4), radius: 0.3, color: (0.9, 0.5, 0.2))]),
        ),
    },
    hypertextures: {
        "blob": (object: Sphere(radius: 0.3),
            noises: [(shape: Curve([(0.0, 0.0, 1.0), (1.0, 1.0, 1.0)]), amplitude: 0.1, frequency: 3.0)],
            color: Step(threshold: 0.3, color: (0.8, 0.7, 0.6)), opacity_length: 0.05),
    },
    nodes: [
        (name: "ground", surface: Plane(size: (2.0, 2.0), cells: (2, 2)), height: (length: 0.4),
            texel: "balls", method: ViewSlices(planes: 24)),
        (name: "blob", transform: (translate: (0.0, 0.0, 0.6)), hypertexture: "blob",
            method: RayMarch(step: 0.02, shading: Phong)),
    ],
)
"#;

fn methods(s: &Session) -> Vec<Method> {
    s.renderer().unwrap().blueprint.objects.iter().filter_map(|o| o.scene_method()).collect()
}

#[test]
fn refined_frame_equals_a_full_quality_frame_from_scratch() {
    let dir = common::scratch_dir("voltex-draft");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut s = Session::open(&ctx, &scene, RenderOptions::default());
    assert!(s.error.is_none(), "{:?}", s.error);
    let full = s.render(&ctx).unwrap().unwrap().image;
    assert_eq!((full.width, full.height), (32, 24));

    // A drag: each step drawn at a quarter of the width and height, a quarter of the planes and
    // four times the ray step.
    s.draft = 4;
    let mut cam = *s.scene().unwrap().camera;
    for dx in [0.1, 0.2, 0.3] {
        cam.eye.x = dx;
        s.options.camera = Some(cam);
        assert!(matches!(s.rebuild(&ctx), Outcome::Rebuilt(_)));
        let draft = s.render(&ctx).unwrap().unwrap().image;
        assert_eq!((draft.width, draft.height), (8, 6));
    }
    let drafted = methods(&s);
    assert!(matches!(drafted[0], Method::ViewSlices(ref v) if v.planes == 6), "{drafted:?}");
    assert!(matches!(drafted[1], Method::RayMarch(ref h) if (h.step() - 0.08).abs() < 1e-12), "{drafted:?}");

    // The drag stops: refined at full quality, the same frame a new preview makes.
    s.draft = 1;
    assert!(matches!(s.rebuild(&ctx), Outcome::Rebuilt(_)));
    let refined = s.render(&ctx).unwrap().unwrap().image;
    let options = RenderOptions { camera: Some(cam), ..Default::default() };
    let mut fresh = Session::open(&ctx, &scene, options);
    let scratch = fresh.render(&ctx).unwrap().unwrap().image;
    assert_eq!((refined.width, refined.height), (32, 24));
    assert_eq!(methods(&s), methods(&fresh));
    assert!(refined.pixels == scratch.pixels, "the refined frame differs from a frame made from scratch");
    assert!(refined.pixels != full.pixels, "the camera moved: the frame must change");
    std::fs::remove_dir_all(&dir).ok();
}
