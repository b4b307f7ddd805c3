//! Volumes on real files against the exact f64 transmittance: `varied.vdb` (written by the
//! OpenVDB library; densities from 1e-5 to 2000, thin and dense parts) against the integral of
//! the formula it was made from, and every `.vdb` under `scenes/` (each float grid, purely
//! absorbing) against the integral of its voxels as read. What the GPU reads (bricks, their
//! aprons, the two-level table, shared uniform bricks, empty-space skipping, f32) is checked;
//! the truth shares none of it.

use crate::volume::{exact_transmittance, max_error, render, rmse};

use glam::{DMat4, DVec3, IVec3};
use voltex::scene;

/// `tools/gen_volumes.py`'s `varied_density` at world point p of the unit cube (keep alike).
fn varied_density(p: DVec3) -> f64 {
    let (x, y, z) = (p.x, p.y, p.z);
    let rad = ((x - 0.5).powi(2) + (y - 0.5).powi(2)).sqrt();
    let ring = 40.0
        * (0.5 - (((rad - 0.3).powi(2) + (z - 0.5).powi(2)).sqrt() - 0.09) * 128.0 / 3.0).clamp(0.0, 1.0);
    let e =
        (((x - 0.5) / 0.17).powi(2) + ((y - 0.5) / 0.17).powi(2) + ((z - 0.5) / 0.28).powi(2)).sqrt() - 1.0;
    let wave = 0.5 + 0.5 * (9.0 * x + 2.0).sin() * (7.0 * y).sin() * (5.0 * z).cos();
    let egg = (-4.0 * e).clamp(0.0, 1.0) * 10f64.powf(-2.0 + 3.0 * wave);
    let h = ((x - 0.5).powi(2) + (y - 0.5).powi(2) + (z - 0.7).powi(2)) / 0.03f64.powi(2);
    let core = 2000.0 * (1.0 - h).clamp(0.0, 1.0);
    let slab = z < 0.25 && x > 0.1 && x < 0.9 && y > 0.1 && y < 0.9;
    let haze = if slab { 0.02 + 0.2 * (0.5 + 0.5 * (23.0 * x).sin() * (19.0 * y).cos()) } else { 0.0 };
    ring.max(egg).max(core) + haze
}

const N: i32 = 128;

/// Voxel i of varied.vdb: the formula at the cell centre (i + 1/2) / 128, as the f32 the file holds.
fn varied_voxel(i: IVec3) -> f64 {
    if i.cmplt(IVec3::ZERO).any() || i.cmpge(IVec3::splat(N)).any() {
        return 0.0;
    }
    varied_density((i.as_dvec3() + 0.5) / N as f64) as f32 as f64
}

fn load(path: &std::path::Path, text: &str) -> scene::Scene {
    scene::parse(text, path).unwrap()
}

/// The Reference of varied.vdb at 256x256 against the exact integral of its formula: RMSE <=
/// 1e-3 (the goal); RayMarch at its default step (one voxel) within its stated error. The file
/// holds the formula's values (read by voltex: every voxel equal to the f32 of the formula).
#[test]
fn varied_densities_are_exact() {
    let path = voltex::project_root().join("scenes/volumes/varied.ron");
    let request = voltex::vdb::Request { density: "density".into(), color: None, band: 1.0 };
    let voxels = voltex::vdb::voxels(&path.with_file_name("varied.vdb"), &request).unwrap();
    let to_world = DMat4::from_translation(DVec3::splat(0.5 / N as f64))
        * DMat4::from_scale(DVec3::splat(1.0 / N as f64));
    assert!(voxels.index_to_world.abs_diff_eq(to_world, 1e-12), "{:?}", voxels.index_to_world);
    let mut differ = 0;
    for z in -1..=N {
        for y in -1..=N {
            for x in -1..=N {
                let i = IVec3::new(x, y, z);
                differ += (voxels.get(i) as f64 != varied_voxel(i)) as usize;
            }
        }
    }
    assert!(differ < 10, "{differ} voxels differ from the formula (f32 rounding of sin/pow at most)");

    let text = std::fs::read_to_string(&path).unwrap();
    let size = 256;
    let scene = load(&path, &text);
    let truth =
        exact_transmittance(&scene, size, to_world, (IVec3::ZERO, IVec3::splat(N - 1)), &varied_voxel);
    let partly = truth.iter().filter(|t| **t > 0.02 && **t < 0.98).count();
    assert!(partly > 5000, "{partly} pixels see the thin parts");
    for (method, max_rmse, max_largest) in [("Reference()", 1e-3, 0.02), ("RayMarch()", 4e-3, 0.12)] {
        let image =
            render(&load(&path, &text.replace("method: RayMarch()", &format!("method: {method}"))), size);
        let (e, m) = (rmse(&image, &truth), max_error(&image, &truth));
        println!("varied.vdb {size}x{size} {method}: RMSE {e:.2e}, largest {m:.2e}");
        assert!(e <= max_rmse && m <= max_largest, "{method}: RMSE {e:.2e}, largest {m:.2e}");
    }
}

/// Every float grid of every `.vdb` under `scenes/`, purely absorbing before a white
/// background, framed from above one corner, its density scaled to an optical depth of about
/// 1.5 across a cube of its voxels: the Reference within RMSE 1e-3 of the exact integral of the voxels as
/// read, RayMarch (one voxel a step) within 1e-2.
#[test]
fn every_scene_vdb_is_exact() {
    let mut files = Vec::new();
    find_vdb(&voltex::project_root().join("scenes"), &mut files);
    files.sort();
    let mut checked = 0;
    for file in &files {
        for grid in voltex::vdb::grids(file).unwrap().iter().filter(|g| g.value == "float") {
            let band = if grid.is_level_set() { 2.0 } else { 1.0 };
            let request = voltex::vdb::Request { density: grid.name.clone(), color: None, band };
            let voxels = voltex::vdb::voxels(file, &request).unwrap();
            let (lo, hi) = voxels.bounds();
            // Far-apart voxels (a sparse grid 1000 voxels across): fewer rays, each long.
            let size = if sparse(lo, hi) { 48 } else { 96 };
            let text = absorbing_scene(file, grid, &voxels, lo, hi);
            let at = |i: IVec3| voxels.get(i) as f64;
            let scene = load(file, &text);
            let truth = exact_transmittance(&scene, size, voxels.index_to_world, (lo, hi), &at);
            assert!(truth.iter().any(|t| *t < 0.9), "{}: the grid absorbs", file.display());
            for (method, max_rmse) in [("Reference()", 1e-3), ("RayMarch()", 1e-2)] {
                let image = render(&load(file, &text.replace("Reference()", method)), size);
                let e = rmse(&image, &truth);
                println!(
                    "{} `{}` {size}x{size} {method}: RMSE {e:.2e}, largest {:.2e}",
                    file.file_name().unwrap().to_string_lossy(),
                    grid.name,
                    max_error(&image, &truth)
                );
                assert!(e <= max_rmse, "{} `{}` {method}: RMSE {e:.2e}", file.display(), grid.name);
            }
            checked += 1;
        }
    }
    assert!(checked >= 10, "{checked} grids");
}

/// Whether the voxels lie far apart (a box over 512 voxels across).
fn sparse(lo: IVec3, hi: IVec3) -> bool {
    (hi - lo).max_element() > 512
}

fn find_vdb(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            find_vdb(&p, out);
        } else if p.extension().is_some_and(|x| x == "vdb") {
            out.push(p);
        }
    }
}

/// A scene drawing `grid` of `file` with the Reference: absorbing, white background, the
/// camera above one corner of its world box.
fn absorbing_scene(
    file: &std::path::Path,
    grid: &voltex::vdb::GridInfo,
    voxels: &voltex::vdb::GridVoxels,
    lo: IVec3,
    hi: IVec3,
) -> String {
    let m = voxels.index_to_world;
    let corners: Vec<DVec3> = (0..8)
        .map(|c| {
            let pick = |a: usize, bit: i32| if c >> bit & 1 == 0 { lo[a] - 1 } else { hi[a] + 1 };
            m.transform_point3(DVec3::new(pick(0, 0) as f64, pick(1, 1) as f64, pick(2, 2) as f64))
        })
        .collect();
    let centre = corners.iter().sum::<DVec3>() / 8.0;
    let radius = corners.iter().map(|c| (*c - centre).length()).fold(0.0, f64::max);
    let (eye, target) = if sparse(lo, hi) {
        // Blobs far apart: from beyond the highest corner along the diagonal, through the blob
        // there and the empty space behind it.
        let (l, h) = (m.transform_point3((lo - 1).as_dvec3()), m.transform_point3((hi + 1).as_dvec3()));
        (h + (h - l) * 0.05, l)
    } else {
        (centre + DVec3::new(0.55, -0.7, 0.45).normalize() * 3.0 * radius, centre)
    };
    // Mean density of the voxels that hold any, over the width of a cube of as many voxels.
    let (sum, count) =
        voxels.values().filter(|v| *v > 0.0).fold((0.0, 0usize), |(s, n), v| (s + v as f64, n + 1));
    let voxel =
        [m.x_axis, m.y_axis, m.z_axis].iter().map(|c| c.truncate().length()).fold(f64::INFINITY, f64::min);
    let scale = 1.5 / (sum / count as f64 * (count as f64).cbrt() * voxel);
    let band = if grid.is_level_set() { ", band: 2.0" } else { "" };
    let v = |p: DVec3| format!("({:.6}, {:.6}, {:.6})", p.x, p.y, p.z);
    format!(
        "Scene(\n  output: (width: 64, height: 64),\n  camera: (eye: {}, target: {}, up: (0.0, 0.0, 1.0), fov_y: 40.0),\n  \
         background: (1.0, 1.0, 1.0),\n  volumes: {{ \"v\": (file: \"{}\", grid: \"{}\", density_scale: {scale:.6e}, albedo: (0.0, 0.0, 0.0){band}) }},\n  \
         nodes: [(name: \"v\", volume: \"v\", method: Reference())],\n)\n",
        v(eye),
        v(target),
        file.file_name().unwrap().to_string_lossy(),
        grid.name
    )
}
