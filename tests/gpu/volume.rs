//! Volume objects (OpenVDB grids): the transmittance of an absorbing box against its analytic
//! value, the kernel against its f64 twin, and the sparse table's memory.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use glam::{DMat4, DVec3, IVec3};
use voltex::methods::volume::march_volume::{march_volume, span, TwinView};
use voltex::methods::volume::VolumePlan;
use voltex::render::{Blueprint, Renderer};
use voltex::scene;

fn scene_path(name: &str) -> std::path::PathBuf {
    voltex::project_root().join("scenes/volumes").join(name)
}

/// The absorbing box scene with `grid`, drawn by `method`.
fn box_scene(grid: &str, method: &str) -> scene::Scene {
    let path = scene_path("absorbing_box.ron");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replace("grid: \"density\"", &format!("grid: \"{grid}\""))
        .replace("method: RayMarch()", &format!("method: {method}"));
    scene::parse(&text, &path).unwrap()
}

/// The exact optical depth (before `density_scale`) along the index-space ray o + dir t (t in
/// world units) over [t0, t1], of the trilinear interpolant of the voxel values `at` (voxel i at
/// index point i, OpenVDB's convention): cut wherever a coordinate crosses an integer, each
/// piece lies in one cell, where the density is a cubic in t, so Simpson's rule is exact.
pub(crate) fn optical_depth(
    o: DVec3,
    dir: DVec3,
    t0: f64,
    t1: f64,
    at: &(dyn Fn(IVec3) -> f64 + Sync),
) -> f64 {
    let mut cuts = vec![t0, t1];
    for a in 0..3 {
        if dir[a].abs() > 1e-300 {
            let (u0, u1) = (o[a] + dir[a] * t0, o[a] + dir[a] * t1);
            for k in u0.min(u1).ceil() as i64..=u0.max(u1).floor() as i64 {
                let t = (k as f64 - o[a]) / dir[a];
                if t > t0 && t < t1 {
                    cuts.push(t);
                }
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    let mut tau = 0.0;
    for w in cuts.windows(2).filter(|w| w[1] > w[0]) {
        let (a, b, m) = (w[0], w[1], 0.5 * (w[0] + w[1]));
        let c = (o + dir * m).floor();
        let corner = c.as_ivec3();
        let k: [f64; 8] = std::array::from_fn(|n| {
            let n = n as i32;
            at(corner + IVec3::new(n & 1, n >> 1 & 1, n >> 2))
        });
        if k.iter().all(|v| *v == 0.0) {
            continue;
        }
        let rho = |t: f64| {
            let f = o + dir * t - c;
            let x0 =
                (k[0] * (1.0 - f.x) + k[1] * f.x) * (1.0 - f.y) + (k[2] * (1.0 - f.x) + k[3] * f.x) * f.y;
            let x1 =
                (k[4] * (1.0 - f.x) + k[5] * f.x) * (1.0 - f.y) + (k[6] * (1.0 - f.x) + k[7] * f.x) * f.y;
            x0 * (1.0 - f.z) + x1 * f.z
        };
        tau += (b - a) / 6.0 * (rho(a) + 4.0 * rho(m) + rho(b));
    }
    tau
}

/// Per pixel (rows top to bottom): the exact transmittance of the rays of `scene`'s one volume
/// object, whose voxels are `at` over `lo..=hi` (0 elsewhere) under `index_to_world`; as the
/// march casts them (pixel centres, from the eye), in f64, on every core.
pub(crate) fn exact_transmittance(
    scene: &scene::Scene,
    size: u32,
    index_to_world: DMat4,
    (lo, hi): (IVec3, IVec3),
    at: &(dyn Fn(IVec3) -> f64 + Sync),
) -> Vec<f64> {
    let bp = Blueprint::new(scene, &common::sized(size, size)).unwrap();
    let scale = bp.objects[0].method::<VolumePlan>().unwrap().params.medium[3] as f64;
    let node = bp.objects[0].object.volume.as_ref().unwrap();
    let view = twin_view(&bp);
    let to_index = (node.to_world * index_to_world).inverse() * DMat4::from_translation(view.camera.eye);
    let o = to_index.transform_point3(DVec3::ZERO);
    let (box_lo, box_hi) = ((lo - 1).as_dvec3(), (hi + 1).as_dvec3());
    let row = |py: u32| -> Vec<f64> {
        (0..size)
            .map(|px| {
                let sx = 2.0 * (px as f64 + 0.5) / size as f64 - 1.0;
                let sy = 1.0 - 2.0 * (py as f64 + 0.5) / size as f64;
                let d = (view.forward + view.camera.right * sx + view.camera.up * sy).normalize();
                let dir = to_index.transform_vector3(d);
                let (t0, t1) = span(o, dir, box_lo, box_hi);
                let tau = if t1 > t0.max(0.0) { optical_depth(o, dir, t0.max(0.0), t1, at) } else { 0.0 };
                (-scale * tau).exp()
            })
            .collect()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    std::thread::scope(|s| {
        let parts: Vec<_> = (0..threads)
            .map(|k| {
                s.spawn(move || {
                    (k..size).step_by(threads as usize).map(|py| (py, row(py))).collect::<Vec<_>>()
                })
            })
            .collect();
        let mut rows: Vec<(u32, Vec<f64>)> = parts.into_iter().flat_map(|p| p.join().unwrap()).collect();
        rows.sort_by_key(|r| r.0);
        rows.into_iter().flat_map(|r| r.1).collect()
    })
}

/// The analytic transmittance of the box scene, whose 16^3 voxels are separable: v0(i) v1(j) v2(k).
fn analytic(scene: &scene::Scene, size: u32, v: &[&(dyn Fn(usize) -> f64 + Sync); 3]) -> Vec<f64> {
    let grid = scene.volume("box").unwrap();
    let at = |i: IVec3| {
        if i.cmplt(IVec3::ZERO).any() || i.cmpgt(IVec3::splat(15)).any() {
            return 0.0;
        }
        (0..3).map(|a| v[a](i[a] as usize)).product::<f64>()
    };
    exact_transmittance(scene, size, grid.index_to_world, (IVec3::ZERO, IVec3::splat(15)), &at)
}

pub(crate) fn twin_view(bp: &Blueprint) -> TwinView {
    let f = &bp.frame;
    let v3 = |a: [f32; 4]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let p = bp.objects[0].method::<VolumePlan>().unwrap();
    TwinView {
        camera: voltex::methods::view::RayCamera {
            eye: bp.eye,
            right: v3(p.params.right),
            up: v3(p.params.up),
            near: p.params.right[3] as f64,
            far: p.params.up[3] as f64,
        },
        forward: v3(f.forward),
        light: v3(f.light_dir),
        ambient: f.light_dir[3] as f64,
        size: bp.size,
    }
}

/// The rendered image's red channel (white background times the transmittance).
pub(crate) fn render(scene: &scene::Scene, size: u32) -> Vec<f64> {
    let bp = Blueprint::new(scene, &common::sized(size, size)).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut r = Renderer::new(&ctx, bp).unwrap();
    let frame = r.render(&ctx).unwrap();
    frame.image.pixels.iter().map(|p| p[0] as f64).collect()
}

pub(crate) fn rmse(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

pub(crate) fn max_error(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

const ONE: &(dyn Fn(usize) -> f64 + Sync) = &|_| 1.0;
/// The `ramp` grid of box.vdb: 0.25 + 1.5 (i + 1/2) / 16 along i.
const RAMP: &(dyn Fn(usize) -> f64 + Sync) = &|i| 0.25 + 1.5 * (i as f64 + 0.5) / 16.0;

#[test]
fn absorbing_box_transmittance_is_analytic() {
    for (grid, v) in [("density", [ONE, ONE, ONE]), ("ramp", [RAMP, ONE, ONE])] {
        let truth = analytic(&box_scene(grid, "Reference()"), 64, &v);
        assert!(truth.iter().any(|t| *t < 0.3), "the box absorbs");
        let reference = render(&box_scene(grid, "Reference()"), 64);
        let (e, m) = (rmse(&reference, &truth), max_error(&reference, &truth));
        println!("{grid}: Reference RMSE {e:.2e}, max {m:.2e}");
        assert!(e < 2e-4 && m < 2e-3, "{grid}: the Reference is exact up to f32: RMSE {e:.2e}, max {m:.2e}");
        let march = render(&box_scene(grid, "RayMarch()"), 64);
        let (e, m) = (rmse(&march, &truth), max_error(&march, &truth));
        println!("{grid}: RayMarch (one voxel a step) RMSE {e:.2e}, max {m:.2e}");
        assert!(e < 5e-3 && m < 5e-2, "{grid}: RayMarch within its step's error: RMSE {e:.2e}, max {m:.2e}");
    }
}

/// The kernel against its f64 twin: both methods on the absorbing box, shadows and colour on
/// the smoke, the exact Reference lit on the level set, a rotated half grid.
#[test]
fn kernel_matches_twin() {
    let cases = [
        ("absorbing_box.ron", "method: RayMarch()", "method: Reference()"),
        ("absorbing_box.ron", "", ""),
        ("smoke.ron", "", ""),
        ("level_set.ron", "method: RayMarch(shading: Phong)", "method: Reference(lighting: PerPixel)"),
        ("half_rotated.ron", "", ""),
    ];
    for (file, from, to) in cases {
        let mut text = std::fs::read_to_string(scene_path(file)).unwrap();
        if !from.is_empty() {
            text = text.replace(from, to);
        }
        let scene = scene::parse(&text, &scene_path(file)).unwrap();
        let bp = Blueprint::new(&scene, &common::sized(24, 24)).unwrap();
        let plan = bp.objects[0].method::<VolumePlan>().unwrap().clone();
        let node = bp.objects[0].object.volume.clone().unwrap();
        let view = twin_view(&bp);
        let cpu = march_volume(&plan, &node.to_world, &view);
        let ctx = gpu!(ADAPTER);
        let mut r = Renderer::new(&ctx, bp).unwrap();
        r.render(&ctx).unwrap();
        let i = r.blueprint.find_instance("Volume").unwrap();
        let bytes = r.read_instance_buffer(&ctx, i, "volume_state").unwrap();
        drop(ctx);
        let gpu = bytemuck::pod_collect_to_vec::<u8, voltex::types::MarchState>(&bytes);
        let diffs: Vec<f64> = gpu
            .iter()
            .zip(&cpu)
            .map(|(g, c)| (0..4).map(|k| (g.color[k] as f64 - c[k]).abs()).fold(0.0, f64::max))
            .collect();
        let worst = diffs.iter().copied().fold(0.0, f64::max);
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        let covered = cpu.iter().filter(|c| c[3] > 0.05).count();
        println!("{file} {}: mean difference {mean:.2e}, largest {worst:.2e}", plan.describe());
        assert!(covered > 20, "{file}: the volume covers pixels");
        assert!(
            mean < 1e-5 && worst < 1e-3,
            "{file}: kernel and twin differ by {mean:.2e} (largest {worst:.2e})"
        );
    }
}

/// The volume texel of `smoke_texel.ron` baked on the GPU against `bake_volume` (its twin), in
/// both lightings: within the 8-bit rounding, and normals alike where there is matter.
#[test]
fn volume_texel_bake_matches_twin() {
    use voltex::bake::volume::{bake_volume, VolumeTexel};
    use voltex::bake::{BakeRequest, BakeSource, Baker};
    use voltex::gpu::readback::read_texture;
    let scene = scene::load(&scene_path("smoke_texel.ron")).unwrap();
    let v = &scene.volumes["smoke"];
    let grid = scene.volume("smoke").unwrap().clone();
    let texel = VolumeTexel::new(grid, None, v.albedo, v.density_scale, 0.05);
    let res = [20, 16, 12];
    let light = [-0.4f32, 0.5, 0.75];
    let ambient = 0.3;
    for per_pixel in [false, true] {
        let ctx = gpu!(ADAPTER);
        let req = BakeRequest {
            resolution: res,
            source: BakeSource::Volume(Box::new(texel.clone())),
            per_pixel,
            light,
            ambient,
            derived: Default::default(),
            layers: false,
            shadow: None,
        };
        let baked = Baker::new(&voltex::gpu::sources::Sources::project().unwrap()).bake(&ctx, &req).unwrap();
        let volume = read_texture(&ctx, &baked.volume, 4).unwrap();
        let normals = if per_pixel { read_texture(&ctx, &baked.normals, 4).unwrap() } else { Vec::new() };
        drop(ctx);
        let (mut worst, mut worst_normal, mut matter) = (0.0f64, 0.0f64, 0);
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let i = 4 * (x + res[0] * (y + res[1] * z)) as usize;
                    let l = [light[0], light[1], light[2], ambient];
                    let (rgba, normal) = bake_volume(&texel, res, [x, y, z], l, per_pixel);
                    let d =
                        (0..4).map(|c| (volume[i + c] as f64 - rgba[c] * 255.0).abs()).fold(0.0, f64::max);
                    worst = worst.max(d);
                    matter += (rgba[3] > 0.05) as usize;
                    if per_pixel && rgba[3] > 0.05 {
                        let gpu = (0..3).map(|c| normals[i + c] as i8 as f64 / 127.0);
                        worst_normal =
                            gpu.zip(normal).map(|(g, n)| (g - n).abs()).fold(worst_normal, f64::max);
                    }
                }
            }
        }
        println!("per_pixel {per_pixel}: {matter} voxels with matter, worst {worst:.2}/255, normal {worst_normal:.3}");
        assert!(matter > 100, "the blob is in the texel");
        assert!(worst <= 1.5, "per_pixel {per_pixel}: {worst}/255");
        assert!(worst_normal < 0.05, "{worst_normal}");
    }
}

/// By hand (`cargo test --release --test gpu volume::measure -- --ignored --nocapture`): the
/// RMSE against the analytic transmittance at 256x256 (the bound for the Reference is
/// 1e-3) for both methods and several RayMarch steps, with the march's GPU time.
#[test]
#[ignore]
fn measure_transmittance_rmse_256() {
    let size = 256;
    for (grid, v) in [("density", [ONE, ONE, ONE]), ("ramp", [RAMP, ONE, ONE])] {
        let truth = analytic(&box_scene(grid, "Reference()"), size, &v);
        for method in ["Reference()", "RayMarch(quality: HQ)", "RayMarch()", "RayMarch(step: 0.125)"] {
            let scene = box_scene(grid, method);
            let bp = Blueprint::new(&scene, &common::sized(size, size)).unwrap();
            let ctx = gpu!(ADAPTER);
            let mut r = Renderer::new(&ctx, bp).unwrap();
            r.render(&ctx).unwrap();
            let times = r.render_timed(&ctx).unwrap();
            let frame = r.render(&ctx).unwrap();
            drop(ctx);
            let image: Vec<f64> = frame.image.pixels.iter().map(|p| p[0] as f64).collect();
            let ms: f64 = times.iter().filter(|(n, _)| n.starts_with("march_volume")).map(|(_, t)| t).sum();
            println!(
                "{grid:8} {method:24} RMSE {:.2e}  max {:.2e}  march_volume {ms:.1} ms",
                rmse(&image, &truth),
                max_error(&image, &truth)
            );
        }
    }
}

/// The sparse case through the plan: two blobs 1000 voxels apart cost the frame well under a
/// MiB of table and bricks (a dense grid over their bounds: 1016^3 floats, 4 GB), and `voltex
/// plan`'s memory says so before anything is allocated.
#[test]
fn far_apart_blobs_plan_sparse_memory() {
    let scene = scene::load(&scene_path("far_apart.ron")).unwrap();
    let bp = Blueprint::new(&scene, &common::sized(64, 64)).unwrap();
    let o = &bp.objects[0];
    let plan = o.method::<VolumePlan>().unwrap();
    let bytes: u64 = voltex::methods::MethodPlan::memory(plan, o, (64, 64)).iter().map(|m| m.1).sum();
    let grid = &o.object.volume.as_ref().unwrap().grid;
    let span = (grid.hi - grid.lo + 1).as_dvec3();
    let dense = span.x * span.y * span.z * 4.0;
    println!(
        "far_apart: {} bricks, {} table words, {bytes} bytes planned; dense {dense:.3e} bytes",
        grid.bricks(),
        grid.table.len()
    );
    assert!(span.min_element() > 1000.0);
    assert!(bytes < 1 << 20 && (bytes as f64) < dense * 1e-3, "{bytes} bytes");
}
