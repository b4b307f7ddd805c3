//! Texels baked from hypertextures (Meyer & Neyret 1998, 3.3): `bake_hypertexture.wgsl` against
//! its twin (both lightings, a non-cubic volume, a box of its own, animated noises, a volume baked
//! in several slabs), the opacity convention against RayMarch and the analytic slab, the bake
//! cache key, `voltex bake`, and bad input reported at its position.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use voltex::bake::hypertexture::HyperTexel;
use voltex::bake::{BakeRequest, BakeSource, Baker};
use voltex::cpu::bake::bake_params;
use voltex::cpu::bake_hypertexture::bake_hypertexture_voxel;
use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::gpu::readback::read_texture;
use voltex::render::{Blueprint, RenderOptions, Renderer};
use voltex::scene;

const LIGHT: [f32; 3] = [-0.4, 0.5, 0.75];
const AMBIENT: f32 = 0.3;

/// A scene with hypertexture `h` and texel `t` (both RON) and no nodes.
fn scene_with(hypertexture: &str, texel: &str) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 16, height: 16),\n    camera: (eye: (0.0, -3.0, 1.0), \
         target: (0.0, 0.0, 0.0)),\n    hypertextures: {{ \"h\": {hypertexture} }},\n    texels: {{ \"t\": {texel} }},\n)\n"
    );
    scene::parse(&text, Path::new("test.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const PUFF: &str = "(object: Sphere(radius: 0.5), noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.5, 1.0), \
     (1.0, 1.0, 0.0)]), amplitude: 0.15, frequency: 4.0), (shape: Table([0.0, 0.3, 1.0]), amplitude: 0.05, \
     frequency: 9.0, seed: 3)], color: Ramp([(0.0, (1.0, 1.0, 1.0, 0.0)), (0.3, (0.9, 0.8, 0.6, 0.0)), \
     (0.5, (0.9, 0.6, 0.4, 0.8)), (1.0, (0.6, 0.3, 0.2, 1.0))]), opacity_length: 0.03)";

/// The texel's packed hypertexture.
fn hyper_texel(scene: &scene::Scene, time: f64) -> HyperTexel {
    let t = &scene.texels["t"];
    let scene::TexelSource::Hypertexture { bounds, .. } = &t.source else { panic!("a hypertexture texel") };
    let bounds = bounds.as_ref().map(|b| (b.lo, b.hi));
    HyperTexel::new(&scene.hypertextures["h"], bounds, t.resolution, time)
}

/// Bakes `ht` at `resolution`: (rgba8 volume, rgba8snorm normals when per pixel).
fn bake(ht: &HyperTexel, resolution: [u32; 3], per_pixel: bool) -> (Vec<u8>, Vec<u8>) {
    let ctx = gpu!(ADAPTER);
    let req = BakeRequest {
        resolution,
        source: BakeSource::Hypertexture(Box::new(ht.clone())),
        per_pixel,
        light: LIGHT,
        ambient: AMBIENT,
        derived: Default::default(),
        layers: false,
        shadow: None,
    };
    let baked = Baker::new(&voltex::gpu::sources::Sources::project().unwrap()).bake(&ctx, &req).unwrap();
    let volume = read_texture(&ctx, &baked.volume, 4).unwrap();
    let normals = if per_pixel { read_texture(&ctx, &baked.normals, 4).unwrap() } else { Vec::new() };
    (volume, normals)
}

/// Compares the voxels `which` of a GPU bake with the twin: (largest difference of an 8-bit
/// colour channel in units of 1/255, voxels off by more than 2/255, largest normal difference
/// among voxels with some opacity, voxels with some opacity).
fn against_twin(
    ht: &HyperTexel,
    resolution: [u32; 3],
    per_pixel: bool,
    which: impl Iterator<Item = [u32; 3]>,
) -> (f32, usize, f32, usize) {
    let (volume, normals) = bake(ht, resolution, per_pixel);
    let tables = bake_transfer(&ht.packed.functions, &ht.packed.points);
    let model = Model { params: &ht.params, noises: &ht.packed.noises, tables: &tables, grid: None };
    let params = bake_params(resolution, 0, LIGHT, AMBIENT);
    let [w, h, _] = resolution;
    let (mut worst, mut off, mut worst_normal, mut matter) = (0.0f32, 0, 0.0f32, 0);
    for v in which {
        let i = 4 * (v[0] + w * (v[1] + h * v[2])) as usize;
        let (rgba, normal) = bake_hypertexture_voxel(&params, &model, v, per_pixel);
        let d = (0..4).map(|c| (volume[i + c] as f32 - rgba[c] * 255.0).abs()).fold(0.0, f32::max);
        worst = worst.max(d);
        off += (d > 2.0) as usize;
        matter += (rgba[3] > 0.0) as usize;
        if per_pixel && rgba[3] > 0.05 {
            let gpu = (0..3).map(|c| normals[i + c] as i8 as f32 / 127.0);
            let nd = gpu.zip(normal).map(|(g, n)| (g - n).abs()).fold(0.0, f32::max);
            worst_normal = worst_normal.max(nd);
        }
    }
    (worst, off, worst_normal, matter)
}

fn every(res: [u32; 3]) -> impl Iterator<Item = [u32; 3]> {
    (0..res[2]).flat_map(move |z| (0..res[1]).flat_map(move |y| (0..res[0]).map(move |x| [x, y, z])))
}

/// Every voxel of a non-cubic bake matches the twin in both lightings (8-bit rounding; a few
/// voxels where the f32 density crosses a steep stretch of the ramp may differ more), and the
/// per-pixel normals too where there is matter.
#[test]
fn bake_kernel_matches_twin() {
    let res = [20, 16, 12];
    let scene = scene_with(
        PUFF,
        &format!("(resolution: {res:?}, source: Hypertexture(name: \"h\"))")
            .replace('[', "(")
            .replace(']', ")"),
    );
    let ht = hyper_texel(&scene, 0.0);
    let (lo, hi) = ht.bounds();
    assert!((lo + 0.7).abs().max_element() < 1e-6 && (hi - 0.7).abs().max_element() < 1e-6, "{lo} {hi}");
    let n = (res[0] * res[1] * res[2]) as usize;
    for per_pixel in [false, true] {
        let (worst, off, normal, _) = against_twin(&ht, res, per_pixel, every(res));
        eprintln!(
            "per_pixel {per_pixel}: worst {worst}/255, {off} of {n} voxels off by > 2/255, normal {normal}"
        );
        assert!(
            off * 500 <= n && worst <= 16.0,
            "per_pixel {per_pixel}: {off} voxels off, worst {worst}/255"
        );
        assert!(normal < 0.05 || !per_pixel, "normals differ by {normal}");
    }
    // Something was baked: the middle is opaque, the corners empty.
    let (volume, _) = bake(&ht, res, false);
    let at = |v: [u32; 3]| volume[4 * (v[0] + 20 * (v[1] + 16 * v[2])) as usize + 3];
    assert!(at([10, 8, 6]) > 200 && at([0, 0, 0]) == 0);
}

/// A box of its own (half the object, offset) and animated noises baked at a time both match
/// the twin; the time changes an animated bake, and the cache key, and nothing else's.
#[test]
fn bounds_and_time_match_twin() {
    let animated = PUFF.replace("frequency: 4.0)", "frequency: 4.0, speed: 0.8)");
    let texel = "(resolution: (16, 16, 16), source: Hypertexture(name: \"h\", bounds: (lo: (0.0, -0.3, -0.6), hi: (0.6, 0.3, 0.0))))";
    let scene = scene_with(&animated, texel);
    let (a, b) = (hyper_texel(&scene, 0.5), hyper_texel(&scene, 1.5));
    assert_eq!(a.params.march[3], 0.5);
    let (lo, hi) = a.bounds();
    let want = (glam::DVec3::new(0.0, -0.3, -0.6), glam::DVec3::new(0.6, 0.3, 0.0));
    assert!(
        (lo - want.0).abs().max_element() < 1e-6 && (hi - want.1).abs().max_element() < 1e-6,
        "{lo} {hi}"
    );
    let (worst, off, _, _) = against_twin(&a, [16; 3], false, every([16; 3]));
    eprintln!("animated, own box: worst {worst}/255, {off} voxels off by > 2/255");
    assert!(off * 500 <= 4096 && worst <= 16.0, "{off} voxels off, worst {worst}/255");
    assert_ne!(bake(&a, [16; 3], false).0, bake(&b, [16; 3], false).0, "time changes an animated bake");
    assert_ne!(format!("{a:?}"), format!("{b:?}"));
    // A still hypertexture bakes the same at every time: one cache entry.
    let still = scene_with(PUFF, texel);
    assert_eq!(format!("{:?}", hyper_texel(&still, 0.5)), format!("{:?}", hyper_texel(&still, 1.5)));
    // The hypertexture's definition is part of the key.
    let other = scene_with(&PUFF.replace("seed: 3", "seed: 4"), texel);
    assert_ne!(format!("{:?}", hyper_texel(&still, 0.0)), format!("{:?}", hyper_texel(&other, 0.0)));
}

/// A mesh object (a box OBJ): its grid is baked before the texel, which matches the twin reading
/// the same grid.
#[test]
fn mesh_object_matches_twin() {
    let dir = std::env::temp_dir().join(format!("voltex-hyper-texel-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cube = "v -0.5 -0.4 -0.3\nv 0.5 -0.4 -0.3\nv 0.5 0.4 -0.3\nv -0.5 0.4 -0.3\nv -0.5 -0.4 0.3\nv 0.5 -0.4 0.3\n\
                v 0.5 0.4 0.3\nv -0.5 0.4 0.3\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    std::fs::write(dir.join("box.obj"), cube).unwrap();
    let hyper = PUFF.replace("Sphere(radius: 0.5)", "Mesh(path: \"box.obj\", resolution: 24)");
    let text = format!(
        "#![enable(implicit_some)]\nScene(output: (width: 16, height: 16), camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)), \
         hypertextures: {{ \"h\": {hyper} }}, texels: {{ \"t\": (resolution: (16, 16, 16), source: Hypertexture(name: \"h\")) }})\n"
    );
    std::fs::write(dir.join("mesh.ron"), text).unwrap();
    let scene = scene::load(&dir.join("mesh.ron")).unwrap();
    let ht = hyper_texel(&scene, 0.0);
    let (shape, spec) = ht.packed.mesh.clone().expect("a mesh object");
    let (volume, _) = bake(&ht, [16; 3], false);
    let (cells, depth) = {
        let ctx = gpu!(ADAPTER);
        let grid = voltex::hypertexture::mesh::bake(&ctx, &shape, &spec).unwrap();
        voltex::hypertexture::mesh::read(&ctx, &grid).unwrap()
    };
    let tables = bake_transfer(&ht.packed.functions, &ht.packed.points);
    let model =
        Model { params: &ht.params, noises: &ht.packed.noises, tables: &tables, grid: Some((&cells, depth)) };
    let params = bake_params([16; 3], 0, LIGHT, AMBIENT);
    let (mut worst, mut off, mut matter) = (0.0f32, 0, 0);
    for v in every([16; 3]) {
        let i = 4 * (v[0] + 16 * (v[1] + 16 * v[2])) as usize;
        let (rgba, _) = bake_hypertexture_voxel(&params, &model, v, false);
        let d = (0..4).map(|c| (volume[i + c] as f32 - rgba[c] * 255.0).abs()).fold(0.0, f32::max);
        worst = worst.max(d);
        off += (d > 2.0) as usize;
        matter += (volume[i + 3] > 128) as usize;
    }
    eprintln!("mesh object: worst {worst}/255, {off} voxels off by > 2/255, {matter} more than half opaque");
    // The grid's f32 trilinear weights against f64 ones: a few voxels on steep stretches of the
    // ramp differ by a few levels.
    assert!(
        off * 500 <= 4096 && worst <= 16.0 && matter > 100,
        "worst {worst}/255, {off} off, {matter} opaque"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A volume of more than `VOXELS_PER_DISPATCH` voxels is baked in slabs of layers: the layers on
/// both sides of a slab boundary and the last one match the twin.
#[test]
fn slabs_of_layers_match_twin() {
    let res = [128, 128, 80];
    assert!(res[0] * res[1] * res[2] > voltex::bake::hypertexture::VOXELS_PER_DISPATCH);
    let scene = scene_with(PUFF, "(resolution: (128, 128, 80), source: Hypertexture(name: \"h\", bounds: (lo: (-0.7, -0.7, -0.7), hi: (0.7, 0.7, 0.0))))");
    let ht = hyper_texel(&scene, 0.0);
    let layers = [0, 31, 63, 64, 65, 79];
    // (Layer 64 cuts the puff: a slab written to the wrong layers would show.)
    let which = layers.into_iter().flat_map(|z| (0..128).flat_map(move |y| (0..128).map(move |x| [x, y, z])));
    let (worst, off, _, _) = against_twin(&ht, res, false, which);
    eprintln!("slabs: worst {worst}/255, {off} voxels off by > 2/255");
    let at = |z: u32| (0..128).flat_map(move |y| (0..128).map(move |x| [x, y, z]));
    let (.., matter) = against_twin(&ht, res, false, at(64));
    eprintln!("layer 64: {matter} voxels of matter");
    assert!(matter > 1000, "layer 64 holds {matter} voxels of matter");
    assert!(off * 500 <= 6 * 128 * 128 && worst <= 16.0, "{off} voxels off, worst {worst}/255");
}

/// A slab with periodic noises baked over one period tiles: the box moved by a whole period
/// along x or y bakes the same texel (to 8-bit rounding), while without `period` it does not.
#[test]
fn periodic_slab_tiles() {
    let slab = |period: &str| {
        format!(
            "(object: Box(size: (4000.0, 4000.0, 0.1)), field: Constant(direction: (0.0, 0.0, 1.0)), noises: [(shape: \
             Curve([(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]), amplitude: 0.25, frequency: 6.0{period}), (shape: Table([0.0, 1.0]), \
             amplitude: 0.1, frequency: 15.0, seed: 7{period})], color: Ramp([(0.0, (0.3, 0.5, 0.1, 0.0)), (0.2, (0.3, 0.5, \
             0.1, 0.0)), (0.4, (0.4, 0.6, 0.2, 0.9)), (1.0, (0.1, 0.2, 0.1, 1.0))]), opacity_length: 0.01)"
        )
    };
    let texel = |lo: [f64; 2]| {
        format!(
            "(resolution: (16, 16, 8), source: Hypertexture(name: \"h\", bounds: (lo: ({}, {}, -0.05), hi: ({}, {}, 0.4))))",
            lo[0],
            lo[1],
            lo[0] + 1.0,
            lo[1] + 1.0
        )
    };
    let volume = |period: &str, lo: [f64; 2]| {
        bake(&hyper_texel(&scene_with(&slab(period), &texel(lo)), 0.0), [16, 16, 8], false).0
    };
    let worst = |a: &[u8], b: &[u8]| a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    let periodic = ", period: (1.0, 1.0, 1.0)";
    let home = volume(periodic, [-0.5, -0.5]);
    assert!(home.chunks(4).filter(|p| p[3] > 128).count() > 200, "some matter");
    for lo in [[0.5, -0.5], [-0.5, 1.5]] {
        let moved = volume(periodic, lo);
        eprintln!("periodic, box at {lo:?}: worst {}/255", worst(&home, &moved));
        assert!(worst(&home, &moved) <= 1, "box at {lo:?}");
    }
    let (plain, moved) = (volume("", [-0.5, -0.5]), volume("", [0.5, -0.5]));
    eprintln!("not periodic: worst {}/255", worst(&plain, &moved));
    assert!(worst(&plain, &moved) > 64);
}

// ---- opacity: a texel is as opaque as RayMarch draws its hypertexture ----

/// A box of constant colour and opacity (no distortion), seen from straight above at `scale`,
/// drawn by `node` (RON) over a black background; fully lit (ambient 1) so shading is the albedo.
fn slab_scene(scale: f64, node: &str, texel_length: &str) -> scene::Scene {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 24, height: 24),\n    camera: (eye: (0.0, 0.0, {eye}), \
         target: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov_y: 20.0),\n    ambient: 1.0,\n    \
         lights: [Directional(direction: (0.0, 0.0, -1.0))],\n    hypertextures: {{ \"h\": (object: Box(size: (1.0, 1.0, 0.5)), \
         noises: [(shape: Table([0.0, 1.0]), amplitude: 0.0, frequency: 1.0)], color: Ramp([(0.0, (0.8, 0.8, 0.8, 0.3)), \
         (1.0, (0.8, 0.8, 0.8, 0.3))]), opacity_length: 0.1) }},\n    texels: {{ \"t\": (resolution: (8, 8, 8), {texel_length}\
         source: Hypertexture(name: \"h\")) }},\n    nodes: [{node}],\n)\n",
        eye = 3.0 * scale
    );
    scene::parse(&text, Path::new("slab.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The centre pixel of a render.
fn centre(scene: &scene::Scene) -> f64 {
    let ctx = gpu!(ADAPTER);
    let bp = Blueprint::new(scene, &RenderOptions::default()).unwrap();
    let image = Renderer::new(&ctx, bp).unwrap().render(&ctx).unwrap().image;
    image.pixels[(12 * 24 + 12) as usize][0] as f64
}

/// Through the box's 0.5 (times the scale) of constant opacity 0.3 per 0.1 of world length, a
/// texel drawn with ViewSlices and with AxisSlices (blended: binary alpha is the paper's
/// threshold) matches RayMarch and the analytic slab
/// `0.8 (1 - 0.7^(thickness / 0.1))` at scale 1 and 2 (8-bit voxels: within 2%).
#[test]
fn opacity_matches_ray_march_at_any_scale() {
    for scale in [1.0, 2.0] {
        let expected = 0.8 * (1.0 - 0.7f64.powf(0.5 * scale / 0.1));
        let marched = format!(
            "(name: \"m\", transform: (scale: ({scale}, {scale}, {scale})), hypertexture: \"h\", method: RayMarch(step: 0.005))"
        );
        let base = format!(
            "name: \"s\", transform: (translate: (0.0, 0.0, {})), surface: Plane(size: ({scale}, {scale}), cells: (2, 2)), \
             height: (length: {}), texel: \"t\"",
            -0.25 * scale,
            0.5 * scale
        );
        let ray = centre(&slab_scene(scale, &marched, ""));
        let view = centre(&slab_scene(scale, &format!("({base}, method: ViewSlices(planes: 64))"), ""));
        let axis = centre(&slab_scene(scale, &format!("({base}, method: AxisSlices(blend: Blended))"), ""));
        eprintln!("scale {scale}: analytic {expected:.4}, RayMarch {ray:.4}, ViewSlices {view:.4}, AxisSlices {axis:.4}");
        for (what, v) in [("RayMarch", ray), ("ViewSlices", view), ("AxisSlices", axis)] {
            assert!((v / expected - 1.0).abs() < 0.02, "scale {scale}: {what} {v} against {expected}");
        }
    }
    // A texel length of its own is used, with a warning at the hypertexture's name.
    let scene =
        slab_scene(1.0, "(name: \"m\", hypertexture: \"h\", method: RayMarch())", "opacity_length: 0.2, ");
    assert_eq!(scene.texels["t"].opacity_length(&scene.hypertextures), 0.2);
    assert!(
        scene.warnings.len() == 1
            && scene.warnings[0].starts_with("slab.ron:8:")
            && scene.warnings[0].contains("less opaque"),
        "{:?}",
        scene.warnings
    );
}

// ---- the command line and bad input ----

/// `voltex bake` writes the slice stack of a hypertexture texel, and the example scene renders.
#[test]
fn bake_command_writes_the_slice_stack() {
    let dir = std::env::temp_dir().join(format!("voltex-hyper-texel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("puff.ron");
    let text = format!(
        "#![enable(implicit_some)]\nScene(output: (width: 16, height: 16), camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)), \
         hypertextures: {{ \"h\": {PUFF} }}, texels: {{ \"t\": (resolution: (16, 16, 8), source: Hypertexture(name: \"h\")) }})\n"
    );
    std::fs::write(&path, text).unwrap();
    let out = common::ok(common::voltex(&["bake", common::s(&path), "--out", common::s(&dir.join("out"))]));
    assert!(out.contains("16x16x8"), "{out}");
    let slices = std::fs::read_dir(dir.join("out/t")).unwrap().count();
    assert!(slices >= 8, "{slices} files");
    std::fs::remove_dir_all(&dir).ok();
}

/// An animated hypertexture texel drawn by `voltex render --frames`: each frame bakes it at its
/// own time (frames 0 and 2 at 1 fps differ), and a repeated time gives the same image.
#[test]
fn render_frames_bake_animated_texels_at_their_time() {
    let dir = std::env::temp_dir().join(format!("voltex-hyper-texel-frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let animated = PUFF.replace("frequency: 4.0)", "frequency: 4.0, speed: 0.5)");
    let text = format!(
        "#![enable(implicit_some)]\nScene(output: (width: 24, height: 24), camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)), \
         hypertextures: {{ \"h\": {animated} }}, texels: {{ \"t\": (resolution: (16, 16, 16), source: Hypertexture(name: \"h\")) }}, \
         nodes: [(name: \"s\", transform: (translate: (0.0, 0.0, -0.7)), surface: Plane(size: (1.4, 1.4), cells: (1, 1)), \
         height: (length: 1.4), texel: \"t\", method: ViewSlices(planes: 64))])\n"
    );
    std::fs::write(dir.join("anim.ron"), text).unwrap();
    let (out, scene) = (dir.join("anim.exr"), dir.join("anim.ron"));
    let args = ["render", common::s(&scene), "-o", common::s(&out), "--frames", "0..2", "--fps", "1"];
    common::ok(common::voltex(&args));
    let frame = |n: u32| voltex::io::exr::read(&dir.join(format!("anim_{n:04}.exr"))).unwrap().0.pixels;
    let (f0, f2) = (frame(0), frame(2));
    let differ = f0.iter().zip(&f2).filter(|(a, b)| (a[0] - b[0]).abs() > 0.01).count();
    assert!(differ > 20, "{differ} pixels differ between frames 0 and 2");
    let single = dir.join("single.exr");
    common::ok(common::voltex(&["render", common::s(&scene), "-o", common::s(&single), "--time", "2"]));
    assert_eq!(voltex::io::exr::read(&single).unwrap().0.pixels, f2, "--time 2 renders frame 2");
    std::fs::remove_dir_all(&dir).ok();
}

/// The scene with the texel line replaced: the error is at line 7 where `at` starts, mentions
/// `word`, and `voltex render` exits 1 writing nothing.
#[track_caller]
fn bad(texel: &str, at: &str, word: &str) {
    let text = format!(
        "#![enable(implicit_some)]\nScene(\n    output: (width: 16, height: 16),\n    camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)),\n    \
         hypertextures: {{ \"h\": {PUFF} }},\n    texels: {{\n        \"t\": {texel},\n    }},\n)\n"
    );
    let col = texel.find(at).unwrap() + 14;
    let e = scene::parse(&text, Path::new("bad.ron"))
        .err()
        .unwrap_or_else(|| panic!("no error for {texel}"))
        .to_string();
    assert!(
        e.starts_with(&format!("bad.ron:7:{col}: ")) && e.contains(word),
        "want 7:{col} and `{word}`: {e}"
    );
    let dir = std::env::temp_dir().join(format!("voltex-hyper-texel-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bad.ron"), &text).unwrap();
    let out =
        common::voltex(&["render", common::s(&dir.join("bad.ron")), "-o", common::s(&dir.join("out.exr"))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("bad.ron:7:{col}:")) && err.contains(word), "{err}");
    assert!(!dir.join("out.exr").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_hypertexture_texels_are_reported_at_their_position() {
    bad(
        "(resolution: (8, 8, 8), source: Hypertexture(name: \"wool\"))",
        "\"wool\"",
        "unknown hypertexture \"wool\": expected one of \"h\"",
    );
    bad(
        "(resolution: (8, 8, 8), source: Hypertexture(name: \"h\", bounds: (lo: (0.0, 0.0, 0.5), hi: (1.0, 1.0, 0.5))))",
        "(lo:",
        "expected `lo` below `hi` on every axis, found 0.5 >= 0.5 on z",
    );
    bad(
        "(resolution: (512, 512, 128), source: Hypertexture(name: \"h\"))",
        "\"h\"",
        "at most 16777216 (256^3)",
    );
    bad("(resolution: (8, 8, 8), source: Hypertexture(nme: \"h\"))", "nme", "name");
}
