//! ViewSlices' `Tiles` compositor: the same image as the raster path up to coverage and blending
//! rounding, as close to the Reference, the binning kernel against its CPU twin, and the lists'
//! overflow path drawing the same image.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: f32 blending, since they compare the raster
/// compositor's blended image with the tiles' f32 compute one to 2e-4 (without it the graph
/// blends in f16 and says so).
const ADAPTER: Expectations =
    Expectations { features: wgpu::Features::FLOAT32_BLENDABLE, ..Expectations::DEFAULTS };

use std::path::PathBuf;

use voltex::io::Image;
use voltex::methods::view_slices::{tiles, ViewSlicesPlan};
use voltex::render::{Blueprint, MethodKind, RenderOptions, Renderer};
use voltex::scene::{self, Compositor};
use voltex::types::{DrawIndirect, SliceVertex, TileAttributes, TileTriangle};

fn example(name: &str) -> PathBuf {
    voltex::project_root().join("scenes/view_slices").join(name)
}

fn options(compositor: Compositor) -> RenderOptions {
    RenderOptions { size: Some((64, 64)), compositor: Some(compositor), ..Default::default() }
}

fn render(name: &str, opts: &RenderOptions) -> Image {
    render_scene(&scene::load(&example(name)).unwrap(), opts)
}

fn render_scene(scene: &scene::Scene, opts: &RenderOptions) -> Image {
    let ctx = crate::common::adapter::device(&ADAPTER);
    let mut r = Renderer::new(&ctx, Blueprint::new(scene, opts).unwrap()).unwrap();
    r.render(&ctx).unwrap().image
}

/// Per pixel, the largest channel difference.
fn pixel_differences(a: &Image, b: &Image) -> Vec<f64> {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..3).map(|c| (p[c] as f64 - q[c] as f64).abs()).fold(0.0, f64::max))
        .collect()
}

/// Both compositors on torus_egg and flat_box at 64x64: the tiles path composites front to back
/// in f32 registers and stops at transmittance 1e-4, the rasteriser blends back to front, so
/// most pixels agree to 2e-3; the rest are pixel centres on or within rounding of a slice's
/// silhouette edge, which llvmpipe's fixed-point edge test and the tiles' f32 one can place on
/// either side (one fragment, at most 0.01 here). Against the Reference, the tiles image is as
/// close as the raster one.
#[test]
fn tiles_composite_the_raster_image() {
    for name in ["torus_egg.ron", "flat_box.ron"] {
        let raster = render(name, &options(Compositor::Raster));
        let tiles = render(name, &options(Compositor::Tiles));
        let truth = render(
            name,
            &RenderOptions {
                method: Some(MethodKind::named("Reference").unwrap()),
                ..options(Compositor::Raster)
            },
        );
        let d = pixel_differences(&raster, &tiles);
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let far = d.iter().filter(|&&v| v > 2e-3).count();
        let max = d.iter().copied().fold(0.0, f64::max);
        eprintln!("{name}: mean {mean:.2e}, max {max:.2e}, {far} of {} pixels over 2e-3", d.len());
        assert!(mean < 2e-4, "{name}: mean difference {mean}");
        assert!(max < 0.01, "{name}: largest difference {max}");
        assert!(far * 25 < d.len(), "{name}: {far} pixels differ by more than 2e-3");
        let flip_raster = voltex::metrics::flip(&raster, &truth).unwrap().mean;
        let flip_tiles = voltex::metrics::flip(&tiles, &truth).unwrap().mean;
        eprintln!("{name}: FLIP against the Reference: raster {flip_raster:.4}, tiles {flip_tiles:.4}");
        assert!(flip_tiles <= flip_raster + 2e-3, "{name}: tiles {flip_tiles} against raster {flip_raster}");
    }
}

/// Per-pixel lighting interpolates each slice vertex's frame (from its prism) over the polygon:
/// the rasteriser as a varying, the tiles from the triangle's barycentrics. On a torus of 2,304
/// prisms, whose frames differ from prism to prism, both draw the same image.
#[test]
fn per_pixel_lighting_tiles_composite_the_raster_image() {
    let text = std::fs::read_to_string(example("torus_egg.ron")).unwrap();
    let lit = text
        .replace("segments: (24, 12)", "segments: (48, 24)")
        .replace("resolution: (128, 128, 128)", "resolution: (32, 32, 32)")
        .replace("lighting: Baked", "lighting: PerPixel");
    assert_eq!(lit.matches("(48, 24)").count() + lit.matches("PerPixel").count(), 2);
    let scene = scene::parse(&lit, &example("torus_egg.ron")).unwrap();
    let raster = render_scene(&scene, &options(Compositor::Raster));
    let tiles = render_scene(&scene, &options(Compositor::Tiles));
    let baked = render("torus_egg.ron", &options(Compositor::Raster));
    let d = pixel_differences(&raster, &tiles);
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let max = d.iter().copied().fold(0.0, f64::max);
    // How far apart two different lightings are, for scale.
    let apart = pixel_differences(&raster, &baked).iter().sum::<f64>() / d.len() as f64;
    eprintln!(
        "per-pixel torus: raster against tiles mean {mean:.2e}, max {max:.2e}; against baked {apart:.2e}"
    );
    assert!(mean < 2e-4, "mean difference {mean}");
    assert!(max < 0.01, "largest difference {max}");
    assert!(apart > 20.0 * mean, "the lit image is too close to the baked one ({apart}) to tell");
}

/// Lists too small for the sweep: every overflowing segment is composited from all the
/// triangles of its planes, which draws the same image (up to which of two slices of one plane
/// a pixel keeps where adjacent prisms' slices overlap by rounding).
#[test]
fn overflowing_lists_draw_the_same_image() {
    let full = render("torus_egg.ron", &options(Compositor::Tiles));
    let small =
        render("torus_egg.ron", &RenderOptions { tile_entries: Some(4096), ..options(Compositor::Tiles) });
    let max = voltex::metrics::max_abs_diff(&full, &small).unwrap();
    assert!(max < 1e-4, "largest difference {max}");
}

fn read<T: bytemuck::Pod>(r: &Renderer, i: usize, name: &str) -> Vec<T> {
    let ctx = gpu!(ADAPTER);
    let bytes = r.read_instance_buffer(&ctx, i, name).unwrap();
    bytemuck::pod_collect_to_vec(&bytes[..bytes.len() / std::mem::size_of::<T>() * std::mem::size_of::<T>()])
}

/// `bin_slices`, `scan_tiles` and `fill_tiles` against their twins on the slices the GPU emitted
/// for torus_egg: the same triangles (edges, tile ranges, planes) and texel-coordinate planes,
/// the same segment ends, and the same entries in each segment (their order is the atomics').
#[test]
fn binning_matches_its_twin() {
    let scene = scene::load(&example("torus_egg.ron")).unwrap();
    let opts = RenderOptions { planes: Some(96), ..options(Compositor::Tiles) };
    let r = {
        let ctx = gpu!(ADAPTER);
        let mut r = Renderer::new(&ctx, Blueprint::new(&scene, &opts).unwrap()).unwrap();
        r.render(&ctx).unwrap();
        r
    };
    let i = r.blueprint.find_instance("ViewSlicesTiles").expect("a Tiles instance");
    let vs = r.blueprint.objects[0].method::<ViewSlicesPlan>().unwrap();
    let params = tiles::tile_params(r.blueprint.size, vs.sweep.plane_count, vs.tile_entries[0]);
    let frame = r.blueprint.frame;
    let count = read::<DrawIndirect>(&r, i, "draw_args")[0].vertex_count as usize;
    let vertices = &read::<SliceVertex>(&r, i, "slice_vertices")[..count];
    let plane_ends = &read::<u32>(&r, i, "plane_cursors")[..vs.sweep.plane_count as usize];
    let (triangles, attributes, counts) = tiles::bin_slices(&frame, &params, vertices, plane_ends);
    assert!(triangles.len() > 1000, "{} triangles", triangles.len());
    let gpu_triangles = read::<TileTriangle>(&r, i, "tile_triangles");
    let gpu_attributes = read::<TileAttributes>(&r, i, "tile_attributes");
    let close = |a: &[f32], b: &[f32], what: &str, t: usize| {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-3 * (1.0 + x.abs()), "triangle {t} {what}: {a:?} against {b:?}");
        }
    };
    for (t, (c, g)) in triangles.iter().zip(&gpu_triangles).enumerate() {
        assert_eq!((c.plane, c.tiles), (g.plane, g.tiles), "triangle {t}");
        for (a, b) in [(&c.e0, &g.e0), (&c.e1, &g.e1), (&c.e2, &g.e2)] {
            close(&a[..3], &b[..3], "edge", t);
            assert_eq!(a[3], b[3], "triangle {t}: tie owner");
        }
        let (a, b) = (&attributes[t], &gpu_attributes[t]);
        close(&[a.at_a, a.d_x, a.d_y].concat(), &[b.at_a, b.d_x, b.d_y].concat(), "texel coordinates", t);
    }
    let starts = tiles::scan_tiles(&counts);
    let (ends, entries) = tiles::fill_tiles(&params, &triangles, &starts);
    let gpu_ends = read::<u32>(&r, i, "tile_cursors");
    assert_eq!(ends[..], gpu_ends[..ends.len()]);
    let gpu_entries = read::<u32>(&r, i, "tile_entries");
    for (s, (&start, &end)) in starts.iter().zip(&ends).enumerate() {
        let (start, end) = (start as usize, end as usize);
        let (mut a, mut b) = (entries[start..end].to_vec(), gpu_entries[start..end].to_vec());
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b, "segment {s}");
    }
}

/// `composite_tiles` against its twin at 64x64, baked lighting: torus_egg (nothing opaque) and
/// sphere_balls (baked; an opaque base sphere hides the shell's far side): the same lists (read back
/// from the kernels that filled them), the same texel and depth; each pixel's fragments
/// composited front to back. The kernel takes texel coordinates from per-triangle affine
/// functions of the pixel, one step correction per pixel and the sampler's filtering, the twin
/// barycentrics per fragment and trilinear weights in f64: close pixel by pixel, unbiased.
#[test]
fn compositing_matches_its_twin() {
    use voltex::bake::Baker;
    use voltex::gpu::readback::read_texture;
    for (name, opaque) in [("torus_egg.ron", false), ("sphere_balls.ron", true)] {
        let text =
            std::fs::read_to_string(example(name)).unwrap().replace("lighting: PerPixel", "lighting: Baked");
        let scene = scene::parse(&text, &example(name)).unwrap();
        let opts = RenderOptions { planes: Some(96), ..options(Compositor::Tiles) };
        let ctx = gpu!(ADAPTER);
        let mut r = Renderer::new(&ctx, Blueprint::new(&scene, &opts).unwrap()).unwrap();
        r.render(&ctx).unwrap();
        let i = r.blueprint.find_instance("ViewSlicesTiles").expect("a Tiles instance");
        let gpu: Vec<[f32; 4]> =
            bytemuck::pod_collect_to_vec(&r.read_instance_buffer(&ctx, i, "tile_layer").unwrap());
        let bake = &r.blueprint.bakes[0];
        let baked =
            Baker::new(&voltex::gpu::sources::Sources::project().unwrap()).bake(&ctx, &bake.request).unwrap();
        let texel = read_texture(&ctx, &baked.volume, 4).unwrap();
        // The base surfaces' depth, where a base surface is drawn (the only opaque pass here).
        let depth: Option<Vec<f32>> =
            r.read_texture(&ctx, "base_depth").ok().map(|d| d.pixels.iter().map(|p| p[0]).collect());
        assert_eq!(
            depth.as_ref().is_some_and(|d| d.iter().any(|z| *z < 1.0)),
            opaque,
            "{name}: opaque depth"
        );
        let read = |name: &str| r.read_instance_buffer(&ctx, i, name).unwrap();
        let vs = r.blueprint.objects[0].method::<ViewSlicesPlan>().unwrap();
        let cpu = tiles::composite_tiles_frame(
            &r.blueprint.frame,
            vs,
            bake.opacity_length,
            read,
            (bake.request.resolution, &texel),
            depth.as_deref(),
        );
        drop(ctx);
        assert_eq!(cpu.len(), gpu.len());
        let d: Vec<f64> = (gpu.iter().zip(&cpu))
            .map(|(g, c)| (0..4).map(|k| (g[k] as f64 - c[k] as f64).abs()).fold(0.0, f64::max))
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let max = d.iter().copied().fold(0.0, f64::max);
        let covered = cpu.iter().filter(|c| c[3] > 0.05).count();
        // The mean signed difference per channel: sampling rounding is unbiased, a wrong step
        // correction, order or depth test is not.
        let bias: Vec<f64> = (0..4)
            .map(|k| {
                gpu.iter().zip(&cpu).map(|(g, c)| g[k] as f64 - c[k] as f64).sum::<f64>() / d.len() as f64
            })
            .collect();
        eprintln!(
            "{name}: composite_tiles against its twin: mean {mean:.2e}, max {max:.2e}, bias {:?}, {covered} pixels covered",
            bias.iter().map(|b| format!("{b:.1e}")).collect::<Vec<_>>()
        );
        assert!(covered > d.len() / 10, "{name}: {covered} pixels covered");
        // llvmpipe filters with 8-bit weights: on the opaque torus's sharp texel edges a sample
        // moves by up to 1/256 of a voxel step, so single pixels differ by up to about 0.01.
        assert!(mean < 1e-3 && max < 0.02, "{name}: mean {mean:.2e}, max {max:.2e}");
        assert!(bias.iter().all(|b| b.abs() < 1e-4), "{name}: biased by {bias:?}");
    }
}
