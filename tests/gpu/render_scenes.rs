//! Rendering on software Vulkan: a golden image per example scene, the analytic flat shell (a
//! constant volume over a plane must equal the box it encloses), brightness that does not depend
//! on the plane count, and no seams along prism edges.
use crate::common::adapter::Expectations;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use common::golden::{check_golden, Threshold};
use glam::DVec3;
use voltex::io::Image;
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene::{self, Scene};

fn render_blueprint(bp: Blueprint) -> Image {
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    assert_eq!(voltex::metrics::count_nonfinite(&frame.image), 0, "no NaN or infinity in any pixel");
    frame.image
}

fn render(scene: &Scene, opts: RenderOptions) -> Image {
    render_blueprint(Blueprint::new(scene, &opts).unwrap())
}

fn example(name: &str) -> Scene {
    scene::load(&voltex::project_root().join("scenes/view_slices").join(name)).unwrap()
}

const TEST_SIZE: Option<(u32, u32)> = Some((128, 128));

#[test]
fn golden_torus_egg() {
    let img = render(&example("torus_egg.ron"), RenderOptions { size: TEST_SIZE, ..Default::default() });
    check_golden("view_slices_torus_egg", &img, Threshold::Flip(0.01));
}

#[test]
fn golden_terrain() {
    let img = render(&example("terrain.ron"), RenderOptions { size: TEST_SIZE, ..Default::default() });
    check_golden("view_slices_terrain", &img, Threshold::Flip(0.01));
}

#[test]
fn golden_sphere_balls() {
    let img = render(&example("sphere_balls.ron"), RenderOptions { size: TEST_SIZE, ..Default::default() });
    check_golden("view_slices_sphere_balls", &img, Threshold::Flip(0.01));
}

#[test]
fn golden_cloud_over_moss() {
    let img =
        render(&example("cloud_over_moss.ron"), RenderOptions { size: TEST_SIZE, ..Default::default() });
    check_golden("view_slices_cloud_over_moss", &img, Threshold::Flip(0.01));
}

#[test]
fn golden_flat_box() {
    let img = render(&example("flat_box.ron"), RenderOptions { size: TEST_SIZE, ..Default::default() });
    check_golden("view_slices_flat_box", &img, Threshold::Flip(0.01));
}

/// A constant volume (colour c, opacity a per length L) on a flat 2x2 plane with equal height
/// vectors of length `h`, seen from straight above.
fn slab_scene(cells: u32, planes: u32, eye: (f64, f64, f64)) -> Scene {
    let src = format!(
        r#"#![enable(implicit_some)]
Scene(
    output: (width: 128, height: 128),
    camera: (eye: ({}, {}, {}), target: (0.0, 0.0, 0.25), up: (0.0, 1.0, 0.0), fov_y: 40.0),
    background: (0.1, 0.2, 0.3),
    ambient: 1.0,
    texels: {{ "fog": (resolution: (8, 8, 8), opacity_length: 0.4, source: Constant(color: (0.8, 0.6, 0.4), opacity: 0.6)) }},
    nodes: [(
        name: "slab",
        surface: Plane(size: (2.0, 2.0), cells: ({cells}, {cells})),
        height: (length: 0.5),
        texel: "fog",
        method: ViewSlices(planes: {planes}),
    )],
)"#,
        eye.0, eye.1, eye.2
    );
    scene::parse(&src, Path::new("slab.ron")).unwrap()
}

/// Pixel (x, y) centre's unit ray direction for a camera looking straight down -z with +y up.
fn ray(x: u32, y: u32, size: u32, fov_y_deg: f64) -> DVec3 {
    let t = (fov_y_deg.to_radians() * 0.5).tan();
    let u = ((x as f64 + 0.5) / size as f64 * 2.0 - 1.0) * t;
    let v = (1.0 - (y as f64 + 0.5) / size as f64 * 2.0) * t;
    DVec3::new(u, v, -1.0).normalize()
}

#[test]
fn flat_shell_equals_the_box_it_encloses() {
    let img = render(&slab_scene(4, 64, (0.0, 0.0, 3.0)), RenderOptions::default());
    // The volume is stored as rgba8: compare with the quantised opacity and premultiplied colour
    // (values chosen away from rounding ties).
    let a = (0.6f64 * 255.0).round() / 255.0;
    let colour = [0.8, 0.6, 0.4].map(|c: f64| (c * 0.6 * 255.0).round() / 255.0 / a);
    let background = [0.1, 0.2, 0.3];
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for y in 0..128 {
        for x in 0..128 {
            let d = ray(x, y, 128, 40.0);
            // Where the ray crosses the top (z = 0.5) and bottom (z = 0) planes of the slab.
            let top = DVec3::new(0.0, 0.0, 3.0) + d * (2.5 / -d.z);
            let bottom = DVec3::new(0.0, 0.0, 3.0) + d * (3.0 / -d.z);
            if [top, bottom].iter().any(|p| p.x.abs() > 0.95 || p.y.abs() > 0.95) {
                continue; // enters or leaves through a side: not the analytic case
            }
            let path = 0.5 / -d.z;
            let transmittance = (1.0 - a).powf(path / 0.4);
            let p = img.get(x, y);
            for c in 0..3 {
                let expected = colour[c] * (1.0 - transmittance) + background[c] * transmittance;
                let err = (p[c] as f64 - expected).abs() / expected;
                worst = worst.max(err);
            }
            checked += 1;
        }
    }
    eprintln!("flat slab: worst relative error {worst:.5} over {checked} pixels");
    assert!(checked > 4000, "{checked} pixels checked");
    assert!(worst < 0.01, "worst relative error {worst} against the analytic slab");
}

fn mean(img: &Image) -> f64 {
    img.pixels.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / img.pixels.len() as f64
}

#[test]
fn plane_count_changes_error_not_brightness() {
    let eye = (0.4, -1.8, 2.4);
    let coarse = mean(&render(&slab_scene(4, 24, eye), RenderOptions::default()));
    let fine = mean(&render(&slab_scene(4, 192, eye), RenderOptions::default()));
    eprintln!("mean brightness: {coarse:.5} with 24 planes, {fine:.5} with 192");
    assert!((coarse - fine).abs() / fine < 0.01, "mean brightness {coarse} with 24 planes, {fine} with 192");
}

/// Renders the slice polygons of one plane per object with the coverage debug graph: each pixel
/// holds how many polygons cover it.
fn coverage(scene: &Scene) -> Image {
    let graph = voltex::project_root().join("graphs/slice_coverage.ron");
    render(
        scene,
        RenderOptions { planes: Some(1), graph: Some(graph), size: Some((256, 256)), ..Default::default() },
    )
}

/// Pixels covered twice (double blending), and cracks: uncovered pixels between covered ones that
/// lie on a thin line of uncovered pixels (at most two uncovered neighbours), which tells a crack
/// from a concave notch of the cross-section's boundary (open to the outside).
fn seams(img: &Image) -> (usize, usize, usize) {
    let (w, h) = (img.width, img.height);
    let at = |x: u32, y: u32| img.get(x, y)[0];
    let (mut covered, mut doubled, mut cracks) = (0, 0, 0);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let c = at(x, y);
            covered += (c >= 1.0) as usize;
            doubled += (c > 1.0) as usize;
            let across =
                (at(x - 1, y) >= 1.0 && at(x + 1, y) >= 1.0) || (at(x, y - 1) >= 1.0 && at(x, y + 1) >= 1.0);
            let uncovered_neighbours =
                (0..9).filter(|&i| i != 4 && at(x + i % 3 - 1, y + i / 3 - 1) == 0.0).count();
            cracks += (c == 0.0 && across && uncovered_neighbours <= 2) as usize;
        }
    }
    (covered, doubled, cracks)
}

/// "A constant-density volume on a closed mesh shows no seam pixels along prism edges": the
/// polygons of a plane through closed shells cover each pixel of the cross-section exactly once.
#[test]
fn closed_shells_show_no_seam_pixels() {
    for surface in [
        "Sphere(radius: 1.0, segments: (24, 12))",
        "Torus(major: 1.0, minor: 0.45, segments: (24, 12), distortion: 0.15, seed: 1)",
    ] {
        for eye in ["(0.3, -3.2, 1.6)", "(2.5, 1.0, 1.9)", "(0.01, 0.02, 3.4)"] {
            let src = format!(
                r#"Scene(output: (width: 256, height: 256), camera: (eye: {eye}, target: (0.0, 0.0, 0.0), fov_y: 45.0),
                texels: {{ "fog": (resolution: (4, 4, 4), source: Constant(color: (1.0, 1.0, 1.0))) }},
                nodes: [(name: "shell", surface: {surface}, height: (length: 0.3), texel: "fog", method: ViewSlices(planes: 1))])"#
            );
            let img = coverage(&scene::parse(&src, Path::new("closed.ron")).unwrap());
            let (covered, doubled, cracks) = seams(&img);
            eprintln!("{surface} from {eye}: {covered} pixels covered, {doubled} twice, {cracks} cracks");
            assert!(covered > 3000, "{surface} from {eye}: the cross-section covers {covered} pixels");
            assert_eq!((doubled, cracks), (0, 0), "{surface} from {eye}: pixels covered twice, cracks");
        }
    }
}

/// Two interpenetrating slabs (red and blue constant densities, tilted +-35 degrees about x):
/// their slices are interleaved by depth, so the image matches front-to-back ray marching of the
/// two media, and not compositing one object over the other.
#[test]
fn overlapping_objects_composite_plane_by_plane() {
    let node = |name: &str, angle: f64, texel: &str| {
        format!(
            r#"(name: "{name}", transform: (rotate: ({angle}, 0.0, 0.0)), surface: Plane(size: (2.0, 2.0), cells: (4, 4)),
                height: (length: 0.4), texel: "{texel}", method: ViewSlices(planes: 256))"#
        )
    };
    let src = format!(
        r#"Scene(output: (width: 96, height: 96), camera: (eye: (0.0, -3.0, 0.2), target: (0.0, 0.0, 0.2), fov_y: 40.0),
        background: (0.1, 0.1, 0.1), ambient: 1.0,
        texels: {{
            "red": (resolution: (4, 4, 4), opacity_length: 0.3, source: Constant(color: (0.9, 0.2, 0.1), opacity: 0.6)),
            "blue": (resolution: (4, 4, 4), opacity_length: 0.3, source: Constant(color: (0.1, 0.3, 0.9), opacity: 0.6)),
        }},
        nodes: [{}, {}])"#,
        node("a", 35.0, "red"),
        node("b", -35.0, "blue")
    );
    let scene = scene::parse(&src, Path::new("slabs.ron")).unwrap();
    let bp = Blueprint::new(&scene, &RenderOptions::default()).unwrap();
    let inv = glam::DMat4::from_cols_array_2d(&bp.frame.view_proj.map(|c| c.map(f64::from))).inverse();
    // Each slab: origin, unit normal and in-plane axes from its base surface; the stored rgba8
    // premultiplied colour and opacity, as the bake quantises them.
    let a_q = (0.6f64 * 255.0).round() / 255.0;
    let slabs: Vec<(DVec3, DVec3, DVec3, [f64; 3])> = bp
        .objects
        .iter()
        .zip([[0.9, 0.2, 0.1], [0.1, 0.3, 0.9]])
        .map(|(o, colour)| {
            let s = &o.object.surface;
            let origin = s.positions.iter().sum::<DVec3>() / s.positions.len() as f64 - bp.eye;
            let n = s.heights[0].normalize();
            let e1 = DVec3::X;
            (origin, n, n.cross(e1), colour.map(|c: f64| (c * 0.6 * 255.0).round() / 255.0 / a_q))
        })
        .collect();
    let layer = |s: &(DVec3, DVec3, DVec3, [f64; 3]), p: DVec3| {
        let d = p - s.0;
        let z = d.dot(s.1);
        d.x.abs() <= 1.0 && d.dot(s.2).abs() <= 1.0 && (0.0..=0.4).contains(&z)
    };
    let img = render_blueprint(bp);
    let step = 0.0005;
    let keep = 1.0 - (1.0 - a_q).powf(step / 0.3);
    let (mut err, mut err_unsorted, mut n) = (0.0, 0.0, 0);
    for y in 0..96 {
        for x in 0..96 {
            let ndc =
                glam::DVec4::new((x as f64 + 0.5) / 48.0 - 1.0, 1.0 - (y as f64 + 0.5) / 48.0, 0.5, 1.0);
            let h = inv * ndc;
            let dir = (h.truncate() / h.w).normalize();
            // Front-to-back marching; also each slab alone, to composite them object over object.
            let mut colour = [0.0; 3];
            let mut t_all = 1.0;
            let mut alone = [([0.0; 3], 1.0); 2];
            let mut inside = [false; 2];
            let mut t = 1.5;
            while t < 4.5 {
                let p = dir * t;
                for (i, s) in slabs.iter().enumerate() {
                    if layer(s, p) {
                        inside[i] = true;
                        let (seen, own) = (t_all * keep, alone[i].1 * keep);
                        for ((total, single), emitted) in colour.iter_mut().zip(&mut alone[i].0).zip(s.3) {
                            *total += seen * emitted;
                            *single += own * emitted;
                        }
                        t_all *= 1.0 - keep;
                        alone[i].1 *= 1.0 - keep;
                    }
                }
                t += step;
            }
            if !(inside[0] && inside[1]) {
                continue;
            }
            // Object over object, in the order the renderer used to draw them (a, then b over it).
            let unsorted: Vec<f64> =
                (0..3).map(|c| alone[1].0[c] + alone[1].1 * (alone[0].0[c] + alone[0].1 * 0.1)).collect();
            let p = img.get(x, y);
            for c in 0..3 {
                let exact = colour[c] + t_all * 0.1;
                err += (p[c] as f64 - exact).abs();
                err_unsorted += (unsorted[c] - exact).abs();
            }
            n += 3;
        }
    }
    let (err, err_unsorted) = (err / n as f64, err_unsorted / n as f64);
    eprintln!(
        "overlapping slabs: mean error {err:.4} over {} pixels; one object over the other: {err_unsorted:.4}",
        n / 3
    );
    assert!(n > 3000, "{} pixels see both slabs", n / 3);
    assert!(err < 0.01 && err_unsorted > 4.0 * err, "mean error {err}, object over object {err_unsorted}");
}

fn example_text(name: &str) -> String {
    std::fs::read_to_string(voltex::project_root().join("scenes/view_slices").join(name)).unwrap()
}

/// Positions are made camera-relative in f64 before they reach f32 kernels: the torus_egg scene
/// moved 1e5 away from the origin (camera too) renders as it does at the origin.
#[test]
fn scenes_far_from_the_origin_render_as_at_the_origin() {
    let text = example_text("torus_egg.ron");
    let moved = text
        .replace(
            "eye: (0.0, -4.6, 3.0), target: (0.0, 0.0, 0.0)",
            "eye: (100000.0, 99995.4, 3.0), target: (100000.0, 100000.0, 0.0)",
        )
        .replace("translate: (0.0, 0.0, 0.0)", "translate: (100000.0, 100000.0, 0.0)");
    assert_ne!(text, moved);
    let opts = || RenderOptions { size: TEST_SIZE, ..Default::default() };
    let here = render(&scene::parse(&text, Path::new("here.ron")).unwrap(), opts());
    let far = render(&scene::parse(&moved, Path::new("far.ron")).unwrap(), opts());
    let diff = voltex::metrics::max_abs_diff(&here, &far).unwrap();
    eprintln!("torus_egg at 1e5 from the origin: max abs difference {diff:e}");
    assert!(diff < 1e-3, "max abs difference {diff}");
}

/// A camera inside the shell: planes behind the near plane are skipped, the image is finite and
/// shows the texels around the camera.
#[test]
fn camera_inside_the_shell() {
    let text = example_text("torus_egg.ron").replace(
        "eye: (0.0, -4.6, 3.0), target: (0.0, 0.0, 0.0)",
        "eye: (1.62, 0.0, 0.0), target: (0.0, 1.0, 0.3)",
    );
    let img = render(
        &scene::parse(&text, Path::new("inside.ron")).unwrap(),
        RenderOptions { size: TEST_SIZE, ..Default::default() },
    );
    let lit = img.pixels.iter().filter(|p| p[0] > 0.2).count();
    assert!(lit > 2000, "{lit} pixels show texels");
}
