//! RayMarch segments (Gilet & Dischler 2009, section 5): splat sets baked by `bake_splats.wgsl`
//! against their f64 twin and against the analytic sphere, depth-peeled intervals against their
//! twin and the torus's known ones, images against the whole-bounds march, and the limit of too
//! few passes on a concave object.
use crate::common::adapter::{gpu, Expectations};
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use glam::DVec3;
use voltex::cpu::bake_splats::bake_splats;
use voltex::cpu::hypertexture::Model;
use voltex::hypertexture::{mesh, splats};
use voltex::io::Image;
use voltex::methods::ray_march::peel_segments::peel_segments;
use voltex::methods::ray_march::RayMarchPlan;
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene;
use voltex::types::{MarchState, Splat};

fn plan_of(bp: &Blueprint) -> &RayMarchPlan {
    bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).unwrap()
}

const BUMPS: &str = "[(shape: Curve([(0.0, 0.0, 0.0), (1.0, 1.0, 0.0)]), amplitude: 0.12, frequency: 3.0, \
    shift: 0.5), (shape: Table([1.0, 0.0, 1.0]), amplitude: 0.04, frequency: 8.0, seed: 2)]";
/// Semi-transparent: the far side of an object shows through its near side.
const HAZE: &str =
    "Ramp([(0.0, (0.9, 0.8, 0.7, 0.0)), (0.2, (0.9, 0.8, 0.7, 0.3)), (1.0, (0.6, 0.7, 0.9, 0.6))])";
const SOLID: &str = "Step(threshold: 0.1, color: (0.8, 0.7, 0.6))";

/// One hypertexture on `object` seen from `eye` (looking at the origin), drawn with `method`.
fn scene_of(object: &str, color: &str, opacity_length: f64, eye: &str, method: &str) -> scene::Scene {
    placed(object, color, opacity_length, (eye, "(0.0, 0.0, 0.0)"), "()", method)
}

/// `scene_of` with the camera's (eye, target) and the node's transform.
fn placed(
    object: &str,
    color: &str,
    opacity_length: f64,
    (eye, target): (&str, &str),
    transform: &str,
    method: &str,
) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 48, height: 48),\n    camera: (eye: {eye}, target: \
         {target}, up: (0.0, 0.0, 1.0), fov_y: 40.0),\n    lights: [Directional(direction: (-0.5, 0.6, -0.7))],\n    \
         hypertextures: {{ \"h\": (object: {object}, noises: {BUMPS}, color: {color}, opacity_length: {opacity_length}) \
         }},\n    nodes: [(name: \"n\", transform: {transform}, hypertexture: \"h\", method: {method})],\n)\n"
    );
    scene::parse(&text, Path::new("test.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn model<'a>(plan: &'a RayMarchPlan, grid: Option<(&'a [[f32; 4]], f32)>) -> Model<'a> {
    Model { params: &plan.params, noises: &plan.packed.noises, tables: &[], grid }
}

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// Largest distance from a splat of `a` to the nearest of `b` (centres; radii and normals of that
/// nearest must agree too: returned as the largest radius difference and the smallest normal dot).
fn nearest(a: &[Splat], b: &[Splat]) -> (f64, f64, f64) {
    let (mut far, mut radius, mut dot) = (0.0f64, 0.0f64, 1.0f64);
    for s in a {
        let c = v3(s.center);
        let m = b
            .iter()
            .min_by(|x, y| (v3(x.center) - c).length().total_cmp(&(v3(y.center) - c).length()))
            .unwrap();
        far = far.max((v3(m.center) - c).length());
        radius = radius.max((m.center[3] - s.center[3]).abs() as f64);
        if s.normal != [0.0; 4] {
            dot = dot.min(v3(s.normal).dot(v3(m.normal)));
        }
    }
    (far, radius, dot)
}

/// The splat sets of a sphere, a torus and the Figure 11 teapot (a mesh, from its baked grid):
/// the kernel's and the twin's have the same splats, up to f32 rounding (cells whose centre lies
/// within rounding of the band's edge may be in one and not the other).
#[test]
fn splat_bake_kernel_matches_twin() {
    let teapot = scene::load(&voltex::project_root().join("scenes/hypertextures/fig11_teapot.ron")).unwrap();
    let peeled = |s: &scene::Scene| {
        let mut opts = sized(32, 32);
        opts.object_methods = vec![(
            s.nodes[0].name.clone(),
            scene::Method::RayMarch(scene::RayMarch {
                segments: scene::Segments::DepthPeeling { passes: 4, splat_grid: 24 },
                ..Default::default()
            }),
        )];
        Blueprint::new(s, &opts).unwrap()
    };
    let cases = [
        ("sphere", peeled(&scene_of("Sphere(radius: 1.0)", SOLID, 0.05, "(0.0, -4.0, 1.0)", "RayMarch()"))),
        (
            "torus",
            peeled(&scene_of(
                "Torus(major: 1.0, minor: 0.35)",
                SOLID,
                0.05,
                "(0.0, -4.0, 1.0)",
                "RayMarch()",
            )),
        ),
        ("teapot", peeled(&teapot)),
    ];
    let ctx = gpu!(ADAPTER);
    for (name, bp) in &cases {
        let plan = plan_of(bp);
        let grid = plan.bake_mesh_grid(&ctx).unwrap();
        let cells = grid.as_ref().map(|g| mesh::read(&ctx, g).unwrap());
        let set = plan.bake_splats(&ctx, grid.as_ref()).unwrap();
        let (surface, interior) = splats::read(&ctx, &set).unwrap();
        let lattice = &plan.peel.as_ref().unwrap().1;
        let (twin_surface, twin_interior) =
            bake_splats(&model(plan, cells.as_ref().map(|(c, d)| (&c[..], *d))), lattice);
        let (far, radius, dot) = nearest(&surface, &twin_surface);
        let (far_back, _, _) = nearest(&twin_surface, &surface);
        let (far_in, radius_in, _) = nearest(&interior, &twin_interior);
        eprintln!(
            "{name}: lattice {:?} (cell {:.4}), surface splats {} (twin {}), interior {} (twin {}); kernel vs twin: \
             centre {far:.2e} / {far_back:.2e}, radius {radius:.2e}, normal dot {dot:.6}; interior centre {far_in:.2e}, \
             radius {radius_in:.2e}",
            lattice.counts,
            lattice.cell,
            surface.len(),
            twin_surface.len(),
            interior.len(),
            twin_interior.len()
        );
        let close = |a: usize, b: usize| (a as f64 - b as f64).abs() <= 0.005 * b as f64 + 2.0;
        assert!(close(surface.len(), twin_surface.len()) && close(interior.len(), twin_interior.len()));
        assert!(surface.len() > 1000, "{} surface splats", surface.len());
        let tol = 1e-3 * lattice.cell;
        assert!(
            far < tol && far_back < tol && radius < 1e-5 && dot > 0.9999,
            "{far} {far_back} {radius} {dot}"
        );
        assert!(far_in < 1e-5 && radius_in < 1e-4 * lattice.cell.max(1.0), "{far_in} {radius_in}");
    }
}

/// A sphere of radius 1 under noises of total amplitude 0.16: every surface splat lies on the
/// sphere of radius 1 + 0.16 + half a cell with the radial normal; disks cover that sphere (no
/// gaps) and interior spheres fill it; the default lattice gives about the paper's count.
#[test]
fn sphere_splats_cover_the_enlarged_sphere() {
    let scene = scene_of(
        "Sphere(radius: 1.0)",
        SOLID,
        0.05,
        "(0.0, -4.0, 1.0)",
        "RayMarch(segments: DepthPeeling(passes: 2))",
    );
    let bp = Blueprint::new(&scene, &sized(16, 16)).unwrap();
    let plan = plan_of(&bp);
    let ctx = gpu!(ADAPTER);
    let set = plan.bake_splats(&ctx, None).unwrap();
    let (surface, interior) = splats::read(&ctx, &set).unwrap();
    drop(ctx);
    let lattice = plan.peel.as_ref().unwrap().1;
    let r = 1.0 + lattice.level;
    assert!((lattice.level - 0.16 - 0.5 * lattice.cell).abs() < 1e-4, "{}", lattice.level);
    let (mut off, mut tilt) = (0.0f64, 0.0f64);
    for s in &surface {
        let c = v3(s.center);
        off = off.max((c.length() - r).abs());
        tilt = tilt.max(1.0 - v3(s.normal).dot(c.normalize()));
    }
    eprintln!(
        "default lattice {:?}, cell {:.4}: {} surface + {} interior splats; radius off by {off:.2e}, normal by \
         {tilt:.2e}",
        lattice.counts,
        lattice.cell,
        surface.len(),
        interior.len()
    );
    assert!(off < 1e-4 && tilt < 1e-5, "{off} {tilt}");
    assert!((3000..=12000).contains(&(surface.len() + interior.len())));
    // Points on the splat surface (a Fibonacci sphere) lie on some disk: within its radius of its
    // centre and within rounding of its plane... or at most the sagitta off it on a sphere.
    let n = 4000;
    for i in 0..n {
        let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
        let phi = i as f64 * 2.399963229728653;
        let q = DVec3::new((1.0 - z * z).sqrt() * phi.cos(), (1.0 - z * z).sqrt() * phi.sin(), z) * r;
        let covered = surface.iter().any(|s| {
            let off = q - v3(s.center);
            let along = off.dot(v3(s.normal));
            (off - v3(s.normal) * along).length() <= s.center[3] as f64
        });
        assert!(covered, "{q} is on no disk");
        // Inside points (away from the surface by a cell) lie in some interior sphere.
        let p = q * ((r - lattice.cell) / r) * (i % 7) as f64 / 6.0;
        assert!(
            interior.iter().any(|s| (p - v3(s.center)).length() <= s.center[3] as f64),
            "{p} in no sphere"
        );
    }
}

/// Renders `scene` and returns the linear image, the marcher's states and `segment_bounds` (when
/// the object is depth-peeled), with the blueprint.
fn render(scene: &scene::Scene, opts: &RenderOptions) -> (Image, Vec<MarchState>, Vec<u32>, Blueprint) {
    render_blocks(scene, opts, None)
}

/// `render`, with footprints cut into blocks of `block` pixels (default: `FOOTPRINT_BLOCK`).
fn render_blocks(
    scene: &scene::Scene,
    opts: &RenderOptions,
    block: Option<u32>,
) -> (Image, Vec<MarchState>, Vec<u32>, Blueprint) {
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut bp = Blueprint::new(scene, opts).unwrap();
    for m in bp.objects.iter_mut().filter_map(|o| o.method_mut::<RayMarchPlan>()) {
        m.segments.counts[3] = block.unwrap_or(m.segments.counts[3]);
    }
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let image = r.render(&ctx).unwrap().image;
    let instance = r.blueprint.find_instance("RayMarch").unwrap();
    let states =
        bytemuck::pod_collect_to_vec(&r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap());
    let bounds =
        bytemuck::pod_collect_to_vec(&r.read_instance_buffer(&ctx, instance, "segment_bounds").unwrap());
    drop(ctx);
    let bp = Blueprint::new(scene, opts).unwrap();
    (image, states, bounds, bp)
}

fn evaluations(states: &[MarchState]) -> f64 {
    states.iter().map(|s| s.resume[1] as f64).sum()
}

const TORUS: &str = "Torus(major: 1.0, minor: 0.3)";

/// A torus seen edge-on, four passes: the kernel's boundaries equal the twin's (which tests every
/// splat against every ray) on every pixel, also with footprints cut into blocks of 50 pixels
/// (several invocations per splat); the ray through the middle crosses both sides of the tube:
/// two segments, where the splat surface (tube radius 0.3 + 0.16 + half a cell) says.
#[test]
fn peel_kernel_matches_twin_and_torus_has_two_segments() {
    let method = "RayMarch(step: 0.02, segments: DepthPeeling(passes: 4))";
    let scene = scene_of(TORUS, SOLID, 0.05, "(0.0, -4.0, 0.0)", method);
    let opts = sized(48, 48);
    let (_, _, bounds, bp) = render(&scene, &opts);
    let (_, _, blocked, _) = render_blocks(&scene, &opts, Some(50));
    let words = |b: &[u32]| b.chunks(10).flat_map(|p| p[1..].to_vec()).collect::<Vec<u32>>();
    assert_eq!(words(&bounds), words(&blocked), "blocks of 50 footprint pixels change nothing");
    let plan = plan_of(&bp);
    let ctx = gpu!(ADAPTER);
    let set = plan.bake_splats(&ctx, None).unwrap();
    let (surface, _) = splats::read(&ctx, &set).unwrap();
    drop(ctx);
    let m = model(plan, None);
    let stride = 10;
    let (mut worst, mut differ, mut two) = (0.0f64, 0, 0);
    for y in 0..48 {
        for x in 0..48 {
            let cpu = peel_segments(&bp.frame, &m, &plan.segments, &surface, x, y);
            let base = ((y * 48 + x) * stride) as usize;
            let gpu: Vec<f64> =
                bounds[base + 1..base + stride as usize].iter().map(|&b| f32::from_bits(b) as f64).collect();
            let mut same = true;
            for (g, c) in gpu.iter().zip(&cpu) {
                if g.is_infinite() || c.is_infinite() {
                    same &= g == c;
                } else {
                    worst = worst.max((g - c).abs());
                    same &= (g - c).abs() < 1e-4;
                }
            }
            differ += !same as usize;
            two += (gpu[3].is_finite() && gpu[4].is_finite()) as usize;
        }
    }
    eprintln!("{} surface splats; kernel vs twin: {differ} of 2304 pixels differ, largest difference {worst:.2e}; {two} pixels with two segments", surface.len());
    // A ray grazing a disk's rim may hit it in f32 and miss it in f64.
    assert!(differ <= 12, "{differ} pixels differ");
    assert!(two > 100, "{two} pixels with two segments");
    // The ray through the middle (pixel 24, 24, about the y axis): its segments hold the tube
    // where the density can be positive (radius 0.3 + 0.16) and lie within the splat surface
    // (tube radius 0.3 + its level; disks on the hole's side cut inside it by less than the
    // half-cell margin). The first entry lies before the bounds (y = -1.46): the marcher clips it.
    let lattice = plan.peel.as_ref().unwrap().1;
    let (support, splat) = (0.46, 0.3 + lattice.level);
    let cpu = peel_segments(&bp.frame, &m, &plan.segments, &surface, 24, 24);
    let inner = [4.0 - 1.0 - support, 4.0 - 1.0 + support, 4.0 + 1.0 - support, 4.0 + 1.0 + support];
    let outer = [4.0 - 1.0 - splat, 4.0 - 1.0 + splat, 4.0 + 1.0 - splat, 4.0 + 1.0 + splat];
    eprintln!("middle ray: {:?}; support {inner:?}; splat surface {outer:?}", &cpu[1..5]);
    for (i, c) in cpu[1..5].iter().enumerate() {
        let (entry, slack) = (i % 2 == 0, 1e-3);
        let contains = if entry { *c <= inner[i] + slack } else { *c >= inner[i] - slack };
        assert!(contains, "boundary {i}: {c} cuts into the support ({})", inner[i]);
        assert!(
            (c - outer[i]).abs() < 0.5 * lattice.cell,
            "boundary {i}: {c} far from the splat surface {}",
            outer[i]
        );
    }
    assert!(cpu[5].is_infinite());
}

/// A bumpy sphere (convex): depth peeling takes the bounds march's samples inside its segments,
/// so it gives the same image (within rounding), with fewer density evaluations (the point of
/// segments).
#[test]
fn convex_sphere_matches_the_bounds_march() {
    let opts = sized(64, 64);
    let march = |segments: &str| {
        let method = format!("RayMarch(step: 0.01, shading: Phong{segments})");
        render(&scene_of("Sphere(radius: 1.0)", SOLID, 0.02, "(0.0, -4.0, 1.0)", &method), &opts)
    };
    let (bounds, bounds_states, _, _) = march("");
    let (peeled, peeled_states, _, _) = march(", segments: DepthPeeling(passes: 2)");
    let flip = voltex::metrics::flip(&peeled, &bounds).unwrap().mean;
    let (a, b) = (evaluations(&peeled_states), evaluations(&bounds_states));
    eprintln!(
        "sphere, DepthPeeling(passes: 2) vs Bounds: FLIP {flip:.4}; density evaluations {a:.0} vs {b:.0}"
    );
    assert!(flip < 0.002, "FLIP {flip}");
    assert!(a < 0.95 * b, "{a} vs {b} evaluations");
}

/// A semi-transparent torus seen from above at a slant: rays through the near side of the tube
/// go on into the far side. Four passes match the whole-bounds march; one pass marches only the
/// first segment and loses the far side (the limit is real).
#[test]
fn one_pass_loses_the_far_side_of_a_concave_object() {
    let opts = sized(64, 64);
    let march = |segments: &str| {
        let method = format!("RayMarch(step: 0.01{segments})");
        let (image, states, _, _) = render(&scene_of(TORUS, HAZE, 1.0, "(0.0, -3.5, 0.6)", &method), &opts);
        (image, states.iter().map(|s| s.color[3] as f64).sum::<f64>())
    };
    let (bounds, bounds_coverage) = march("");
    let (four, four_coverage) = march(", segments: DepthPeeling(passes: 4)");
    let (one, one_coverage) = march(", segments: DepthPeeling(passes: 1)");
    let flip = |a: &Image, b: &Image| voltex::metrics::flip(a, b).unwrap().mean;
    let (f4, f1) = (flip(&four, &bounds), flip(&one, &bounds));
    eprintln!(
        "torus: FLIP against Bounds: 4 passes {f4:.4}, 1 pass {f1:.4}; coverage {bounds_coverage:.1} / \
         {four_coverage:.1} / {one_coverage:.1} (bounds / 4 / 1)"
    );
    assert!(f4 < 0.002, "4 passes: FLIP {f4}");
    assert!(f1 > 0.02, "1 pass: FLIP {f1}");
    assert!(one_coverage < 0.95 * four_coverage);
}

/// The example scene `teapot_depth_peeling.ron` (the Figure 11 teapot, a concave mesh: the
/// handle's hole, the spout, semi-transparent so far walls show): its four passes give the image
/// of the whole-bounds march, with fewer density evaluations (6% fewer: most are the Phong
/// gradients of samples inside the teapot, which both take).
#[test]
fn teapot_example_matches_the_bounds_march() {
    let path = voltex::project_root().join("scenes/hypertextures/teapot_depth_peeling.ron");
    let scene = scene::load(&path).unwrap();
    let march = |bounds: bool| {
        let mut opts = sized(96, 64);
        if bounds {
            let method = scene::RayMarch { shading: scene::Shading::Phong, ..Default::default() };
            opts.object_methods = vec![("teapot".into(), scene::Method::RayMarch(method))];
        }
        let (image, states, _, _) = render(&scene, &opts);
        (image, evaluations(&states))
    };
    let (peeled, a) = march(false);
    let (bounds, b) = march(true);
    let flip = voltex::metrics::flip(&peeled, &bounds).unwrap().mean;
    eprintln!(
        "teapot, DepthPeeling(passes: 4) vs Bounds: FLIP {flip:.5}; density evaluations {a:.0} vs {b:.0}"
    );
    assert!(flip < 0.002, "FLIP {flip}");
    assert!(a < 0.97 * b, "{a} vs {b} evaluations");
}

/// Depth peeling equals the bounds march on a sphere rotated and scaled unevenly (the footprints
/// and the splat radii in world units follow the node's transform), and with the eye inside the
/// object (every ray starts inside the splat surface: the start is its first entry).
#[test]
fn transformed_and_inside_views_match_the_bounds_march() {
    let opts = sized(48, 48);
    for (camera, transform) in common::TRANSFORMED_AND_INSIDE_VIEWS {
        let march = |segments: &str| {
            let method = format!("RayMarch(step: 0.01{segments})");
            let (image, states, _, _) =
                render(&placed("Sphere(radius: 1.0)", HAZE, 0.3, camera, transform, &method), &opts);
            (image, evaluations(&states))
        };
        let (bounds, b) = march("");
        let (peeled, a) = march(", segments: DepthPeeling(passes: 2)");
        let flip = voltex::metrics::flip(&peeled, &bounds).unwrap().mean;
        eprintln!(
            "eye {}, transform {transform}: FLIP {flip:.5}; density evaluations {a:.0} vs {b:.0}",
            camera.0
        );
        assert!(flip < 0.002, "FLIP {flip}");
        assert!(a <= b, "{a} vs {b}");
    }
}

/// The adaptive stride within depth-peeled segments (each segment begins at stride 1): on the
/// semi-transparent torus, whose rays cross two segments, the adaptive march with and without
/// depth peeling gives the fixed step's image, with fewer density evaluations.
#[test]
fn adaptive_stride_within_segments_matches_the_fixed_step() {
    let opts = sized(64, 64);
    let march = |knobs: &str| {
        let method = format!("RayMarch(step: 0.01{knobs})");
        let (image, states, _, _) = render(&scene_of(TORUS, HAZE, 1.0, "(0.0, -3.5, 0.6)", &method), &opts);
        (image, evaluations(&states))
    };
    let (fixed, n_fixed) = march("");
    let (adaptive, n_adaptive) = march(", adaptive: (max_step: 0.08)");
    let (peeled, n_peeled) = march(", adaptive: (max_step: 0.08), segments: DepthPeeling(passes: 4)");
    let flip = |a: &Image| voltex::metrics::flip(a, &fixed).unwrap().mean;
    let (f_adaptive, f_peeled) = (flip(&adaptive), flip(&peeled));
    eprintln!(
        "torus, adaptive stride up to 8 steps: FLIP against the fixed step {f_adaptive:.5} (bounds), {f_peeled:.5} \
         (4 passes); density evaluations {n_fixed:.0} fixed, {n_adaptive:.0} adaptive, {n_peeled:.0} adaptive peeled"
    );
    assert!(f_adaptive < 0.002 && f_peeled < 0.002, "{f_adaptive} {f_peeled}");
    assert!(n_adaptive < 0.7 * n_fixed && n_peeled < n_fixed, "{n_fixed} {n_adaptive} {n_peeled}");
}
