//! Hypertexture mesh objects (Gilet & Dischler 2009, section 5.3): `bake_mesh_grid.wgsl` against
//! its brute-force f64 twin, a finely tessellated sphere against the soft `Sphere` object, the
//! ray marcher's mesh sampling against the twin's, whole images, the bake cache, and bad meshes
//! reported at their position.
use crate::common::adapter::{gpu, Expectations};
use crate::common::sized;

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::{Path, PathBuf};

use glam::DVec3;
use voltex::cpu::bake_mesh_grid::{bake_mesh_grid, on_triangle};
use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::gpu::cache::GpuCache;
use voltex::hypertexture::mesh;
use voltex::mesh::shape::MeshShape;
use voltex::methods::ray_march::march::{ray_march, MarchView};
use voltex::methods::ray_march::{probe, RayMarchPlan};
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene;

/// A closed UV sphere: `around` segments, `rings` bands from pole to pole, shared vertices.
fn sphere_obj(radius: f64, around: usize, rings: usize) -> String {
    let mut s = format!("# UV sphere\nv 0 0 {radius}\n");
    for r in 1..rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for a in 0..around {
            let phi = std::f64::consts::TAU * a as f64 / around as f64;
            let p = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * radius;
            s += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
    }
    s += &format!("v 0 0 {}\n", -radius);
    let ring = |r: usize, a: usize| 2 + (r - 1) * around + a % around;
    let south = 2 + (rings - 1) * around;
    for a in 0..around {
        s += &format!("f 1 {} {}\n", ring(1, a), ring(1, a + 1));
        s += &format!("f {south} {} {}\n", ring(rings - 1, a + 1), ring(rings - 1, a));
        for r in 1..rings - 1 {
            s += &format!("f {} {} {} {}\n", ring(r, a), ring(r + 1, a), ring(r + 1, a + 1), ring(r, a + 1));
        }
    }
    s
}

/// A closed box from `lo` to `hi` whose vertices start at OBJ index `base + 1`.
fn box_obj(lo: [f64; 3], hi: [f64; 3], base: usize) -> String {
    let mut s = String::new();
    for k in 0..8 {
        let c = |a: usize| if k >> a & 1 == 1 { hi[a] } else { lo[a] };
        s += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    for f in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
        s += &format!("f {} {} {} {}\n", base + f[0] + 1, base + f[1] + 1, base + f[2] + 1, base + f[3] + 1);
    }
    s
}

/// A temporary folder holding `files` (name, text).
fn folder(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voltex-mesh-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

fn scene_text(object: &str, noises: &str, method: &str) -> String {
    format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 32, height: 32),\n    camera: (eye: (0.0, -4.5, 1.2), \
         target: (0.0, 0.0, 0.0), fov_y: 35.0),\n    lights: [Directional(direction: (-0.5, 0.6, -0.7))],\n    \
         hypertextures: {{ \"h\": (object: {object}, noises: [{noises}], color: Ramp([(0.0, (1.0, 0.9, 0.8, 0.0)), \
         (0.3, (0.9, 0.8, 0.7, 0.5)), (1.0, (0.5, 0.6, 0.9, 1.0))]), opacity_length: 0.2) }},\n    nodes: [(name: \"n\", \
         transform: (rotate: (10.0, 0.0, 20.0)), hypertexture: \"h\", method: {method})],\n)\n"
    )
}

const NOISE: &str =
    "(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.3, 1.0), (1.0, 1.0, 0.0)]), amplitude: 0.3, frequency: 2.5, shift: 0.5)";

fn mesh_scene(dir: &Path, object: &str, noises: &str, method: &str) -> scene::Scene {
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene_text(object, noises, method)).unwrap();
    scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn plan_of(bp: &Blueprint) -> &RayMarchPlan {
    bp.objects.iter().find_map(|o| o.method::<RayMarchPlan>()).unwrap()
}

/// The grid of a 24 x 12 sphere, of a box made of 12 triangles and of the union of two
/// overlapping boxes: the kernel (a BVH per part, f32) against
/// the brute-force f64 twin, sample by sample (closest points: on the surface at the twin's
/// distance).
#[test]
fn bake_kernel_matches_twin() {
    let cube = "v -1 -0.5 -0.7\nv 1 -0.5 -0.7\nv 1 0.5 -0.7\nv -1 0.5 -0.7\nv -1 -0.5 0.7\nv 1 -0.5 0.7\nv 1 0.5 0.7\n\
                v -1 0.5 0.7\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    // Two overlapping boxes: their union (a part buried in another is not its boundary).
    let union =
        box_obj([-1.0, -0.5, -0.5], [0.3, 0.5, 0.5], 0) + &box_obj([-0.2, -0.3, -0.3], [1.0, 0.3, 0.3], 8);
    let files = [("sphere.obj", &sphere_obj(1.0, 24, 12)[..]), ("box.obj", cube), ("union.obj", &union)];
    let dir = folder("twin", &files);
    let ctx = gpu!(ADAPTER);
    for (name, n) in [("sphere.obj", 24), ("box.obj", 20), ("union.obj", 24)] {
        let m = voltex::mesh::obj::load(&dir.join(name)).unwrap();
        let shape = MeshShape::new(&m, &dir.join(name)).unwrap();
        let spec = shape.grid(n, 0.2);
        let start = std::time::Instant::now();
        let g = mesh::bake(&ctx, &shape, &spec).unwrap();
        let (cells, depth) = mesh::read(&ctx, &g).unwrap();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let (twin, twin_depth) = bake_mesh_grid(&shape, &spec);
        let (mut vec_err, mut dist_err, mut flips): (f64, f64, usize) = (0.0, 0.0, 0);
        for (i, (g, c)) in cells.iter().zip(&twin).enumerate() {
            // Where several surface points are closest (on symmetry axes) the kernel may pick
            // another: its point must lie on the surface at the twin's distance.
            let i = i as u32;
            let p = spec.point(i % n, (i / n) % n, i / (n * n));
            let q = p + DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64);
            let off = (0..shape.triangles.len())
                .map(|t| {
                    let [a, b, c] = shape.triangle(t);
                    (on_triangle(q, a, b, c) - q).length()
                })
                .fold(f64::INFINITY, f64::min);
            vec_err = vec_err.max(off).max(((q - p).length() - c[3].abs()).abs());
            dist_err = dist_err.max((g[3].abs() as f64 - c[3].abs()).abs());
            // Inside/outside disagreements only where the surface is within rounding.
            if (g[3] > 0.0) != (c[3] > 0.0) && c[3].abs() > 1e-5 {
                flips += 1;
            }
        }
        eprintln!(
            "{name} ({} triangles, {n}^3): bake + readback {ms:.1} ms; kernel vs twin: vector {vec_err:.2e}, \
             distance {dist_err:.2e}, depth {:.2e}, inside/outside flips {flips}",
            shape.triangles.len(),
            (depth as f64 - twin_depth).abs()
        );
        assert!(vec_err < 1e-5 && dist_err < 1e-5, "vector {vec_err}, distance {dist_err}");
        assert_eq!(flips, 0);
        assert!((depth as f64 - twin_depth).abs() < 1e-5);
        if name == "union.obj" {
            assert_eq!(shape.parts.len(), 2);
            // On the second box's end face buried in the first (x = -0.2): 0.5 to the first
            // box's faces, not 0 to the buried face; inside the second box only: 0.3.
            let (_, d) = voltex::cpu::bake_mesh_grid::sample(&shape, DVec3::new(-0.2, 0.0, 0.0), true);
            assert!((d - 0.5).abs() < 1e-12, "{d}");
            let (_, d) = voltex::cpu::bake_mesh_grid::sample(&shape, DVec3::new(0.6, 0.0, 0.0), true);
            assert!((d - 0.3).abs() < 1e-12, "{d}");
        }
    }
}

/// A sphere of radius 1 tessellated into 16384 triangles, baked at 65^3 (a sample at the centre):
/// the grid's density and closest-surface vectors against the soft Sphere object's `1 - |x|` and
/// `x (1 / |x| - 1)`. Tessellation moves the surface inwards by at most 1 - cos(pi / 128) = 3e-4
/// (flat triangles), so the densities agree to 1e-3; a closest point on a flat facet is off the
/// radial one by up to |1 - |x|| sin(facet half-angle) sideways, so the vectors agree to that
/// (sqrt(2) pi / 128 = 0.035 of the distance to the surface) plus 1e-3.
#[test]
fn sphere_mesh_matches_the_soft_sphere() {
    let dir = folder("sphere", &[("sphere.obj", &sphere_obj(1.0, 128, 64))]);
    let m = voltex::mesh::obj::load(&dir.join("sphere.obj")).unwrap();
    let shape = MeshShape::new(&m, &dir.join("sphere.obj")).unwrap();
    let spec = shape.grid(65, 0.0);
    let ctx = gpu!(ADAPTER);
    let start = std::time::Instant::now();
    let g = mesh::bake(&ctx, &shape, &spec).unwrap();
    let (cells, depth) = mesh::read(&ctx, &g).unwrap();
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let (mut density_err, mut vec_err): (f64, f64) = (0.0, 0.0);
    let mut inside = 0;
    for k in 0..65 {
        for j in 0..65 {
            for i in 0..65 {
                let p = spec.point(i, j, k);
                let c = cells[(i + 65 * (j + 65 * k)) as usize];
                let density = (c[3] as f64 / depth as f64).clamp(0.0, 1.0);
                let soft = (1.0 - p.length()).clamp(0.0, 1.0);
                density_err = density_err.max((density - soft).abs());
                inside += (density > 0.0) as usize;
                if p.length() > 0.05 {
                    let v = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
                    let bound = (1.0 - p.length()).abs() * 0.035 + 1e-3;
                    vec_err = vec_err.max((v - p * (1.0 / p.length() - 1.0)).length() / bound);
                }
            }
        }
    }
    eprintln!(
        "sphere mesh ({} triangles) at 65^3: bake + readback {ms:.0} ms; density vs soft Sphere: max {density_err:.2e}; \
         closest-surface vector: at most {vec_err:.2} of its bound; largest inside distance {depth}; {inside} samples inside",
        shape.triangles.len()
    );
    assert!(density_err < 1e-3 && vec_err <= 1.0, "density {density_err}, vector {vec_err}");
    assert!((depth - 1.0).abs() < 1e-3);
}

/// The ray marcher's kernels (`probe_hypertexture.wgsl` on the baked grid) against the twin's
/// sampling of the same grid at 2048 random points of the object's bounds (from `seed`):
/// object density, vector field and density within f32 rounding, and some points with density.
pub(crate) fn probes_match_twin(plan: &RayMarchPlan, seed: u32, what: &str) {
    let ctx = gpu!(ADAPTER);
    let grid = plan.bake_mesh_grid(&ctx).unwrap().unwrap();
    let (cells, depth) = mesh::read(&ctx, &grid).unwrap();
    let tables = bake_transfer(&plan.packed.functions, &plan.packed.points);
    let model = Model {
        params: &plan.params,
        noises: &plan.packed.noises,
        tables: &tables,
        grid: Some((&cells, depth)),
    };
    let (lo, hi) = plan.packed.bounds;
    let mut seed = seed;
    let points: Vec<[f32; 4]> = (0..2048)
        .map(|_| {
            let mut next = || {
                seed = voltex::cpu::bake::pcg_hash(seed);
                seed as f64 / 4294967296.0
            };
            let p = lo + (hi - lo) * DVec3::new(next(), next(), next());
            [p.x as f32, p.y as f32, p.z as f32, 0.0]
        })
        .collect();
    let gpu = probe(&ctx, plan, &points).unwrap();
    let (mut worst, mut positive) = ([0.0f64; 3], 0);
    for (i, p) in points.iter().enumerate() {
        let x = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let v = model.vector_field(x);
        let density = model.hyper_density(x);
        let g = &gpu.values[4 * i..4 * i + 4];
        worst[0] = worst[0].max((g[0][1] as f64 - model.object_density(x)).abs());
        worst[1] = worst[1].max((0..3).map(|k| (g[1][k] as f64 - v[k]).abs()).fold(0.0, f64::max));
        worst[2] = worst[2].max((g[2][0] as f64 - density).abs());
        positive += (density > 0.0) as usize;
    }
    eprintln!(
        "{what} hypertexture probes vs twin: object density {:.2e}, field {:.2e}, density {:.2e} ({positive} of \
         2048 points with density)",
        worst[0], worst[1], worst[2]
    );
    assert!(worst[0] < 1e-5 && worst[1] < 1e-5 && worst[2] < 1e-4, "{worst:?}");
    assert!(positive > 100);
}

/// The ray marcher's side: density, field and colour at random points of a mesh hypertexture,
/// the kernels (`probe_hypertexture.wgsl` on the baked grid) against the twin's trilinear sampling
/// of the same grid; and whole images, kernel against twin, unshaded and with Phong.
#[test]
fn mesh_hypertexture_matches_twin() {
    let dir = folder("march", &[("sphere.obj", &sphere_obj(1.0, 32, 16))]);
    let object = "Mesh(path: \"sphere.obj\", resolution: 32)";
    let scene = mesh_scene(&dir, object, NOISE, "RayMarch(step: 0.02)");
    let bp = Blueprint::new(&scene, &sized(8, 8)).unwrap();
    // `voltex plan` lists the bake.
    let text = bp.describe(true);
    assert!(
        text.contains("32x32x32  bake_mesh_grid.wgsl  mesh grid of 960 triangles in 1 part(s)"),
        "{text}"
    );
    probes_match_twin(plan_of(&bp), 11, "mesh");

    for method in ["RayMarch(step: 0.02)", "RayMarch(step: 0.02, shading: Phong)"] {
        let scene = mesh_scene(&dir, object, NOISE, method);
        let (gpu, cpu) = layer_and_twin(&scene, &sized(32, 32));
        let (max, mean) = gpu.iter().zip(&cpu).fold((0.0f64, 0.0), |(m, s), (g, c)| {
            let d = (0..4).map(|k| (g[k] - c[k]).abs()).fold(0.0, f64::max);
            (m.max(d), s + d / gpu.len() as f64)
        });
        let covered = cpu.iter().filter(|c| c[3] > 0.05).count();
        eprintln!("{method}: image kernel vs twin: max {max:.2e}, mean {mean:.2e}, {covered} covered pixels");
        assert!(covered > 100 && mean < 2e-3 && max < 0.05, "max {max}, mean {mean}");
    }
}

/// The kernel's premultiplied layer of the RayMarch object and the twin's (on the kernel's grid).
pub(crate) fn layer_and_twin(scene: &scene::Scene, opts: &RenderOptions) -> (Vec<[f64; 4]>, Vec<[f64; 4]>) {
    let bp = Blueprint::new(scene, opts).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    r.render(&ctx).unwrap();
    let instance = r.blueprint.find_instance("RayMarch").unwrap();
    let bytes = r.read_instance_buffer(&ctx, instance, "ray_march_state").unwrap();
    let plan = plan_of(&r.blueprint);
    let (cells, depth) = mesh::read(&ctx, &plan.bake_mesh_grid(&ctx).unwrap().unwrap()).unwrap();
    drop(ctx);
    let f = &r.blueprint.frame;
    let gpu = common::lit_march_state(f, &bytes);
    let tables = bake_transfer(&plan.packed.functions, &plan.packed.points);
    let view = MarchView::of_frame(f, r.blueprint.size);
    let model = Model {
        params: &plan.params,
        noises: &plan.packed.noises,
        tables: &tables,
        grid: Some((&cells, depth)),
    };
    (gpu, ray_march(&view, model, plan.shade))
}

/// An unchanged mesh is not baked again by a rebuild through the cache; a new resolution is.
#[test]
fn unchanged_mesh_is_not_rebaked() {
    let dir = folder("cache", &[("sphere.obj", &sphere_obj(1.0, 16, 8))]);
    let ctx = gpu!(ADAPTER);
    let mut cache = GpuCache::default();
    let mut build = |resolution: u32, amplitude: f64| {
        let noise = NOISE.replace("0.3, frequency", &format!("{amplitude}, frequency"));
        let object = format!("Mesh(path: \"sphere.obj\", resolution: {resolution})");
        let scene = mesh_scene(&dir, &object, &noise, "RayMarch(step: 0.05)");
        cache.begin();
        Renderer::with_cache(&ctx, Blueprint::new(&scene, &sized(8, 8)).unwrap(), &mut cache).unwrap();
        cache.retain_used();
        cache.stats.bakes
    };
    assert_eq!(build(16, 0.3), 1);
    assert_eq!(build(16, 0.3), 0, "unchanged mesh and grid: no bake");
    assert_eq!(build(20, 0.3), 1, "a new resolution rebakes");
    assert_eq!(build(20, 0.25), 1, "a new largest shift enlarges the grid: rebake");
}

/// Bad mesh objects fail at their position in the scene, naming the OBJ file (and the face).
#[test]
fn bad_meshes_are_reported_at_their_position() {
    let open = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";
    let flat = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n";
    let sphere = sphere_obj(1.0, 8, 4);
    let files = [
        ("open.obj", open),
        ("flat.obj", flat),
        ("broken.obj", "v 0 0 0\nf 1 2 3\n"),
        ("sphere.obj", &sphere),
    ];
    let dir = folder("bad", &files);
    let fails = |object: &str| {
        let path = dir.join("scene.ron");
        std::fs::write(&path, scene_text(object, NOISE, "RayMarch()")).unwrap();
        scene::load(&path).err().unwrap_or_else(|| panic!("{object} was accepted")).to_string()
    };
    let at = |e: &str| e.contains("scene.ron:6:");
    let e = fails("Mesh(path: \"missing.obj\")");
    assert!(at(&e) && e.contains("missing.obj does not exist"), "{e}");
    let e = fails("Mesh(path: \"open.obj\")");
    assert!(at(&e) && e.contains("open.obj:5:1: open mesh") && e.contains("expected a closed mesh"), "{e}");
    let e = fails("Mesh(path: \"flat.obj\")");
    assert!(at(&e) && e.contains("flat.obj:4:1: degenerate mesh") && e.contains("encloses no volume"), "{e}");
    let e = fails("Mesh(path: \"broken.obj\")");
    assert!(e.contains("broken.obj:2:5: vertex index 2 out of range"), "{e}");
    let e = fails("Mesh(path: \"open.obj\", resolution: 0)");
    assert!(
        at(&e) && e.contains("expected a mesh grid resolution (samples per axis) in 4..=128, found 0"),
        "{e}"
    );
    let e = fails("Mesh(path: \"open.obj\", resolution: 1000)");
    assert!(at(&e) && e.contains("found 1000"), "{e}");

    // The step check sees the mesh's bounds (diagonal 2 sqrt(3) + the shift: 1.5e5 samples).
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene_text("Mesh(path: \"sphere.obj\")", NOISE, "RayMarch(step: 0.00003)"))
        .unwrap();
    let e = scene::load(&path).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("scene.ron:7:") && e.contains("samples across the bounds"), "{e}");

    // Through the binary: exit status 1, the position, no output written.
    let path = dir.join("scene.ron");
    std::fs::write(&path, scene_text("Mesh(path: \"open.obj\")", NOISE, "RayMarch()")).unwrap();
    let out = common::voltex(&["render", common::s(&path), "-o", common::s(&dir.join("out.exr"))]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(at(&err) && err.contains("open.obj:5:1: open mesh"), "{err}");
    assert!(!dir.join("out.exr").exists() && !dir.join("out.png").exists());
}

/// The Figure 11 bunny (a stand-in written by `tools/gen_bunny.py`): one closed part in which
/// every edge joins exactly two triangles (a manifold, as marching tetrahedra make), small
/// enough to commit, sitting on z = 0 and about 1.8 tall.
#[test]
fn bunny_stand_in_is_one_closed_manifold_part() {
    let path = voltex::project_root().join("scenes/hypertextures/meshes/bunny.obj");
    let m = voltex::mesh::obj::load(&path).unwrap();
    let shape = MeshShape::new(&m, &path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(shape.parts.len(), 1);
    assert!((5_000..=10_000).contains(&shape.triangles.len()), "{} triangles", shape.triangles.len());
    let mut edges = std::collections::HashMap::new();
    for t in &shape.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0u32) += 1;
        }
    }
    assert!(edges.values().all(|&n| n == 2), "an edge not shared by exactly two triangles");
    assert!(shape.lo.z.abs() < 0.01 && (shape.hi.z - 1.8).abs() < 0.1, "{:?} {:?}", shape.lo, shape.hi);
}
