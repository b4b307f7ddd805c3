//! The numerical-stability catalogue (`scenes/hard_cases/`): every scene rendered with the
//! methods it applies to, with no NaN or infinity in any pixel, no crack or double blending on
//! shared edges (against the same slab as one quad), invariance under moving or scaling the whole
//! scene, and the error against the ground truth (the `Reference` method; for hypertextures the
//! f64 CPU twin of `ray_march`) within a bound stated per case in the tables below. The known
//! failure (horizontal slices only at a grazing view) is asserted as a failure. Unit cases on
//! the CPU twins (prism map inverse, ray intervals, slice polygons, axis choice) cover the
//! degenerate prism geometries.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use std::path::PathBuf;

use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::io::Image;
use voltex::methods::ray_march::march::{ray_march, MarchView};
use voltex::methods::ray_march::RayMarchPlan;
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene::{self, AxisSlices, Method, SliceBlend};
use voltex::types::MarchState;

fn path(name: &str) -> PathBuf {
    voltex::project_root().join("scenes/hard_cases").join(format!("{name}.ron"))
}

fn text(name: &str) -> String {
    std::fs::read_to_string(path(name)).unwrap()
}

/// How a texel scene is drawn for a check.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Draw {
    /// `ViewSlices`, with the scene's plane count (64 where the scene uses another method).
    View,
    /// `ViewSlices` with this many planes.
    Planes(u32),
    /// `AxisSlices` with the scene's knobs, or blended with the default knobs.
    Axis,
    /// The ground truth.
    Reference,
}

/// Renders scene text (parsed as if it were the file `name`) with `draw`; asserts every pixel is
/// finite.
fn render(name: &str, source: &str, draw: Draw) -> Image {
    let scene = scene::parse(source, &path(name)).unwrap_or_else(|e| panic!("{e}"));
    let mut opts = RenderOptions::default();
    match draw {
        Draw::View => {
            opts.method = Some(MethodKind::named("ViewSlices").unwrap());
            if !source.contains("ViewSlices(") {
                opts.planes = Some(64);
            }
        }
        Draw::Planes(n) => {
            opts.method = Some(MethodKind::named("ViewSlices").unwrap());
            opts.planes = Some(n);
        }
        Draw::Reference => opts.method = Some(MethodKind::named("Reference").unwrap()),
        Draw::Axis if !source.contains("AxisSlices(") => {
            let blended = AxisSlices { blend: SliceBlend::Blended, ..Default::default() };
            opts.object_methods =
                scene.nodes.iter().map(|n| (n.name.clone(), Method::AxisSlices(blended))).collect();
            opts.method = Some(MethodKind::named("AxisSlices").unwrap());
        }
        Draw::Axis => opts.method = Some(MethodKind::named("AxisSlices").unwrap()),
    }
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, Blueprint::new(&scene, &opts).unwrap()).unwrap();
    let image = r.render(&ctx).unwrap().image;
    let bad = voltex::metrics::count_nonfinite(&image);
    assert_eq!(bad, 0, "{name} with {draw:?}: {bad} pixels hold NaN or infinity");
    // To look at the renders: VOLTEX_HARD_CASES_OUT=DIR writes each as a tonemapped PNG.
    if let Ok(dir) = std::env::var("VOLTEX_HARD_CASES_OUT") {
        static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let file = PathBuf::from(dir).join(format!("{name}-{k:03}-{draw:?}.png"));
        voltex::io::png::write_tonemapped(&file, &image).unwrap();
    }
    image
}

fn flip(a: &Image, b: &Image) -> f64 {
    voltex::metrics::flip(a, b).unwrap().mean
}

fn max_diff(a: &Image, b: &Image) -> f64 {
    voltex::metrics::max_abs_diff(a, b).unwrap()
}

/// A texel scene of the catalogue: mean FLIP against the Reference per method, and optionally a
/// variant (text replacements) that must render the same (max abs difference per channel).
struct Case {
    scene: &'static str,
    /// (method, largest mean FLIP against the Reference).
    flip: &'static [(Draw, f64)],
    /// Replacements giving the same image by another route (one quad instead of many triangles,
    /// the scene at the origin, at unit scale), and the largest max abs difference per method.
    same_as: &'static [(&'static str, &'static str)],
    same_bound: &'static [(Draw, f64)],
}

use Draw::{Axis, Planes, Reference, View};

const ONE_QUAD: &str = "Plane(size: (2.0, 2.0), cells: (1, 1))";

/// The catalogue's texel scenes and their bounds (measured on llvmpipe, with a margin; see the
/// README's table). The Reference itself is checked for NaN in every case.
const CASES: &[Case] = &[
    Case {
        scene: "sliver_triangles",
        flip: &[(View, 0.02), (Axis, 0.02)],
        same_as: &[("Obj(path: \"sliver_square.obj\")", ONE_QUAD)],
        same_bound: &[(View, 1e-4), (Axis, 1e-4), (Reference, 1e-3)],
    },
    Case {
        scene: "split_slab",
        flip: &[(View, 0.02), (Axis, 0.02)],
        same_as: &[("Plane(size: (2.0, 2.0), cells: (16, 16), jitter: 0.25, seed: 3)", ONE_QUAD)],
        same_bound: &[(View, 1e-4), (Axis, 1e-4), (Reference, 1e-3)],
    },
    // ViewSlices: a known failure, see KNOWN_FAILURES.
    Case { scene: "zero_heights", flip: &[(Axis, 0.05)], same_as: &[], same_bound: &[] },
    // 64 planes: a known failure, see KNOWN_FAILURES; enough planes bring the error down.
    Case { scene: "thin_shell", flip: &[(Planes(1024), 0.02), (Axis, 0.01)], same_as: &[], same_bound: &[] },
    Case { scene: "thick_shell", flip: &[(View, 0.04), (Axis, 0.055)], same_as: &[], same_bound: &[] },
    Case { scene: "per_pixel_small_triangles", flip: &[(View, 0.015)], same_as: &[], same_bound: &[] },
    Case { scene: "grazing_89_9", flip: &[(View, 0.01), (Axis, 0.08)], same_as: &[], same_bound: &[] },
    // AxisSlices: the prisms whose layer holds the eye at the finest level, the slab holding the
    // eye split at it (0.45 before, with the criteria made for an eye outside).
    Case { scene: "camera_inside", flip: &[(View, 0.015), (Axis, 0.07)], same_as: &[], same_bound: &[] },
    Case { scene: "near_camera", flip: &[(View, 0.015), (Axis, 0.04)], same_as: &[], same_bound: &[] },
    Case { scene: "far_camera", flip: &[(View, 0.01), (Axis, 0.02)], same_as: &[], same_bound: &[] },
    Case {
        scene: "far_from_origin",
        flip: &[(View, 0.01), (Axis, 0.02)],
        same_as: &[
            (
                "eye: (100000.0, 99997.5, 2.5), target: (100000.0, 100000.0, 0.0)",
                "eye: (0.0, -2.5, 2.5), target: (0.0, 0.0, 0.0)",
            ),
            ("translate: (100000.0, 100000.0, 0.0)", "translate: (0.0, 0.0, 0.0)"),
        ],
        same_bound: &[(View, 1e-3), (Axis, 1e-3), (Reference, 1e-3)],
    },
    Case {
        scene: "tiny_scene",
        flip: &[(View, 0.01), (Axis, 0.02)],
        same_as: &[
            ("eye: (0.0, -0.00025, 0.00025)", "eye: (0.0, -2.5, 2.5)"),
            ("scale: (0.0001, 0.0001, 0.0001)", "scale: (1.0, 1.0, 1.0)"),
            ("opacity_length: 0.000005", "opacity_length: 0.05"),
        ],
        same_bound: &[(View, 1e-3), (Axis, 1e-3), (Reference, 1e-3)],
    },
    Case { scene: "single_slice", flip: &[(View, 0.02), (Axis, 0.07)], same_as: &[], same_bound: &[] },
    Case { scene: "criteria_finest", flip: &[(Axis, 0.015)], same_as: &[], same_bound: &[] },
    // Occlusion culling at a silhouette: identical with culling off.
    Case {
        scene: "culling_silhouette",
        flip: &[(Axis, 0.1)],
        same_as: &[("occlusion_culling: true", "occlusion_culling: false")],
        same_bound: &[(Axis, 0.0)],
    },
    // The coarsest level: one slab per tile, a large error by design.
    Case { scene: "criteria_coarsest", flip: &[(Axis, 0.16)], same_as: &[], same_bound: &[] },
    Case {
        scene: "texel_boundaries",
        // AxisSlices at the coarsest level (forced): a large error by design; the point is the
        // variant (one quad) being equal.
        flip: &[(View, 0.015), (Axis, 0.17)],
        same_as: &[("cells: (4, 4)", "cells: (1, 1)")],
        same_bound: &[(Axis, 1e-4), (View, 1e-4)],
    },
];

/// Where a method is known to fail: (scene, method, text replacement or none, the level its mean
/// FLIP against the Reference is asserted to exceed, why). The same scene stays within bound with
/// the other methods (CASES) or, for the known failure of the issue, with three directions.
/// (scene, method, text replacement, level, why).
type KnownFailure = (&'static str, Draw, Option<(&'static str, &'static str)>, f64, &'static str);

const KNOWN_FAILURES: &[KnownFailure] = &[
    (
        "grazing_horizontal",
        Axis,
        Some(("max_angle: 80.0", "max_angle: 80.0, directions: Horizontal")),
        0.04,
        "horizontal slices only, 85 degrees from the normal: the gaps between slices show",
    ),
    (
        "thin_shell",
        View,
        None,
        0.1,
        "64 planes across the view depth, a shell thinner than their spacing: each plane cuts it in a sub-pixel strip",
    ),
    (
        "zero_heights",
        View,
        None,
        // Above AxisSlices' bound on the same case (0.081 before slicing sampled level 0).
        0.05,
        "collapsed normal edges: the slice polygons' linear texture coordinates cannot follow the singular prism map",
    ),
];

/// Mean FLIP of the three-direction render of the known failure.
const THREE_DIRECTIONS_BOUND: f64 = 0.04;

fn check_case(case: &Case) -> Vec<String> {
    let source = text(case.scene);
    let reference = render(case.scene, &source, Reference);
    let mut failures = Vec::new();
    for &(draw, bound) in case.flip {
        let e = flip(&render(case.scene, &source, draw), &reference);
        eprintln!("{:<18} {draw:?}: mean FLIP {e:.4} against the Reference (bound {bound})", case.scene);
        if e.is_nan() || e > bound {
            failures.push(format!("{} {draw:?}: mean FLIP {e} > {bound}", case.scene));
        }
    }
    if !case.same_as.is_empty() {
        let mut other = source.clone();
        for (from, to) in case.same_as {
            assert!(other.contains(from), "{}: `{from}`", case.scene);
            other = other.replace(from, to);
        }
        for &(draw, bound) in case.same_bound {
            let a = if draw == Reference { reference.clone() } else { render(case.scene, &source, draw) };
            let d = max_diff(&a, &render(case.scene, &other, draw));
            eprintln!(
                "{:<18} {draw:?}: max abs difference {d:.2e} against its variant (bound {bound})",
                case.scene
            );
            if d.is_nan() || d > bound {
                failures.push(format!(
                    "{} {draw:?}: max abs difference {d} > {bound} against its variant",
                    case.scene
                ));
            }
        }
    }
    failures
}

fn check_cases(names: &[&str]) {
    let failures: Vec<String> =
        CASES.iter().filter(|c| names.contains(&c.scene)).flat_map(check_case).collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn prisms_degenerate_triangles_and_heights() {
    check_cases(&["sliver_triangles", "split_slab", "zero_heights"]);
}

#[test]
fn prisms_thin_and_thick_shells() {
    check_cases(&["thin_shell", "thick_shell", "per_pixel_small_triangles"]);
}

#[test]
fn views_grazing_inside_near_and_far() {
    check_cases(&["grazing_89_9", "camera_inside", "near_camera", "far_camera"]);
}

#[test]
fn views_far_from_the_origin_and_tiny() {
    check_cases(&["far_from_origin", "tiny_scene"]);
}

#[test]
fn slices_single_limits_and_boundaries() {
    check_cases(&["single_slice", "criteria_finest", "criteria_coarsest", "texel_boundaries"]);
}

/// Every scene file of the catalogue is in a table of this file.
#[test]
fn every_hard_case_is_checked() {
    let dir = voltex::project_root().join("scenes/hard_cases");
    let mut listed: Vec<&str> = CASES.iter().map(|c| c.scene).collect();
    listed.extend(HYPER_CASES.iter().map(|c| c.0));
    listed.extend(KNOWN_FAILURES.iter().map(|k| k.0));
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "ron") {
            let stem = p.file_stem().unwrap().to_str().unwrap().to_string();
            assert!(listed.contains(&stem.as_str()), "{stem}.ron is in no table of tests/gpu/hard_cases.rs");
            let first = std::fs::read_to_string(&p).unwrap();
            assert!(first.starts_with("// Hard case"), "{stem}.ron begins with what the case is");
            assert!(first.contains("Correct:"), "{stem}.ron says what correct means");
        }
    }
}

/// Each known failure is asserted as one: its error stays above the stated level (if a change
/// fixes it, move the case to CASES with a bound). The case, horizontal slices at a
/// grazing view, is also checked against three directions, which stay within bound.
#[test]
fn known_failures_stay_known() {
    let mut surprises = Vec::new();
    for &(name, draw, replace, above, why) in KNOWN_FAILURES {
        let source = text(name);
        let failing = match replace {
            Some((from, to)) => {
                assert!(source.contains(from), "{name}: `{from}`");
                source.replace(from, to)
            }
            None => source.clone(),
        };
        let reference = render(name, &source, Reference);
        let e = flip(&render(name, &failing, draw), &reference);
        eprintln!("{name:<18} {draw:?}: mean FLIP {e:.4}, known failure above {above} ({why})");
        if e.is_nan() || e <= above {
            surprises.push(format!("{name} {draw:?}: FLIP {e} is no longer above {above}"));
        }
        if name == "grazing_horizontal" {
            let three = flip(&render(name, &source, Axis), &reference);
            eprintln!("{name:<18} three directions: mean FLIP {three:.4} (bound {THREE_DIRECTIONS_BOUND})");
            assert!(three <= THREE_DIRECTIONS_BOUND, "three directions: FLIP {three}");
        }
    }
    assert!(surprises.is_empty(), "{surprises:#?}");
}

/// Per-pixel lighting through the texel-to-world Jacobian equals the baked lighting where the
/// latter is exact (isotropic texel cubes, z up), on triangles of area 1/32: the vertex frames
/// must be the uv derivatives themselves, not sums weighted by the area around the vertex
/// (that gave 0.092 for ViewSlices).
#[test]
fn per_pixel_lighting_on_small_triangles_equals_baked() {
    let name = "per_pixel_small_triangles";
    let source = text(name);
    let baked = source.replace("lighting: PerPixel", "lighting: Baked");
    assert_ne!(source, baked);
    for draw in [View, Reference] {
        let e = flip(&render(name, &source, draw), &render(name, &baked, draw));
        eprintln!(
            "{name}: {draw:?} per-pixel against baked lighting: mean FLIP {e:.4} (bound {PER_PIXEL_BOUND})"
        );
        assert!(e <= PER_PIXEL_BOUND, "{draw:?}: FLIP {e}");
    }
}

/// Per-pixel lighting adds a Blinn highlight that baked lighting has not: the rest of the gap.
const PER_PIXEL_BOUND: f64 = 0.04;

/// Hypertexture scenes: per object, the largest mean and max difference of the GPU layer from
/// the f64 twin, and the largest share of pixels off by more than 0.02 in some channel.
/// (object, largest mean difference, largest max difference, largest share of pixels off).
type HyperBound = (&'static str, f64, f64, f64);

const HYPER_CASES: &[(&str, &[HyperBound])] = &[
    (
        "vanishing_fields",
        &[("centre", 1e-6, 1e-4, 0.0), ("closest", 1e-6, 1e-4, 0.0), ("swirl", 1e-6, 1e-4, 0.0)],
    ),
    // f32 noise coordinates: exact near the origin, degrading with the coordinates' magnitude.
    ("noise_far", &[("origin", 1e-6, 1e-3, 0.0), ("e3", 1e-4, 0.02, 0.005), ("e5", 2e-3, 0.5, 0.03)]),
    (
        "transfer_limits",
        &[("ramp_jump", 1e-6, 1e-3, 0.0), ("step_low", 1e-6, 1e-4, 0.0), ("step_high", 1e-5, 2e-3, 0.0)],
    ),
];

/// Per RayMarch object (by name): the kernel's premultiplied layer and the twin's.
type Layer = Vec<[f64; 4]>;

fn layers_and_twins(name: &str) -> Vec<(String, Layer, Layer)> {
    let scene = scene::load(&path(name)).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut r = Renderer::new(&ctx, Blueprint::new(&scene, &RenderOptions::default()).unwrap()).unwrap();
    let frame = r.render(&ctx).unwrap();
    let bad = voltex::metrics::count_nonfinite(&frame.image);
    assert_eq!(bad, 0, "{name}: {bad} pixels hold NaN or infinity");
    let f = r.blueprint.frame;
    let light = [0, 1, 2].map(|c| f.light_color[c] as f64);
    let view = MarchView::of_frame(&f, r.blueprint.size);
    let mut out = Vec::new();
    for instance in 0..r.blueprint.instances.len() {
        let (o, part) = (r.blueprint.instances[instance].object, r.blueprint.instances[instance].filters[0]);
        if part != "RayMarch" {
            continue;
        }
        let bytes = r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap();
        let gpu: Vec<[f64; 4]> = bytemuck::pod_collect_to_vec::<u8, MarchState>(&bytes)
            .iter()
            .map(|s| std::array::from_fn(|c| s.color[c] as f64 * if c < 3 { light[c] } else { 1.0 }))
            .collect();
        let object = &r.blueprint.objects[o];
        let plan = object.method::<RayMarchPlan>().unwrap();
        let tables = bake_transfer(&plan.packed.functions, &plan.packed.points);
        let model = Model { params: &plan.params, noises: &plan.packed.noises, tables: &tables, grid: None };
        let cpu = ray_march(&view, model, plan.shade);
        assert!(gpu.iter().chain(&cpu).flatten().all(|v| v.is_finite()), "{name}: non-finite layer values");
        out.push((object.object.name.clone(), gpu, cpu));
    }
    out
}

#[test]
fn hypertextures_vanishing_fields_far_noise_and_transfer_limits() {
    let mut failures = Vec::new();
    for &(name, bounds) in HYPER_CASES {
        for (object, gpu, cpu) in layers_and_twins(name) {
            let &(_, mean_bound, max_bound, off_bound) = bounds
                .iter()
                .find(|b| b.0 == object)
                .unwrap_or_else(|| panic!("{name}: {object} has no bound"));
            let (mut max, mut sum, mut off) = (0.0f64, 0.0, 0usize);
            for (g, c) in gpu.iter().zip(&cpu) {
                let d = (0..4).map(|k| (g[k] - c[k]).abs()).fold(0.0, f64::max);
                max = max.max(d);
                sum += (0..4).map(|k| (g[k] - c[k]).abs()).sum::<f64>() / 4.0;
                off += (d > 0.02) as usize;
            }
            let (mean, off) = (sum / gpu.len() as f64, off as f64 / gpu.len() as f64);
            let covered = cpu.iter().filter(|p| p[3] > 0.05).count();
            eprintln!(
                "{name:<16} {object:<10} against the f64 twin: mean {mean:.2e}, max {max:.2e}, {:.2}% pixels off by > 0.02, {covered} pixels covered",
                off * 100.0
            );
            if !(mean <= mean_bound && max <= max_bound && off <= off_bound) {
                failures.push(format!("{name} {object}: mean {mean}, max {max}, off {off}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

// ---------------------------------------------------------------------------------------------
// Unit cases on the CPU twins: the degenerate prism geometries of the catalogue, without a GPU.

mod twins {
    use glam::{DVec3, Vec2, Vec3};
    use voltex::cpu::prism_map::{inverse, ray_intervals, PrismCorners};
    use voltex::methods::axis_slices::slice_images::level_count;
    use voltex::methods::axis_slices::twin::{choose_axis, AxisFrame};
    use voltex::methods::view_slices::slice_prisms::slice_prism;
    use voltex::types::{AxisParams, Prism, ShellVertex};

    fn prism(bottom: [DVec3; 3], heights: [DVec3; 3]) -> PrismCorners {
        PrismCorners { bottom, top: [0, 1, 2].map(|i| bottom[i] + heights[i]), ids: [0, 1, 2] }
    }

    fn forward(p: &PrismCorners, b: [f64; 3], w: f64) -> DVec3 {
        (0..3).map(|i| (p.bottom[i] + (p.top[i] - p.bottom[i]) * w) * b[i]).sum()
    }

    const BASE: [DVec3; 3] =
        [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.1, 0.0), DVec3::new(0.2, 0.9, 0.05)];
    const BARYS: [[f64; 3]; 4] = [[1.0 / 3.0; 3], [0.8, 0.1, 0.1], [0.0, 0.5, 0.5], [0.05, 0.05, 0.9]];
    /// Heights sampled, the faces excluded: on a face, rounding of the position (relative to its
    /// magnitude) can exceed the root tolerance (relative to the cubic's coefficients, tiny for a
    /// thin shell), so a point on the face of a 1e-6 shell may fall outside; the faces of ordinary
    /// prisms are covered by `src/cpu/prism_map.rs`'s own tests.
    const WS: [f64; 5] = [1e-3, 0.01, 0.5, 0.99, 1.0 - 1e-3];

    /// Inverts `forward(b, w)` at every sample; returns the largest errors in w (relative to the
    /// `w_scale`) and in position (relative to `size`).
    fn round_trip(p: &PrismCorners, barys: &[[f64; 3]]) -> (f64, f64) {
        let size = (p.bottom[1] - p.bottom[0]).length().max((p.top[0] - p.bottom[0]).length());
        let (mut dw, mut dx) = (0.0f64, 0.0f64);
        for &b in barys {
            for w in WS {
                let x = forward(p, b, w);
                let (b2, w2) = inverse(x, p).unwrap_or_else(|| panic!("{b:?} {w}: not found"));
                assert!(b2.iter().all(|v| v.is_finite()) && w2.is_finite());
                dw = dw.max((w2 - w).abs());
                dx = dx.max((forward(p, b2, w2) - x).length() / size);
            }
        }
        (dw, dx)
    }

    /// Near-parallel height vectors (differing by 1e-9: the cubic's leading coefficients vanish
    /// into rounding), a thin shell (heights 1e-6 of the base), a thick splayed one (heights 10x
    /// the base), a sliver base (altitude 1e-6), the prism moved 1e5 from the origin: (b, w)
    /// recovered everywhere. Regression: barycentrics from the normal equations lost 1/sin^2 to
    /// rounding, a position error of 3.4e-5 on the sliver (4.8e-12 as area ratios).
    #[test]
    fn prism_map_inverse_on_near_degenerate_prisms() {
        let up = DVec3::new(0.1, -0.2, 1.0);
        let far = DVec3::new(1e5, -1e5, 1e5);
        let cases: [(&str, PrismCorners, f64); 5] = [
            (
                "near-parallel",
                prism(BASE, [up, up + DVec3::new(1e-9, 0.0, 0.0), up + DVec3::new(0.0, 1e-9, 1e-9)]),
                1e-9,
            ),
            ("thin 1e-6", prism(BASE, [up * 1e-6; 3]), 1e-6),
            (
                "thick splayed",
                prism(
                    BASE,
                    [DVec3::new(-4.0, -3.0, 10.0), DVec3::new(5.0, -2.0, 10.0), DVec3::new(0.0, 6.0, 10.0)],
                ),
                1e-9,
            ),
            ("sliver base", prism([BASE[0], BASE[1], DVec3::new(0.5, 0.05 + 1e-6, 0.0)], [up; 3]), 1e-6),
            ("far from the origin", prism(BASE.map(|p| p + far), [up; 3]), 1e-6),
        ];
        for (what, p, bound) in cases {
            let (dw, dx) = round_trip(&p, &BARYS);
            eprintln!("{what}: w error {dw:.1e}, position error {dx:.1e} (relative)");
            assert!(dw < bound && dx < 1e-9, "{what}: w error {dw}, position {dx}");
        }
    }

    /// Zero-length height vectors: at one corner (a wedge) every point has a preimage that maps
    /// back onto it (w is free on the collapsed edge); with all three zero the prism has no
    /// volume and no ray spends any length in it.
    #[test]
    fn prism_map_inverse_with_zero_length_heights() {
        let up = DVec3::new(0.0, 0.0, 1.0);
        let wedge = prism(BASE, [up, DVec3::ZERO, up]);
        let (_, dx) = round_trip(&wedge, &BARYS);
        assert!(dx < 1e-9, "wedge: position error {dx}");
        // Away from the collapsed edge, (b, w) itself is recovered.
        let (dw, _) = round_trip(&wedge, &[[0.5, 0.2, 0.3], [0.3, 0.0, 0.7]]);
        assert!(dw < 1e-9, "wedge: w error {dw}");
        // All three zero: no volume. Points of the base may come back (at w = 0) or not, by
        // rounding; rays through it find no interval of positive length.
        let flat = prism(BASE.map(|p| p + DVec3::new(-0.4, -0.3, 2.0)), [DVec3::ZERO; 3]);
        for b in BARYS {
            let x = forward(&flat, b, 0.0);
            if let Some((b2, w)) = inverse(x, &flat) {
                assert!((forward(&flat, b2, w) - x).length() < 1e-12);
            }
            let d = x.normalize();
            let length: f64 =
                ray_intervals(d, &flat, 0.0, f64::INFINITY).iter().map(|(t0, t1)| t1 - t0).sum();
            assert!(length < 1e-12, "{b:?}: {length}");
        }
    }

    /// Zero-area bases have no inverse (no barycentrics) and rays through them no interval;
    /// twisted prisms (crossing heights, rejected by the scene checks) still give finite answers
    /// that map back onto the point.
    #[test]
    fn prism_map_on_zero_area_and_twisted_prisms() {
        let up = DVec3::new(0.0, 0.0, 1.0);
        let line =
            prism([DVec3::ZERO, DVec3::X, DVec3::X * 2.0].map(|p| p + DVec3::new(-1.0, 0.2, 3.0)), [up; 3]);
        for b in BARYS {
            assert!(inverse(forward(&line, b, 0.5), &line).is_none());
        }
        for i in 0..20 {
            let d = DVec3::new(-0.3 + 0.03 * i as f64, 0.066, 1.0);
            assert!(ray_intervals(d, &line, 0.0, f64::INFINITY).is_empty());
        }
        let twisted = prism(
            [DVec3::new(0.0, 0.0, 3.0), DVec3::new(1.0, 0.0, 3.0), DVec3::new(0.0, 1.0, 3.0)],
            [DVec3::new(1.0, 0.0, 1.0), DVec3::new(-1.0, 1.0, 1.0), DVec3::new(0.0, -1.0, 1.0)],
        );
        let mut found = 0;
        for i in 0..=20 {
            for j in 0..=20 {
                for k in 0..=10 {
                    let x = DVec3::new(-0.5 + 0.1 * i as f64, -0.5 + 0.1 * j as f64, 3.0 + 0.1 * k as f64);
                    if let Some((b, w)) = inverse(x, &twisted) {
                        assert!(b.iter().all(|v| v.is_finite()) && (0.0..=1.0).contains(&w));
                        assert!((forward(&twisted, b, w) - x).length() < 1e-9, "{x:?}");
                        found += 1;
                    }
                }
            }
        }
        assert!(found > 100, "{found} points inside");
    }

    /// A box split along its diagonal into two prisms sharing a side (welded ids): rays through
    /// the shared side, through the common normal edge and beside it are covered once, the
    /// intervals of both prisms adding up to the box's chord (no crack, no double count). A ray
    /// lying exactly in the shared side is counted by both prisms: see the README (known).
    #[test]
    fn ray_intervals_of_neighbours_add_up_to_the_chord() {
        let c = DVec3::new(-0.5, -0.5, 2.0);
        let corner = |x: f64, y: f64| c + DVec3::new(x, y, 0.0);
        let up = [DVec3::Z; 3];
        let mut a = prism([corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0)], up);
        a.ids = [0, 1, 2];
        let mut b = prism([corner(0.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)], up);
        b.ids = [0, 2, 3];
        let chord = |d: DVec3| {
            // Box [-0.5, 0.5]^2 x [2, 3] from the origin: entry and exit along d.
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for (lo, hi, v) in [(-0.5, 0.5, d.x), (-0.5, 0.5, d.y), (2.0, 3.0, d.z)] {
                if v == 0.0 {
                    if !(lo..=hi).contains(&0.0) {
                        return 0.0;
                    }
                    continue;
                }
                let (u0, u1) = ((lo / v).min(hi / v), (lo / v).max(hi / v));
                t0 = t0.max(u0);
                t1 = t1.min(u1);
            }
            (t1 - t0).max(0.0)
        };
        let covered = |d: DVec3| -> f64 {
            [&a, &b]
                .iter()
                .flat_map(|p| ray_intervals(d, p, 0.0, f64::INFINITY))
                .map(|(t0, t1)| t1 - t0)
                .sum()
        };
        let mut worst = 0.0f64;
        for i in 0..=40 {
            for j in 0..=40 {
                // Across the box, including rays through the normal edges at (0, 0) and (1, 1) of
                // the split (x = y = -0.5 and 0.5 at z = 2: i = j = 0 and 40 hit them exactly).
                let d = DVec3::new(-0.25 + 0.0125 * i as f64, -0.25 + 0.0125 * j as f64 + 1e-7, 1.0);
                let (got, want) = (covered(d), chord(d));
                worst = worst.max((got - want).abs());
            }
        }
        eprintln!("split box: largest difference from the chord {worst:.1e}");
        assert!(worst < 1e-9, "largest difference {worst}");
        // Known failure, stated: a ray exactly in the shared side's plane (x = y) is inside both
        // prisms by the inverse's tolerance, so both claim the segment (double counted). Pixel
        // rays meet this only when the eye lies in the plane of a shared side.
        let d = DVec3::new(0.05, 0.05, 1.0);
        let ratio = covered(d) / chord(d);
        eprintln!("ray in the shared side: covered {ratio:.3} times");
        assert!((ratio - 2.0).abs() < 1e-9, "covered {ratio} times (known: twice; if fixed, assert once)");
    }

    fn sv(bottom: [f32; 3], top: [f32; 3]) -> ShellVertex {
        ShellVertex { bottom: [bottom[0], bottom[1], bottom[2], 1.0], top: [top[0], top[1], top[2], 1.0] }
    }

    fn unit_prism(v: [u32; 3]) -> Prism {
        Prism { vertices: [v[0], v[1], v[2], 0], uv01: [0.0, 0.0, 1.0, 0.0], uv2: [0.0, 1.0, 0.0, 0.0] }
    }

    /// A sphere holding everything (the trivial reject is off in these tests anyway).
    const ALL: [f32; 4] = [0.0, 0.0, 0.0, 1e30];

    /// Planes a hair (1e-7 rad) off parallel to the base, through the middle and through the cap
    /// heights, and a prism whose base is a sliver (altitude 1e-6): finite polygons on the plane,
    /// the full triangle's area at mid height.
    #[test]
    fn slices_near_parallel_to_the_base_and_of_slivers() {
        let verts = [
            sv([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            sv([1.0, 0.0, 0.0], [1.0, 0.0, 1.0]),
            sv([0.0, 1.0, 0.0], [0.0, 1.0, 1.0]),
        ];
        let p = unit_prism([0, 1, 2]);
        let n = Vec3::new(1e-7, 0.0, 1.0).normalize();
        for d in [0.0f32, 1e-7, 0.5, 1.0 - 1e-7, 1.0] {
            let poly = slice_prism(&verts, &p, ALL, 0, n.to_array(), d, false);
            let pts: Vec<Vec3> = poly
                .as_slice()
                .iter()
                .map(|v| Vec3::new(v.position[0], v.position[1], v.position[2]))
                .collect();
            assert!(pts.iter().all(|q| q.is_finite() && (q.dot(n) - d).abs() < 1e-5), "d {d}: {pts:?}");
            assert!(poly.as_slice().iter().all(|v| v.uvw.iter().all(|c| c.is_finite())));
            if d == 0.5 {
                let area = (pts[1] - pts[0]).cross(pts[2] - pts[0]).length() * 0.5;
                assert_eq!(poly.len, 3);
                assert!((area - 0.5).abs() < 1e-5, "area {area}");
            }
        }
        let sliver = [
            sv([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            sv([1.0, 0.0, 0.0], [1.0, 0.0, 1.0]),
            sv([0.5, 1e-6, 0.0], [0.5, 1e-6, 1.0]),
        ];
        for k in 0..64 {
            let a = k as f32 * 0.1;
            let n = Vec3::new(a.cos() * 0.7, a.sin() * 0.7, 0.714).normalize();
            for d in [-0.2f32, 0.0, 0.3, 0.6, 1.0] {
                let poly = slice_prism(&sliver, &p, ALL, 0, n.to_array(), d, false);
                assert!(poly.len <= 5);
                for v in poly.as_slice() {
                    assert!(v.position.iter().chain(&v.uvw).all(|c| c.is_finite()), "k {k} d {d}: {v:?}");
                }
            }
        }
    }

    /// The axis choice on degenerate prisms: zero-length heights, a zero-area base, the eye at the
    /// prism's centre. Documented behaviour: a direction with no thickness is never chosen over
    /// one with thickness; without any, the w set at its coarsest level (nothing visible is
    /// drawn: zero thickness gives zero opacity); levels and counts always in range.
    #[test]
    fn axis_choice_on_degenerate_prisms() {
        let params = AxisParams {
            resolution: [16, 16, 16, 1],
            criteria: [1.0, 1.0, 80f32.to_radians(), 64.0],
            forward: [0.0, 0.0, -1.0, 0.0],
            flags: [0b111, 1 << 20, 0, 0],
        };
        let at = Vec3::new(0.0, 0.0, -3.0);
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y].map(|p| p + at);
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let cases = [
            ("zero heights", AxisFrame::new(tri, tri, uv)),
            ("one zero height", AxisFrame::new(tri, [tri[0] + Vec3::Z, tri[1], tri[2] + Vec3::Z], uv)),
            (
                "zero-area base",
                AxisFrame::new(
                    [at, at + Vec3::X, at + Vec3::X * 2.0],
                    [at, at + Vec3::X, at + Vec3::X * 2.0].map(|p| p + Vec3::Z),
                    uv,
                ),
            ),
            (
                "eye at the centre",
                AxisFrame::new(
                    tri.map(|p| p - at - Vec3::new(0.3, 0.3, 0.5)),
                    tri.map(|p| p - at - Vec3::new(0.3, 0.3, -0.5)),
                    uv,
                ),
            ),
        ];
        for (what, f) in cases {
            let c = choose_axis(&f, &params);
            eprintln!("{what}: direction {}, level {}, count {}", c.direction, c.level, c.count);
            assert!(c.direction < 3 && c.level < level_count(16) && c.count <= 4096, "{what}: {c:?}");
            if what == "zero heights" {
                assert_eq!((c.direction, c.level), (2, level_count(16) - 1), "{what}");
            }
        }
    }
}
