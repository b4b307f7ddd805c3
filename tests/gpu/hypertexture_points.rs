//! Hypertexture point-set objects (Gilet & Dischler 2009, section 5.1): `bake_point_grid.wgsl`
//! against its brute-force f64 twin, known answers (one kernel, two kernels too far apart to
//! meet, a lattice that fills a box), the ray marcher's sampling against the twin's on the same
//! grid, images with and without splat segments, and bad point files reported at their position.
use crate::common::adapter::{gpu, Expectations};
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::hypertexture_mesh::{layer_and_twin, probes_match_twin};

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use voltex::cpu::bake_point_grid::{bake_point_grid, kernel};
use voltex::hypertexture::{mesh, points};
use voltex::mesh::points::PointSet;
use voltex::methods::ray_march::RayMarchPlan;
use voltex::render::Blueprint;
use voltex::scene;

/// Points scattered (a hash sequence) in a blob of radius 0.8 squashed along z.
fn blob(n: usize, seed: u32) -> Vec<DVec3> {
    let mut s = seed;
    let mut next = || {
        s = voltex::cpu::bake::pcg_hash(s);
        s as f64 / 4294967296.0 * 2.0 - 1.0
    };
    let mut out = Vec::new();
    while out.len() < n {
        let p = DVec3::new(next(), next(), next());
        if p.length() <= 1.0 {
            out.push(p * DVec3::new(0.8, 0.8, 0.5));
        }
    }
    out
}

fn object(set: PointSet, radius: f64, saturation: f64, n: u32) -> points::PointObject {
    let spec = set.grid(radius, n, 0.1);
    points::PointObject { set: Arc::new(set), radius, saturation, spec }
}

/// The kernel's grid of `object` and the twin's.
fn both(object: &points::PointObject) -> (Vec<[f32; 4]>, Vec<[f64; 4]>) {
    let ctx = gpu!(ADAPTER);
    let (cells, _) = mesh::read(&ctx, &points::bake(&ctx, object).unwrap()).unwrap();
    (cells, bake_point_grid(&object.set, object.radius, object.saturation, &object.spec))
}

/// 300 points with per-point radii (a PLY `radius` factor from 0.5 to 1.5) at 20^3: the kernel
/// (BVH walk, f32) against the twin (every point, f64), sample by sample: signed distance,
/// kernel sum and the vector to the closest surface point.
#[test]
fn bake_kernel_matches_twin() {
    let centres = blob(300, 3);
    let radii = (0..300).map(|i| 0.5 + (i % 11) as f64 / 10.0).collect();
    let o = object(PointSet::new(centres, Some(radii)), 0.15, 2.0, 20);
    let start = std::time::Instant::now();
    let (gpu, twin) = both(&o);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    assert_eq!(gpu.len(), twin.len());
    let (mut dist, mut sum, mut vector, mut inside, mut ties) = (0.0f64, 0.0f64, 0.0f64, 0, 0);
    let half = twin.len() / 2;
    for (i, (g, c)) in gpu.iter().zip(&twin).enumerate() {
        if i < half {
            dist = dist.max((g[3] as f64 - c[3]).abs());
            let v = (0..3).map(|k| (g[k] as f64 - c[k]).abs()).fold(0.0, f64::max);
            // Flooding may pick another boundary point at the same distance (within rounding).
            if v > 1e-4 && c[3] > 0.0 {
                ties += 1;
            } else {
                vector = vector.max(v);
            }
            inside += (c[3] > 0.0) as usize;
        } else {
            sum = sum.max((g[0] as f64 - c[0]).abs());
        }
    }
    eprintln!(
        "300 points at 20^3: bake + readback {ms:.1} ms; kernel vs twin: distance {dist:.2e}, kernel sum {sum:.2e}, \
         vector {vector:.2e} ({ties} equidistant boundary points picked otherwise); {inside} samples inside a kernel"
    );
    assert!(dist < 1e-5 && sum < 1e-5 && vector < 1e-4, "distance {dist}, sum {sum}, vector {vector}");
    assert!(ties * 100 < inside, "{ties} of {inside}");
    assert!(inside > 200 && inside < half - 1000, "{inside}");
}

/// Known answers. One kernel of radius 0.5: at every sample the density is (1 - d^2/R^2)^3 over
/// the saturation; outside, the signed distance is R - d and the vector points at the centre,
/// exactly; inside (flooded) within a fraction of a cell. Two kernels 1.2 apart (more than 2R): each sample sees one kernel only,
/// its own, so the sum is the larger of the two. A lattice of spacing h = 0.1 filling the box
/// [-0.5, 0.5]^3 with R = 2.5h: inside, more than R from the faces, the sum is the lattice's
/// Riemann sum of the kernel, (64 pi / 315) (R/h)^3 to 1% (the kernel's integral over h^3); with
/// that as the saturation, the density there is 1 to 1%: a saturated box; R beyond the faces it
/// is 0.
#[test]
fn known_answers() {
    let r = 0.5;
    let one = object(PointSet::new(vec![DVec3::new(0.1, -0.2, 0.05)], None), r, 0.5, 24);
    let (gpu, _) = both(&one);
    let n = 24 * 24 * 24;
    let cell = (one.spec.hi.x - one.spec.lo.x) / 23.0;
    let (mut worst, mut flooded) = ([0.0f64; 5], 0);
    for (i, g) in gpu[..n].iter().enumerate() {
        let i = i as u32;
        let p = one.spec.point(i % 24, (i / 24) % 24, i / 576);
        let d = (p - DVec3::new(0.1, -0.2, 0.05)).length();
        worst[0] = worst[0].max((gpu[n + i as usize][0] as f64 - kernel(d, r) / 0.5).abs());
        let v = DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64);
        let want = (DVec3::new(0.1, -0.2, 0.05) - p).normalize() * (d - r);
        if d >= r {
            worst[1] = worst[1].max((g[3] as f64 - (r - d)).abs());
            worst[2] = worst[2].max((v - want).length());
        } else {
            // Inside: the closest of the outside samples' boundary points, which lie on the
            // sphere at most a cell diagonal apart: off the exact one by less than that.
            worst[3] = worst[3].max((g[3] as f64 - (r - d)).abs() / cell);
            worst[4] = worst[4].max((v - want).length() / cell);
            flooded += 1;
        }
    }
    eprintln!(
        "one kernel: density {:.2e}; outside: signed distance {:.2e}, vector {:.2e}; inside ({flooded} samples, \
         flooded): distance within {:.3} cells, vector within {:.3} cells",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    assert!(worst[..3].iter().all(|&w| w < 2e-6), "{worst:?}");
    assert!(worst[3] < 0.3 && worst[4] < 3f64.sqrt() && flooded > 100, "{worst:?}");

    let (a, b) = (DVec3::new(-0.6, 0.0, 0.0), DVec3::new(0.6, 0.0, 0.0));
    let two = object(PointSet::new(vec![a, b], None), r, 1.0, 24);
    let (gpu, _) = both(&two);
    let mut worst: f64 = 0.0;
    for i in 0..n as u32 {
        let p = two.spec.point(i % 24, (i / 24) % 24, i / 576);
        let want = kernel((p - a).length(), r).max(kernel((p - b).length(), r));
        worst = worst.max((gpu[n + i as usize][0] as f64 - want).abs());
    }
    eprintln!("two kernels 1.2 apart: sum vs the larger kernel {worst:.2e}");
    assert!(worst < 2e-6, "{worst}");

    let h = 0.1;
    let lattice: Vec<DVec3> = (0..11 * 11 * 11)
        .map(|i| {
            DVec3::new((i % 11) as f64, ((i / 11) % 11) as f64, (i / 121) as f64) * h - DVec3::splat(0.5)
        })
        .collect();
    let r = 2.5 * h;
    let full = 64.0 * std::f64::consts::PI / 315.0 * (r / h).powi(3);
    let boxed = object(PointSet::new(lattice, None), r, full, 32);
    let (gpu, _) = both(&boxed);
    let n = 32 * 32 * 32;
    let (mut core, mut outside, mut inner, mut zero) = (0.0f64, 0.0f64, 0, 0);
    for i in 0..n as u32 {
        let p = boxed.spec.point(i % 32, (i / 32) % 32, i / 1024);
        let density = gpu[n + i as usize][0] as f64;
        let beyond = (p.abs() - DVec3::splat(0.5)).max_element();
        if beyond < -r {
            core = core.max((density - 1.0).abs());
            inner += 1;
        } else if beyond > r {
            outside = outside.max(density.abs());
            zero += 1;
        }
    }
    eprintln!(
        "lattice box (R = 2.5 h): density deep inside vs 1: {core:.2e} ({inner} samples); R beyond the faces: \
         {outside:.2e} ({zero} samples)"
    );
    assert!(core < 0.01 && outside == 0.0 && inner > 8 && zero > 1000, "{core} {outside} {inner} {zero}");
}

fn folder(tag: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voltex-points-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    dir
}

/// An ASCII PLY of `points`.
fn ply(points: &[DVec3]) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        points.len()
    );
    for p in points {
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    s.into_bytes()
}

fn scene_at(dir: &Path, object: &str, method: &str) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 32, height: 32),\n    camera: (eye: (0.0, -4.0, 1.5), \
         target: (0.0, 0.0, 0.0), fov_y: 35.0),\n    lights: [Directional(direction: (-0.5, 0.6, -0.7))],\n    \
         hypertextures: {{ \"h\": (object: {object}, noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.3, 1.0), \
         (1.0, 1.0, 0.0)]), amplitude: 0.15, frequency: 3.0, shift: 0.5)], color: Ramp([(0.0, (1.0, 0.9, 0.8, 0.0)), \
         (0.3, (0.9, 0.8, 0.7, 0.5)), (1.0, (0.5, 0.6, 0.9, 1.0))]), opacity_length: 0.2) }},\n    nodes: [(name: \"n\", \
         transform: (rotate: (10.0, 0.0, 20.0)), hypertexture: \"h\", method: {method})],\n)\n"
    );
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn plan_of(bp: &Blueprint) -> &RayMarchPlan {
    bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).unwrap()
}

/// The ray marcher's side: density and field at random points of a point-set hypertexture, the
/// kernels (`probe_hypertexture.wgsl` on the baked grid) against the twin's sampling of the same
/// grid; whole images, kernel against twin; and the image over splat segments (depth peeling,
/// splatting) against the image over the whole bounds: the splats skip only empty space.
#[test]
fn points_hypertexture_matches_twin() {
    let dir = folder("march", &[("blob.ply", &ply(&blob(400, 7)))]);
    let object = "Points(path: \"blob.ply\", radius: 0.25, saturation: 3.0, resolution: 32)";
    let scene = scene_at(&dir, object, "RayMarch(step: 0.02)");
    let bp = Blueprint::new(&scene, &sized(8, 8)).unwrap();
    let text = bp.describe(true);
    assert!(
        text.contains("32x32x32  bake_point_grid.wgsl  point grid of 400 kernels of radius 0.25"),
        "{text}"
    );
    probes_match_twin(plan_of(&bp), 5, "points");

    let (gpu, cpu) = layer_and_twin(&scene, &sized(32, 32));
    let (max, mean) = compare(&gpu, &cpu);
    let covered = cpu.iter().filter(|c| c[3] > 0.05).count();
    eprintln!("image kernel vs twin: max {max:.2e}, mean {mean:.2e}, {covered} covered pixels");
    assert!(covered > 100 && mean < 2e-3 && max < 0.05, "max {max}, mean {mean}");

    // Depth peeling marches the same samples; splatting blends slabs (a smoother
    // reconstruction, close but not equal: see hypertexture_splatting.rs), with no holes.
    for (segments, bound) in
        [("DepthPeeling(passes: 4, splat_grid: 24)", 1e-6), ("Splatting(splat_grid: 24)", 0.1)]
    {
        let segmented = scene_at(&dir, object, &format!("RayMarch(step: 0.02, segments: {segments})"));
        let (seg, _) = layer_and_twin(&segmented, &sized(32, 32));
        let (max, mean) = compare(&seg, &gpu);
        let holes = seg.iter().zip(&gpu).filter(|(s, b)| b[3] > 0.05 && s[3] < 0.5 * b[3]).count();
        eprintln!("{segments} vs Bounds: max {max:.2e}, mean {mean:.2e}, {holes} holes");
        assert!(max <= bound && mean <= bound / 10.0 && holes == 0, "max {max}, mean {mean}, {holes} holes");
    }
}

fn compare(a: &[[f64; 4]], b: &[[f64; 4]]) -> (f64, f64) {
    a.iter().zip(b).fold((0.0f64, 0.0), |(m, s), (g, c)| {
        let d = (0..4).map(|k| (g[k] - c[k]).abs()).fold(0.0, f64::max);
        (m.max(d), s + d / a.len() as f64)
    })
}

/// Bad point files and budgets fail when the scene loads, at the file's position or the
/// scene's.
#[test]
fn bad_point_sets_are_reported_at_their_position() {
    let dense: Vec<DVec3> = (0..4000).map(|i| DVec3::splat(i as f64 * 1e-6)).collect();
    let dir = folder(
        "bad",
        &[
            ("nan.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 nan 0\n"),
            ("empty.obj", b"# nothing\n"),
            ("dense.ply", &ply(&dense)),
        ],
    );
    let load = |object: &str| {
        let text = format!(
            "Scene(output: (width: 8, height: 8), camera: (eye: (0, -3, 0), target: (0, 0, 0)), hypertextures: {{ \"h\": \
             (object: {object}, noises: [(shape: Table([0.0, 1.0]), amplitude: 0.1, frequency: 2.0)], color: \
             Step(threshold: 0.3, color: (1, 1, 1))) }}, nodes: [(name: \"n\", hypertexture: \"h\", method: RayMarch(step: 0.05))])"
        );
        let path = dir.join("scene.ron");
        std::fs::write(&path, text).unwrap();
        scene::load(&path).unwrap_err().to_string()
    };
    let e = load("Points(path: \"nan.ply\", radius: 0.1)");
    assert!(e.ends_with("nan.ply:8:3: vertex 0: expected a finite y, found NaN"), "{e}");
    let e = load("Points(path: \"empty.obj\", radius: 0.1)");
    assert!(e.ends_with("empty.obj: expected at least one point, found none"), "{e}");
    let e = load("Points(path: \"missing.ply\", radius: 0.1)");
    assert!(e.contains("scene.ron:1:") && e.contains("missing.ply") && e.contains("does not exist"), "{e}");
    let e = load("Points(path: \"dense.ply\", radius: 0.5)");
    assert!(e.contains("scene.ron:1:") && e.contains("overlap about") && e.contains("at most 4096"), "{e}");
    let e = load("Points(path: \"dense.ply\", radius: -1)");
    assert!(e.contains("scene.ron:1:"), "{e}");
}
