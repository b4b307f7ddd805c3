//! Baked self-shadowing (`bake/shadow_texel.wgsl`, Meyer & Neyret 1998, 3.1): the kernel against
//! its f64 twin (`cpu::shadow_texel`), a uniform slab's exp(-sigma depth / cos), a column
//! shadowing its neighbour across the tile's edge, and the kernel in the bake's key.
use crate::common::adapter::{gpu, Expectations};
use crate::common::{ok, root, s, voltex};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use voltex::bake::shadow::Shadow;
use voltex::bake::{BakeRequest, BakeSource, Baker, StackTexels};
use voltex::cpu::shadow_texel::{shadow_params, shadow_texel};
use voltex::gpu::readback::read_texture;
use voltex::gpu::sources::Sources;

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("voltex-shadow-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The texel "t" of a scene whose texels map holds `texel`, baked as `voltex render` plans it.
fn plan(name: &str, texel: &str) -> voltex::methods::plan::BakePlan {
    let path = temp(name).join("scene.ron");
    let text = format!(
        "#![enable(implicit_some)]\nScene(output: (width: 16, height: 16), camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)),\n\
         lights: [Directional(direction: (0.3, -0.5, -1.0))],\ntexels: {{ \"t\": {texel} }})"
    );
    std::fs::write(&path, text).unwrap();
    voltex::render::baked_texel(&voltex::scene::load(&path).unwrap(), "t").unwrap()
}

/// RGBA voxels of a bake: f32 with `full`, else the 8-bit volume in [0, 1].
fn bake(request: &BakeRequest, full: bool) -> Vec<[f32; 4]> {
    let ctx = gpu!(ADAPTER);
    let sources = Sources::project().unwrap();
    if full {
        let baked = Baker::full_precision(&sources).bake(&ctx, request).unwrap();
        bytemuck::pod_collect_to_vec(&read_texture(&ctx, &baked.volume, 16).unwrap())
    } else {
        let baked = Baker::new(&sources).bake(&ctx, request).unwrap();
        let bytes = read_texture(&ctx, &baked.volume, 4).unwrap();
        bytes.chunks(4).map(|c| std::array::from_fn(|i| c[i] as f32 / 255.0)).collect()
    }
}

fn largest_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs())).fold(0.0, f32::max)
}

#[test]
fn the_shadow_kernel_matches_its_twin() {
    // Soft and opaque spheres (one across the tile's corner), a light 40 degrees off the vertical
    // from the scene (default direction), and one given in the texel's own space.
    let shapes = "source: Implicit(shapes: [\
        Sphere(center: (0.5, 0.5, 0.5), radius: 0.25, color: (0.8, 0.6, 0.3), opacity: 0.7),\
        Sphere(center: (0.95, 0.05, 0.3), radius: 0.2, color: (0.3, 0.7, 0.2), opacity: 1.0)])";
    for (i, shadow) in [
        "shadow: (extinction: 30.0)",
        "shadow: (extinction: 12.0, direction: (-1.0, 0.4, -0.8), ambient: 0.3)",
    ]
    .iter()
    .enumerate()
    {
        let mut p = plan(&format!("twin{i}"), &format!("(resolution: (24, 20, 16), {shapes}, {shadow})"));
        let sh = p.request.shadow.expect("the scene's shadow in the request");
        if i == 1 {
            assert_eq!(sh.toward_light, [1.0, -0.4, 0.8], "the texel's own direction, towards the light");
            assert_eq!(sh.ambient, 0.3);
        }
        let shadowed = bake(&p.request, true);
        let shadowed_8bit = bake(&p.request, false);
        p.request.shadow = None;
        let unshadowed = bake(&p.request, true);
        let unshadowed_8bit = bake(&p.request, false);
        let params = sh.params(p.request.resolution);
        let twin = shadow_texel(&params, &unshadowed);
        let error = largest_difference(&shadowed, &twin);
        let darkened = unshadowed.iter().zip(&shadowed).filter(|(u, s)| s[0] < u[0] * 0.9).count();
        eprintln!("shadow {i}: kernel against twin, f32 volume: largest difference {error:.2e}; {darkened} voxels darkened");
        assert!(error < 1e-6, "f32 volume: {error}");
        assert!(darkened > 100, "the shadows darken the texel: {darkened} voxels");
        // The 8-bit volume: the twin of the 8-bit unshadowed volume, within the last rounding.
        let error = largest_difference(&shadowed_8bit, &shadow_texel(&params, &unshadowed_8bit));
        eprintln!("shadow {i}: 8-bit volume: largest difference {error:.2e}");
        assert!(error <= 0.5 / 255.0 + 1e-4, "8-bit volume: {error}");
    }
}

#[test]
fn a_constant_slab_is_shadowed_as_exp_of_depth_over_cos() {
    // A Constant texel fills the box: an infinite slab 1 high (s and t wrap). With a bias of b
    // voxels the march starts b voxels higher (w crosses fastest in both directions here).
    let (alpha, sigma, n) = (0.6, 5.0, 16u32);
    for (name, direction, cos, bias) in [
        ("above", "(0.0, 0.0, -1.0)", 1.0, 0.0),
        ("angled", "(-0.48, -0.64, -0.6)", 0.6, 0.0),
        ("angled-bias", "(-0.48, -0.64, -0.6)", 0.6, 2.0),
    ] {
        let texel = format!(
            "(resolution: (8, 8, {n}), source: Constant(color: (1.0, 1.0, 1.0), opacity: {alpha}), \
             shadow: (extinction: {sigma}, direction: {direction}, bias: {bias:?}))"
        );
        let mut p = plan(name, &texel);
        let v = bake(&p.request, true);
        p.request.shadow = None;
        let lit = bake(&p.request, true);
        for z in 0..n {
            let depth = ((n as f64 - (z as f64 + 0.5) - bias) / n as f64).max(0.0);
            let t = (-sigma * alpha * depth / cos).exp();
            for voxel in [(0, 0), (5, 3), (7, 7)] {
                let i = voxel.0 + 8 * (voxel.1 + 8 * z as usize);
                let (got, expected) = (v[i], lit[i][1] as f64 * t);
                assert!(lit[i][1] > 0.1, "a lit voxel has colour: {:?}", lit[i]);
                assert!(
                    (got[1] as f64 - expected).abs() < 1e-5,
                    "{name}, layer {z}: {got:?} against {expected}"
                );
                assert!((got[3] as f64 - alpha).abs() < 1e-6, "{name}: alpha kept");
            }
        }
    }
}

#[test]
fn a_column_shadows_its_neighbour_across_the_tile_edge() {
    // An opaque column at s = 0 uploaded as a slice stack; light towards +s and up at 45 degrees.
    let n = 16u32;
    let mut stack = Vec::new();
    for _z in 0..n {
        for _y in 0..4 {
            for x in 0..n {
                let a = if x == 0 { u16::MAX } else { 0 };
                stack.extend([u16::MAX / 2, u16::MAX / 2, u16::MAX / 2, a]);
            }
        }
    }
    let shadow = Shadow { toward_light: [1.0, 0.0, 1.0], extinction: 8.0, ambient: 0.0, bias: 0.0 };
    let request = BakeRequest {
        resolution: [n, 4, n],
        source: BakeSource::Stack(StackTexels(std::sync::Arc::new(stack))),
        per_pixel: false,
        light: [0.0, 0.0, 1.0],
        ambient: 0.0,
        derived: voltex::methods::axis_slices::slice_images::slice_images(false),
        layers: false,
        shadow: Some(shadow),
    };
    let v = bake(&request, true);
    let at = |x: u32, z: u32| v[(x + n * (1 + 4 * z)) as usize];
    // Through the column's copy in the next tile, along a diagonal sqrt(2) / n long.
    let grey = (u16::MAX / 2) as f64 / u16::MAX as f64;
    let through = (grey * (-8.0 * 2f64.sqrt() / n as f64).exp()) as f32;
    for z in 0..n - 2 {
        assert!((at(n - 1, z)[0] - through).abs() < 1e-5, "z {z}: {:?} against {through}", at(n - 1, z));
    }
    assert!((at(1, 3)[0] - grey as f32).abs() < 1e-6, "right of the column: lit");
    let twin = shadow_texel(&shadow_params(request.resolution, shadow.toward_light, 8.0, 0.0, 0.0), &{
        let mut r = request;
        r.shadow = None;
        bake(&r, true)
    });
    assert!(largest_difference(&v, &twin) < 1e-5);
}

#[test]
fn the_shadow_kernel_is_in_the_bake_key() {
    // An edited shadow_texel.wgsl (beside a graph, as the preview reloads it) changes the key
    // of a shadowed bake only.
    let dir = temp("key");
    std::fs::create_dir_all(dir.join("bake")).unwrap();
    let project = Sources::project().unwrap();
    let text = std::fs::read_to_string(voltex::project_root().join("wgsl/bake/shadow_texel.wgsl")).unwrap();
    std::fs::write(dir.join("bake/shadow_texel.wgsl"), text.replace("v.rgb * light", "v.rgb * light * 0.5"))
        .unwrap();
    let edited = project.clone().beside(&dir.join("frame.ron"));
    let texel = "(resolution: (8, 8, 8), source: Constant(color: (1.0, 1.0, 1.0), opacity: 0.5)";
    let shadowed = plan("key-on", &format!("{texel}, shadow: (extinction: 2.0))")).request;
    let plain = plan("key-off", &format!("{texel})")).request;
    let key = |s: &Sources, r| voltex::render::bake_key(s, r).unwrap();
    assert!(shadowed.kernels().contains(&"bake/shadow_texel.wgsl"));
    assert!(!plain.kernels().contains(&"bake/shadow_texel.wgsl"));
    assert_ne!(key(&project, &shadowed), key(&edited, &shadowed));
    assert_eq!(key(&project, &plain), key(&edited, &plain));
    assert_ne!(key(&project, &plain), key(&project, &shadowed));
}

#[test]
fn plan_lists_the_shadow_pass() {
    let scene = root().join("scenes/meyer_neyret/shadowed_pears.ron");
    let printed = ok(voltex(&["plan", s(&scene)]));
    assert!(
        printed.contains(
            "(and its baked shadows: bake/shadow_texel.wgsl towards (0.672, -0.471, 0.572), extinction 80"
        ),
        "{printed}"
    );
}
