//! Scene parsing and flattening (errors with positions are in tests/checks/scene_errors.rs).

use super::*;
use glam::DVec3;
use std::path::PathBuf;

/// The example from the scene format's specification, verbatim.
const SPEC_EXAMPLE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 512, height: 512),
    camera: (eye: (0.0, -3.4, 2.2), target: (0.0, 0.0, 0.0), up: (0.0, 0.0, 1.0), fov_y: 40.0),
    background: (0.02, 0.025, 0.035),
    ambient: 0.25,
    lights: [Directional(direction: (-0.4, 0.3, -1.0), color: (1.0, 1.0, 1.0), intensity: 1.0)],
    texels: {
        "torus_egg": (
            resolution: (128, 128, 128),
            opacity_length: 0.05,   // world length over which a voxel's stored alpha is reached (default 0.05)
            source: Implicit(shapes: [
                Torus(center: (0.5, 0.5, 0.25), major: 0.28, minor: 0.1, color: (0.85, 0.45, 0.2), opacity: 1.0),
                Ellipsoid(center: (0.5, 0.5, 0.6), radii: (0.14, 0.14, 0.26), color: (0.5, 0.75, 1.0), opacity: 0.35),
            ]),
        ),
    },
    nodes: [
        (
            name: "torus",
            transform: (translate: (0.0, 0.0, 0.0), rotate: (0.0, 0.0, 0.0), scale: (1.0, 1.0, 1.0)),   // rotate = Euler XYZ degrees; all optional
            surface: Torus(major: 1.0, minor: 0.45, segments: (24, 12), distortion: 0.15, seed: 1),
            height: (length: 0.35),     // optional scale: VertexAttribute | Texture(path: "x.png", channel: 0)
            uv_tiling: (4.0, 2.0),
            texel: "torus_egg",
            method: ViewSlices(planes: 400, trivial_reject: true, lighting: Baked),   // lighting: Baked | PerPixel; trivial_reject default true
            base_color: None,            // optional: draw the base surface opaque with this colour
            children: [],
        ),
    ],
)
"#;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-scene-unit-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn spec_example_parses() {
    let s = parse(SPEC_EXAMPLE, Path::new("spec.ron")).unwrap();
    assert_eq!(s.output, Output { width: 512, height: 512 });
    assert_eq!(s.camera.eye, DVec3::new(0.0, -3.4, 2.2));
    assert_eq!(s.texels["torus_egg"].resolution, [128; 3]);
    let o = s.objects().unwrap();
    assert_eq!(o.len(), 1);
    assert_eq!(o[0].surface.triangles.len(), 576);
    assert_eq!(o[0].texel.as_deref(), Some("torus_egg"));
    assert_eq!(
        o[0].method,
        Some(Method::ViewSlices(ViewSlices {
            planes: 400,
            trivial_reject: true,
            lighting: Lighting::Baked,
            compositor: Default::default(),
            lod: Default::default()
        }))
    );
    // uv tiling applied to corners: the torus seam reaches u = 4.
    let max_u = o[0].surface.corner_uvs.iter().flatten().map(|uv| uv.x).fold(0.0, f64::max);
    assert_eq!(max_u, 4.0);
}

#[test]
fn defaults() {
    let s = parse(
        "Scene(output: (width: 8, height: 8), camera: (eye: (0, -1, 0), target: (0, 0, 0)),\
         nodes: [(name: \"a\", surface: Plane(size: (1, 1), cells: (1, 1)), method: ViewSlices(planes: 4), texel: \"t\")],\
         texels: {\"t\": (resolution: (1, 1, 1), source: Constant(color: (1, 1, 1)))})",
        Path::new("d.ron"),
    )
    .unwrap();
    assert_eq!(s.ambient, 0.2);
    assert_eq!(s.camera.up, DVec3::Z);
    assert_eq!(s.texels["t"].opacity_length(&s.hypertextures), 0.05);
    let n = &s.nodes[0];
    assert_eq!((n.height.length, n.uv_tiling), (0.1, [1.0, 1.0]));
    assert_eq!(n.transform, Transform::default());
    let Method::ViewSlices(v) = &n.method.as_ref().unwrap().value else { panic!("not ViewSlices") };
    assert!(v.trivial_reject && v.lighting == Lighting::Baked);
}

fn scene_with_nodes(nodes: &str) -> Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(output: (width: 8, height: 8), camera: (eye: (0, -1, 0), target: (0, 0, 0)), nodes: [{nodes}])"
    );
    parse(&text, Path::new("n.ron")).unwrap()
}

#[test]
fn child_transform_is_parent_times_child() {
    let s = scene_with_nodes(
        "(name: \"p\", transform: (translate: (1, 0, 0), scale: (2, 2, 2)), children: [
            (name: \"c\", transform: (translate: (0, 1, 0), rotate: (90, 0, 0)),
             surface: Plane(size: (1, 1), cells: (1, 1)), height: (length: 0.1))])",
    );
    let o = s.objects().unwrap();
    assert_eq!(o.len(), 1, "group nodes without a surface make no object");
    let surf = &o[0].surface;
    // Plane corner (-0.5, -0.5, 0): rotate 90 about x -> (-0.5, 0, -0.5); + (0,1,0); * 2; + (1,0,0).
    assert!((surf.positions[0] - DVec3::new(0.0, 2.0, -1.0)).length() < 1e-12);
    // Height +z * 0.1: rotated to -y, scaled by 2.
    assert!((surf.heights[0] - DVec3::new(0.0, -0.2, 0.0)).length() < 1e-12);
    assert!(o[0].report.errors.is_empty());
}

#[test]
fn mirroring_keeps_heights_outside() {
    let s = scene_with_nodes(
        "(name: \"m\", transform: (scale: (-1, 1, 1)), surface: Sphere(radius: 1, segments: (8, 4)))",
    );
    let o = s.objects().unwrap();
    let surf = &o[0].surface;
    for t in 0..surf.triangles.len() {
        let i = surf.triangles[t][0] as usize;
        assert!(surf.face_normal(t).dot(surf.heights[i]) > 0.0);
    }
}

#[test]
fn height_from_vertex_attribute_and_texture() {
    let dir = temp_dir("heights");
    std::fs::write(
        dir.join("q.obj"),
        "v 0 0 0 1 0 0\nv 1 0 0 0.5 0 0\nv 1 1 0 0 0 0\nv 0 1 0 0.25 0 0\nf 1 2 3 4\n",
    )
    .unwrap();
    // 4 x 1 grey PNG: 0, 255, 255, 0 (pixel centres at u = 0.125, 0.375, 0.625, 0.875).
    let file = std::fs::File::create(dir.join("h.png")).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), 4, 1);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(&[0, 255, 255, 0]).unwrap();

    let text = r#"#![enable(implicit_some)]
Scene(output: (width: 8, height: 8), camera: (eye: (0, -1, 0), target: (0, 0, 0)), nodes: [
    (name: "attr", surface: Obj(path: "q.obj"), height: (length: 2.0, scale: VertexAttribute)),
    (name: "tex", surface: Plane(size: (1, 1), cells: (2, 1)),
     height: (length: 1.0, scale: Texture(path: "h.png", channel: 0))),
])"#;
    let path = dir.join("s.ron");
    std::fs::write(&path, text).unwrap();
    let o = load(&path).unwrap().objects().unwrap();
    let h: Vec<f64> = o[0].surface.heights.iter().map(|h| h.z).collect();
    assert_eq!(h, vec![2.0, 1.0, 0.0, 0.5]);
    // `Mesh(path)`, the surface's name, and `Obj(path)`, its first, read as the same surface.
    std::fs::write(&path, text.replace("Obj(path", "Mesh(path")).unwrap();
    let m = load(&path).unwrap().objects().unwrap();
    assert_eq!(m[0].surface.positions, o[0].surface.positions);
    assert_eq!(m[0].surface.heights, o[0].surface.heights);
    assert_eq!(o[0].report.warnings.len(), 1, "one zero height: {:?}", o[0].report);
    // Plane vertices at u = 0, 0.5, 1: wrapping makes u = 0 and 1 the mean of the end pixels.
    let h: Vec<f64> = o[1].surface.heights.iter().map(|h| h.z).collect();
    assert_eq!(h, vec![0.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
}
