//! `voltex export` through the library: a constant texel on a plane (analytic density, colour
//! and tile), a hypertexture node against the bake kernel's CPU twin at full precision (no 8-bit
//! steps), and the written file read back by vdb-rs.
use crate::common::adapter::{gpu, Expectations};

/// What these tests assume of the adapter: WebGPU's defaults.
const ADAPTER: Expectations = Expectations::DEFAULTS;

use crate::common;

use std::path::Path;

use glam::{DMat4, DVec3};
use voltex::bake::{BakeSource, Baker};
use voltex::cpu::bake::bake_params;
use voltex::cpu::bake_hypertexture::bake_hypertexture_voxel;
use voltex::cpu::bake_transfer::bake_transfer;
use voltex::cpu::hypertexture::Model;
use voltex::gpu::sources::Sources;
use voltex::io::vdb::{Compression, GridData};
use voltex::render::export::{self, ExportOptions};
use voltex::scene;

fn parse(text: &str) -> scene::Scene {
    scene::parse(text, Path::new("export.ron")).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

const PLANE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 16, height: 16),
    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0)),
    texels: { "fog": (resolution: (8, 6, 4), opacity_length: 0.1,
        source: Constant(color: (0.2, 0.4, 0.6), opacity: 0.5)) },
    nodes: [(name: "floor", transform: (translate: (0.0, 0.0, 1.0)),
        surface: Plane(size: (2.0, 3.0), cells: (2, 2)), height: (length: 0.5), texel: "fog",
        method: ViewSlices(planes: 8))],
)"#;

/// A constant texel on a plane: every voxel active with the extinction `-ln(1 - 0.5) / 0.1` and
/// the colour given, the tile exactly over the plane; vdb-rs reads the file back.
#[test]
fn a_constant_texel_on_a_plane_exports_its_extinction_colour_and_tile() {
    let scene = parse(PLANE);
    let exports = export::plan(&scene, &ExportOptions::default()).unwrap();
    assert_eq!(exports.len(), 1);
    let e = &exports[0];
    assert!(e.note.is_none(), "{:?}", e.note);
    let rgba = {
        let ctx = gpu!(ADAPTER);
        export::bake(&ctx, &mut Baker::full_precision(&Sources::project().unwrap()), e).unwrap()
    };
    let grids = export::grids(e, &rgba);
    let sigma = 2f32.ln() / 0.1;
    let GridData::Float(density) = &grids[0].data else { panic!("density first") };
    let GridData::Vec3(colour) = &grids[1].data else { panic!("Cd second") };
    assert_eq!(density.active_count(), 8 * 6 * 4);
    for (i, j, k) in (0..8).flat_map(|i| (0..6).flat_map(move |j| (0..4).map(move |k| (i, j, k)))) {
        let d = density.get([i, j, k]).unwrap();
        assert!((d - sigma).abs() < 1e-4 * sigma, "{d} at {i} {j} {k}");
        let c = colour.get([i, j, k]).unwrap();
        assert!(c.iter().zip([0.2, 0.4, 0.6]).all(|(a, b)| (a - b).abs() < 1e-5), "{c:?}");
    }
    // Voxel (i, j, k) sits at the centre of its cell of the plane's tile, lifted by the node.
    let centre = |i: f64, j: f64, k: f64| {
        DVec3::new(-1.0 + (i + 0.5) * 0.25, -1.5 + (j + 0.5) * 0.5, 1.0 + (k + 0.5) * 0.125)
    };
    for (i, j, k) in [(0.0, 0.0, 0.0), (7.0, 5.0, 3.0), (3.0, 1.0, 2.0)] {
        let p = e.index_to_world.transform_point3(DVec3::new(i, j, k));
        assert!((p - centre(i, j, k)).length() < 1e-9, "{p} at {i} {j} {k}");
    }
    // The file, read by vdb-rs: the same voxels and a scale-translate map.
    let path = std::env::temp_dir().join(format!("voltex-export-{}.vdb", std::process::id()));
    voltex::io::vdb::write(&path, &grids, Compression::Zip).unwrap();
    let file = std::fs::File::open(&path).unwrap();
    let mut reader = vdb_rs::VdbReader::new(std::io::BufReader::new(file)).unwrap();
    let grid = reader.read_grid::<f32>("density").unwrap();
    assert_eq!(grid.iter().count(), 8 * 6 * 4);
    assert!(grid.iter().all(|(_, d, _)| (d - sigma).abs() < 1e-4 * sigma));
    match grid.transform {
        vdb_rs::Map::ScaleTranslateMap { translation, scale_values, .. } => {
            assert!((DVec3::from_array(translation.to_array()) - centre(0.0, 0.0, 0.0)).length() < 1e-9);
            assert!(
                (DVec3::from_array(scale_values.to_array()) - DVec3::new(0.25, 0.5, 0.125)).length() < 1e-12
            );
        }
        other => panic!("expected a scale-translate map, got {other:?}"),
    }
    std::fs::remove_file(&path).unwrap();
}

const PUFF: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 16, height: 16),
    camera: (eye: (0.0, -3.0, 1.0), target: (0.0, 0.0, 0.0)),
    hypertextures: { "puff": (object: Sphere(radius: 0.5),
        noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 0.5, 1.0), (1.0, 1.0, 0.0)]), amplitude: 0.15, frequency: 4.0)],
        color: Ramp([(0.0, (1.0, 1.0, 1.0, 0.0)), (0.3, (0.9, 0.8, 0.6, 0.0)), (0.5, (0.9, 0.6, 0.4, 0.8)),
            (1.0, (0.6, 0.3, 0.2, 1.0))]), opacity_length: 0.03) },
    nodes: [(name: "cloud", transform: (translate: (1.0, 2.0, 3.0), rotate: (0.0, 0.0, 30.0), scale: (2.0, 2.0, 2.0)),
        hypertexture: "puff")],
)"#;

/// A hypertexture node: every voxel of the f32 bake matches the kernel's CPU twin far below one
/// 8-bit step, the values are not 8-bit steps, and the box sits in the node's frame.
#[test]
fn a_hypertexture_node_exports_the_kernels_values_at_full_precision() {
    let scene = parse(PUFF);
    let opts = ExportOptions { resolution: 20, ..Default::default() };
    let exports = export::plan(&scene, &opts).unwrap();
    let e = &exports[0];
    assert_eq!((e.name.as_str(), e.resolution()), ("cloud", [20, 20, 20]));
    let export::Source::Bake { request, .. } = &e.source else { panic!("a bake") };
    let rgba = {
        let ctx = gpu!(ADAPTER);
        export::bake(&ctx, &mut Baker::full_precision(&Sources::project().unwrap()), e).unwrap()
    };
    let BakeSource::Hypertexture(ht) = &request.source else { panic!("a hypertexture bake") };
    let tables = bake_transfer(&ht.packed.functions, &ht.packed.points);
    let model = Model { params: &ht.params, noises: &ht.packed.noises, tables: &tables, grid: None };
    let params = bake_params(request.resolution, 0, request.light, request.ambient);
    let (mut worst, mut off_grid, mut matter) = (0.0f32, 0, 0);
    for (n, gpu) in rgba.iter().enumerate() {
        let v = [n as u32 % 20, n as u32 / 20 % 20, n as u32 / 400];
        let (twin, _) = bake_hypertexture_voxel(&params, &model, v, true);
        worst = worst.max((0..4).map(|c| (gpu[c] - twin[c]).abs()).fold(0.0, f32::max));
        matter += (gpu[3] > 0.0) as usize;
        off_grid += ((gpu[3] * 255.0 - (gpu[3] * 255.0).round()).abs() > 0.01) as usize;
    }
    eprintln!(
        "export bake vs twin: worst {worst}, {matter} voxels with matter, {off_grid} between 8-bit steps"
    );
    assert!(matter > 500, "{matter}");
    assert!(worst < 2e-3, "worst difference {worst}");
    assert!(off_grid * 2 > matter, "only {off_grid} of {matter} alphas are off the 8-bit grid");
    // The density is the extinction of the voxel's opacity over the hypertexture's length.
    let grids = export::grids(e, &rgba);
    let GridData::Float(density) = &grids[0].data else { panic!() };
    let centre = rgba[10 + 20 * (10 + 20 * 10)][3] as f64;
    let expected = export::density(centre, 0.03);
    assert!((density.get([10, 10, 10]).unwrap() as f64 - expected).abs() < 1e-4 * expected);
    // Voxel centres in the node's frame: the box (-0.7..0.7)^3 of 20 voxels, then the node.
    let node = DMat4::from_scale_rotation_translation(
        DVec3::splat(2.0),
        glam::DQuat::from_rotation_z(30f64.to_radians()),
        DVec3::new(1.0, 2.0, 3.0),
    );
    let (lo, hi) = ht.bounds();
    let local = lo + (hi - lo) * (DVec3::new(3.0, 0.0, 19.0) + 0.5) / 20.0;
    let p = e.index_to_world.transform_point3(DVec3::new(3.0, 0.0, 19.0));
    assert!((p - node.transform_point3(local)).length() < 1e-5, "{p}");
}

/// `--only` keeps one volume; unknown names and oversized volumes fail before any GPU work.
#[test]
fn plan_selects_and_refuses_before_baking() {
    let scene = parse(PUFF);
    let only = |names: &[&str]| ExportOptions {
        only: names.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    };
    assert_eq!(export::plan(&scene, &only(&["cloud"])).unwrap().len(), 1);
    let e = export::plan(&scene, &only(&["fog"])).unwrap_err().to_string();
    assert!(e.contains("--only \"fog\"") && e.contains("cloud"), "{e}");
    let big = ExportOptions { resolution: 1024, ..Default::default() };
    let e = export::plan(&scene, &big).unwrap_err().to_string();
    assert!(e.contains("1073741824 voxels") && e.contains("--resolution"), "{e}");
}

/// A lit, coloured volume node drawn from `file` (scenes/volumes/), and the same scene drawing
/// instead the node's export (`density_scale` and `albedo` already applied, placed in world).
fn lit_volume(file: &str, volume: &str, node: &str, method: &str) -> String {
    format!(
        r#"#![enable(implicit_some)]
Scene(
    output: (width: 40, height: 40),
    camera: (eye: (2.5, -4.0, 4.5), target: (0.3, 0.5, 1.0), fov_y: 40.0),
    background: (0.1, 0.1, 0.15),
    ambient: 0.3,
    lights: [Directional(direction: (-0.4, 0.5, -0.8), intensity: 1.0)],
    volumes: {{ "v": (file: {:?}, {volume}) }},
    nodes: [(name: "cloud", volume: "v", {node} method: {method})],
)"#,
        voltex::project_root().join("scenes/volumes").join(file)
    )
}

/// Re-importing an exported volume node draws the image of the original: the smoke (with its
/// Cd) and a rotated half grid, each moved by a rotating node, with RayMarch and shadows and
/// with the exact Reference lit per pixel.
#[test]
fn an_exported_volume_node_renders_like_the_original() {
    let dir = common::scratch_dir("export-volume-reimport");
    let node = "transform: (translate: (0.2, 0.5, 1.0), rotate: (10.0, 0.0, 35.0), scale: (1.2, 1.2, 1.2)),";
    for (file, volume) in [
        ("smoke.vdb", r#"color: "Cd", density_scale: 6.0, albedo: (0.9, 0.7, 0.5)"#),
        ("half_rotated.vdb", "density_scale: 5.0, albedo: (0.9, 0.8, 0.6)"),
    ] {
        for method in ["RayMarch(shading: PhongShadows)", "Reference(lighting: PerPixel)"] {
            let original = parse(&lit_volume(file, volume, node, method));
            let exports = export::plan(&original, &ExportOptions::default()).unwrap();
            let path = dir.join(format!("{file}.export.vdb"));
            voltex::io::vdb::write(&path, &export::grids(&exports[0], &[]), Compression::Zip).unwrap();
            let text = lit_volume(file, r#"color: "Cd""#, "", method);
            let again = parse(&text.replace(
                &format!("{:?}", voltex::project_root().join("scenes/volumes").join(file)),
                &format!("{path:?}"),
            ));
            let (a, b) = (render(&original), render(&again));
            let diff = a.iter().zip(&b).map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).abs()).fold(0.0, f32::max));
            let worst = diff.fold(0.0, f32::max);
            let lit = a.iter().filter(|p| (p[0] - 0.1).abs() > 0.05).count();
            println!("{file} {method}: {lit} pixels show the volume, largest difference {worst:.2e}");
            assert!(lit > 100, "{file}: the volume covers the image");
            assert!(worst < 2e-3, "{file} {method}: the re-import differs by {worst}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

fn render(scene: &scene::Scene) -> Vec<[f32; 4]> {
    let bp = voltex::render::Blueprint::new(scene, &common::sized(40, 40)).unwrap();
    let ctx = gpu!(ADAPTER);
    let mut r = voltex::render::Renderer::new(&ctx, bp).unwrap();
    r.render(&ctx).unwrap().image.pixels
}
