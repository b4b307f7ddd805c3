//! The reference renderer: the GPU kernel against its f64 CPU twin on every example scene, and
//! analytic checks (a constant slab's transmittance; brightness independent of the step).

use std::path::Path;
use std::sync::{Mutex, OnceLock};

use voltex::cpu::trace_reference;
use voltex::gpu::GpuContext;
use voltex::io::Image;
use voltex::methods::reference::twin_inputs;
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene;

fn ctx() -> &'static Mutex<GpuContext> {
    static CTX: OnceLock<Mutex<GpuContext>> = OnceLock::new();
    CTX.get_or_init(|| {
        Mutex::new(GpuContext::new().expect("a GPU adapter (software Vulkan: mesa-vulkan-drivers)"))
    })
}

fn reference_options(size: u32) -> RenderOptions {
    RenderOptions { size: Some((size, size)), method: Some(MethodKind::Reference), ..Default::default() }
}

/// The kernel's premultiplied layer and the twin's, for the same frame and the same volumes.
fn gpu_and_twin(scene: &Path, opts: &RenderOptions) -> (Image, Image) {
    let scene = scene::load(scene).unwrap();
    let bp = Blueprint::new(&scene, opts).unwrap();
    let ctx = ctx().lock().unwrap_or_else(|e| e.into_inner());
    let mut r = Renderer::new(&ctx, bp).unwrap();
    r.render(&ctx).unwrap();
    let gpu = r.read_texture(&ctx, "reference_rgba").unwrap();
    let (texels, normals) = r.reference_atlases(&ctx).unwrap().unwrap();
    let (view, objects) = twin_inputs(&r.blueprint, &texels, &normals);
    let cpu = trace_reference::trace(&view, &objects);
    let cpu = Image::from_pixels(view.width, view.height, cpu.iter().map(|p| p.map(|c| c as f32)).collect())
        .unwrap();
    (gpu, cpu)
}

fn example(name: &str) -> std::path::PathBuf {
    voltex::project_root().join("scenes/view_slices").join(name)
}

#[test]
fn debug_twin() {
    let (gpu, cpu) = gpu_and_twin(&example("torus_egg.ron"), &reference_options(48));
    voltex::io::png::write_tonemapped(Path::new("/tmp/ref/gpu.png"), &gpu).unwrap();
    voltex::io::png::write_tonemapped(Path::new("/tmp/ref/cpu.png"), &cpu).unwrap();
    let d = voltex::metrics::max_abs_diff(&gpu, &cpu).unwrap();
    println!("max abs diff {d}");
}

#[test]
fn debug_counts() {
    let (gpu, _cpu) = gpu_and_twin(&example("torus_egg.ron"), &reference_options(48));
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let (view, objects) = twin_inputs(&bp, &vec![0u8; 1 << 26], &vec![0u8; 4]);
    for (x, y) in [(24, 24), (10, 20), (24, 10), (30, 15)] {
        let d = view.ray(x, y);
        let mut segs = 0;
        let mut hits = 0;
        for p in &objects[0].prisms {
            segs += voltex::cpu::prism_map::ray_intervals(d, p, 0.0, f64::INFINITY).len();
            hits += voltex::cpu::prism_map::boundary_hits(d, p).len();
        }
        println!("pixel {x},{y}: gpu {:?} cpu segs {segs} hits {hits}", gpu.get(x, y));
    }
}
#[test]
fn debug_data() {
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let set = bp.reference.as_ref().unwrap();
    let p = set.prisms[0];
    println!("prism0 {:?} vertex {:?} forward {:?} params {:?}", p, set.vertices[p.vertices[0] as usize], bp.frame.forward, set.params);
}
#[test]
fn debug_cpu_miss() {
    use glam::DVec3;
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let set = bp.reference.as_ref().unwrap();
    let (view, objects) = twin_inputs(&bp, &vec![0u8; 1 << 26], &vec![0u8; 4]);
    let d = view.ray(24, 24);
    let mut best = f64::INFINITY;
    for p in &set.prisms {
        let v = |i: u32| { let b = set.vertices[i as usize].bottom; DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64) };
        let a = v(p.vertices[0]); let e1 = v(p.vertices[1]) - a; let e2 = v(p.vertices[2]) - a;
        let pp = d.cross(e2); let det = e1.dot(pp); let s = -a; let u = s.dot(pp)/det; let q = s.cross(e1); let vv = d.dot(q)/det;
        best = best.min((-u).max(-vv).max(u+vv-1.0));
    }
    let mut best2 = f64::INFINITY;
    for p in &objects[0].prisms {
        let a = p.bottom[0]; let e1 = p.bottom[1] - a; let e2 = p.bottom[2] - a;
        let pp = d.cross(e2); let det = e1.dot(pp); let s = -a; let u = s.dot(pp)/det; let q = s.cross(e1); let vv = d.dot(q)/det;
        best2 = best2.min((-u).max(-vv).max(u+vv-1.0));
    }
    println!("d {d:?} best gpu-data {best} best twin-data {best2}");
}
#[test]
fn debug_v65() {
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let set = bp.reference.as_ref().unwrap();
    println!("v65 {:?}", set.vertices[65]);
}
#[test]
fn debug_p0() {
    use glam::DVec3;
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let set = bp.reference.as_ref().unwrap();
    let (view, _objects) = twin_inputs(&bp, &vec![0u8; 1 << 26], &vec![0u8; 4]);
    let d = view.ray(24, 24);
    let p = set.prisms[0];
        let v = |i: u32| { let b = set.vertices[i as usize].bottom; DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64) };
        let a = v(p.vertices[0]); let e1 = v(p.vertices[1]) - a; let e2 = v(p.vertices[2]) - a;
        let pp = d.cross(e2); let det = e1.dot(pp); let s = -a; let u = s.dot(pp)/det; let q = s.cross(e1); let vv = d.dot(q)/det;
    println!("cpu p0 det {det} u {u} v {vv} b2x {}", v(p.vertices[2]).x);
}
#[test]
fn debug_sums() {
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let bp = Blueprint::new(&scene, &reference_options(48)).unwrap();
    let set = bp.reference.as_ref().unwrap();
    let mut sum = 0u64; let mut sumx = 0.0f64;
    for p in &set.prisms { sum += (p.vertices[0]+p.vertices[1]+p.vertices[2]) as u64;
      sumx += set.vertices[p.vertices[0] as usize].bottom[0] as f64 + set.vertices[p.vertices[1] as usize].bottom[1] as f64 + set.vertices[p.vertices[2] as usize].top[2] as f64; }
    println!("cpu n {} sum {sum} sumx {sumx}", set.prisms.len());
}
