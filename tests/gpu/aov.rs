//! AOVs against analytic answers: a constant slab over the left half of the view and an opaque
//! floor under the right half, seen from straight above, give known transmittance, per-object
//! coverage and depth; the EXR holds them as named channels with the metadata and camera
//! attributes that say how the image was made.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use glam::DVec3;
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene::{self, Scene};

const SIZE: u32 = 64;
const FOV: f64 = 40.0;
const EYE_Z: f64 = 3.0;

/// A slab (x in [-2, 0], z in [0.5, 1], constant opacity `opacity` per 0.4) and an opaque floor
/// (x in [0, 2], z = 0), the camera at z = 3 looking down.
fn scene(opacity: f64) -> Scene {
    let src = format!(
        r#"#![enable(implicit_some)]
Scene(
    output: (width: {SIZE}, height: {SIZE}),
    camera: (eye: (0.0, 0.0, {EYE_Z}), target: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov_y: {FOV}),
    background: (0.1, 0.2, 0.3),
    ambient: 1.0,
    aovs: ["depth", "coverage", "transmittance"],
    texels: {{ "fog": (resolution: (8, 8, 8), opacity_length: 0.4, source: Constant(color: (0.8, 0.6, 0.4), opacity: {opacity})) }},
    nodes: [
        (
            name: "slab",
            transform: (translate: (-1.0, 0.0, 0.5)),
            surface: Plane(size: (2.0, 4.0), cells: (4, 4)),
            height: (length: 0.5),
            texel: "fog",
            method: ViewSlices(planes: 96),
        ),
        (
            name: "floor",
            transform: (translate: (1.0, 0.0, 0.0)),
            surface: Plane(size: (2.0, 4.0), cells: (1, 1)),
            base_color: (0.5, 0.5, 0.5),
        ),
    ],
)"#
    );
    scene::parse(&src, Path::new("aov_slab.ron")).unwrap()
}

/// The unit ray through pixel (x, y)'s centre.
fn ray(x: u32, y: u32) -> DVec3 {
    let t = (FOV.to_radians() * 0.5).tan();
    let u = ((x as f64 + 0.5) / SIZE as f64 * 2.0 - 1.0) * t;
    let v = (1.0 - (y as f64 + 0.5) / SIZE as f64 * 2.0) * t;
    DVec3::new(u, v, -1.0).normalize()
}

fn channel<'a>(frame: &'a voltex::render::Frame, name: &str) -> &'a [f32] {
    let names: Vec<&str> = frame.aovs.iter().map(|c| c.0.as_str()).collect();
    &frame.aovs.iter().find(|c| c.0 == name).unwrap_or_else(|| panic!("no channel {name} in {names:?}")).1
}

fn render(scene: &Scene, opts: RenderOptions) -> (voltex::render::Frame, Renderer) {
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, Blueprint::new(scene, &opts).unwrap()).unwrap();
    let frame = r.render(&ctx).unwrap();
    (frame, r)
}

#[test]
fn transmittance_coverage_and_depth_of_a_slab_beside_a_floor() {
    let (frame, _) = render(&scene(0.3), RenderOptions::default());
    let a = (0.3f64 * 255.0).round() / 255.0; // the texel is rgba8
    let (t, z) = (channel(&frame, "transmittance.Y"), channel(&frame, "Z"));
    let (slab, floor) = (channel(&frame, "coverage.slab.Y"), channel(&frame, "coverage.floor.Y"));
    let mut worst = [0.0f64; 4];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let (expect_t, expect_z) =
                if x < SIZE / 2 { ((1.0 - a).powf(0.5 / -ray(x, y).z / 0.4), 1e10) } else { (0.0, EYE_Z) };
            let (expect_slab, expect_floor) = if x < SIZE / 2 { (1.0 - expect_t, 0.0) } else { (0.0, 1.0) };
            worst[0] = worst[0].max((t[i] as f64 - expect_t).abs());
            worst[1] = worst[1].max((z[i] as f64 - expect_z).abs() / expect_z);
            worst[2] = worst[2].max((slab[i] as f64 - expect_slab).abs());
            worst[3] = worst[3].max((floor[i] as f64 - expect_floor).abs());
        }
    }
    eprintln!(
        "worst: transmittance {:.2e}, depth (relative) {:.2e}, coverage slab {:.2e}, floor {:.2e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!(worst[0] < 8e-3, "transmittance off by {}", worst[0]);
    assert!(worst[1] < 1e-5, "depth off by {} (relative)", worst[1]);
    assert!(worst[2] < 8e-3 && worst[3] < 1e-6, "coverage off by {:?}", &worst[2..]);
}

/// An opaque slab: its depth is that of its top face (z = 1, camera depth 2), found within one
/// plane spacing by view slicing and one step by the Reference. Axis slicing draws each slab's
/// slice at its far side, and each prism picks its level: the depth is within one slab of the
/// level chosen (here up to 2 of the texel's 8 layers, 1/8), one more where two prisms meet.
#[test]
fn depth_of_an_opaque_slab_by_slicing_and_by_the_reference() {
    let scene = scene(0.9);
    for (method, within) in [
        (None, 1.2 / 96.0),
        (Some(MethodKind::named("Reference").unwrap()), 0.01),
        (Some(MethodKind::named("AxisSlices").unwrap()), 3.0 / 16.0),
    ] {
        let opts = RenderOptions {
            method,
            step: (method == Some(MethodKind::named("Reference").unwrap())).then_some(0.005),
            aovs: Some(vec!["depth".into()]),
            ..Default::default()
        };
        let (frame, _) = render(&scene, opts);
        let z = channel(&frame, "Z");
        let left = (0..SIZE * SIZE).filter(|i| i % SIZE < SIZE / 2).map(|i| z[i as usize] as f64);
        let (lo, hi) = left.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        eprintln!("{method:?}: slab depth in [{lo:.5}, {hi:.5}]");
        assert!(
            lo >= 2.0 - 1e-4 && hi <= 2.0 + within,
            "{method:?}: depth in [{lo}, {hi}], expected [2, {}]",
            2.0 + within
        );
    }
}

/// The RayMarch kernel records its first opaque sample: a soft sphere (density 1 - |x|) drawn
/// as a step at density 0.3 is opaque from radius 0.7.
#[test]
fn depth_of_a_ray_marched_sphere() {
    let src = r#"#![enable(implicit_some)]
Scene(
    output: (width: 32, height: 32),
    camera: (eye: (0.0, 0.0, 4.0), target: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov_y: 30.0),
    aovs: ["depth", "coverage"],
    hypertextures: {
        "ball": (object: Sphere(radius: 1.0), noises: [(shape: Curve([(0.0, 0.0, 1.0), (1.0, 1.0, 1.0)]), amplitude: 0.0, frequency: 1.0, shift: 0.0)], color: Step(threshold: 0.3, color: (0.8, 0.7, 0.6), opacity: 1.0), opacity_length: 0.01),
    },
    nodes: [(name: "ball", hypertexture: "ball", method: RayMarch(step: 0.004))],
)"#;
    let scene = scene::parse(src, Path::new("aov_ball.ron")).unwrap();
    let (frame, _) = render(&scene, RenderOptions::default());
    let z = channel(&frame, "Z");
    // The four centre pixels' rays pass within 0.03 of the axis: the surface is at 3.3.
    for (x, y) in [(15, 15), (16, 15), (15, 16), (16, 16)] {
        let v = z[y * 32 + x] as f64;
        assert!((3.3 - 0.01..=3.3 + 0.005).contains(&v), "centre depth {v}, expected 3.3");
    }
    assert_eq!(z[0], 1e10, "a corner sees nothing opaque");
    let cover = channel(&frame, "coverage.ball.Y");
    assert!(cover[16 * 32 + 16] > 0.999 && cover[0] == 0.0);
}

/// The EXR holds the AOV channels by name, the string metadata and the camera attributes.
#[test]
fn exr_channels_metadata_and_camera_round_trip() {
    let (frame, r) = render(&scene(0.3), RenderOptions { time: Some(1.25), ..Default::default() });
    let ctx = gpu!(ADAPTER);
    let meta = r.metadata(&ctx, &frame);
    drop(ctx);
    let path = common::scratch_dir("aov_exr").join("slab.exr");
    let pairs: Vec<(&str, String)> = meta.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    let extras = voltex::io::exr::Extras {
        channels: &frame.aovs,
        camera: Some(r.camera_attributes()),
        fps: Some(24.0),
    };
    voltex::io::exr::write_with(&path, &frame.image, &pairs, &extras).unwrap();

    let (image, read_meta) = voltex::io::exr::read(&path).unwrap();
    assert_eq!(image.pixels, frame.image.pixels, "the colour is unchanged by the extra channels");
    let get = |k: &str| {
        read_meta.iter().find(|m| m.0 == k).map(|m| m.1.clone()).unwrap_or_else(|| panic!("no {k}"))
    };
    assert_eq!(get("voltex_version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(get("voltex_time"), "1.25");
    assert_eq!(get("voltex_aovs"), "depth,coverage,transmittance");
    assert!(get("voltex_graph").ends_with("frame.ron"));
    assert!(get("voltex_camera").starts_with("eye (0, 0, 3), forward (0.000000, 0.000000, -1.000000)"));
    assert!(get("voltex_object_slab").starts_with("ViewSlices(planes: 96"));
    assert_eq!(get("voltex_object_floor"), "BaseSurface");

    let (w, h, channels) = voltex::io::exr::read_channels(&path).unwrap();
    assert_eq!((w, h), (SIZE as usize, SIZE as usize));
    let names: Vec<&str> = channels.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["R", "G", "B", "A", "Z", "coverage.floor.Y", "coverage.slab.Y", "transmittance.Y"]);
    for (name, plane) in &frame.aovs {
        assert_eq!(&channels.iter().find(|c| &c.0 == name).unwrap().1, plane, "channel {name}");
    }

    // OpenEXR's attributes: world (x, y, 0) is at camera depth 3, and NDC maps the view's left
    // edge (x = -3 tan 20 degrees) to 0 and its top edge to 0.
    let exr = exr::prelude::read_first_flat_layer_from_file(&path).unwrap();
    let a = &exr.layer_data.attributes;
    let m = |mat: [f32; 16], p: [f64; 3]| -> [f64; 3] {
        let v = [p[0], p[1], p[2], 1.0];
        let c = |j: usize| (0..4).map(|i| v[i] * mat[i * 4 + j] as f64).sum::<f64>();
        [c(0) / c(3), c(1) / c(3), c(2) / c(3)]
    };
    let cam = m(a.world_to_camera.unwrap(), [0.5, -0.25, 0.0]);
    assert!(
        (cam[0] - 0.5).abs() < 1e-6 && (cam[1] + 0.25).abs() < 1e-6 && (cam[2] - 3.0).abs() < 1e-6,
        "{cam:?}"
    );
    let edge = 3.0 * (FOV.to_radians() * 0.5).tan();
    let ndc = m(a.world_to_normalized_device.unwrap(), [-edge, edge, 0.0]);
    assert!(ndc[0].abs() < 1e-5 && ndc[1].abs() < 1e-5, "top-left corner at NDC {ndc:?}");
    assert_eq!(a.frames_per_second, Some((24, 1)));
}

/// A volume object's coverage is its layer's opacity: over a white background a purely absorbing
/// box shows its transmittance, so `coverage.box` = 1 - R and `transmittance` = R per pixel.
#[test]
fn coverage_and_transmittance_of_an_absorbing_volume() {
    let path = common::root().join("scenes/volumes/absorbing_box.ron");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "background: (1.0, 1.0, 1.0),",
        "background: (1.0, 1.0, 1.0),\n    aovs: [\"coverage\", \"transmittance\"],",
    );
    let scene = scene::parse(&text, &path).unwrap();
    let (frame, _) = render(&scene, common::sized(32, 32));
    let (cover, trans) = (channel(&frame, "coverage.box.Y"), channel(&frame, "transmittance.Y"));
    let mut worst = 0.0f32;
    let mut seen = 0;
    for (i, p) in frame.image.pixels.iter().enumerate() {
        worst = worst.max((cover[i] - (1.0 - p[0])).abs()).max((trans[i] - p[0]).abs());
        seen += usize::from(cover[i] > 0.5);
    }
    assert!(seen > 50, "the box covers {seen} pixels");
    assert!(worst < 2e-3, "coverage or transmittance off by {worst}");
}
