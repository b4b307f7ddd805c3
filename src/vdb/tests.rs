//! Reading the example files (written by OpenVDB 12 through tools/gen_volumes.py) and the bad
//! inputs of tests/vdb/.

use std::path::PathBuf;

use glam::{DVec3, IVec3};

use super::*;

fn file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(name)
}

fn request(density: &str, color: Option<&str>) -> Request {
    Request { density: density.into(), color: color.map(Into::into), band: 1.0 }
}

fn load_example(name: &str, density: &str, color: Option<&str>) -> SparseVolume {
    load(&file(&format!("scenes/volumes/{name}")), &request(density, color)).unwrap()
}

#[test]
fn box_tiles_and_ramp_leaves_read_as_written() {
    // Eight 8^3 tiles of density 1; voxel (0, 0, 0) at world -15/32, voxels 1/16 apart.
    let v = load_example("box.vdb", "density", None);
    assert_eq!((v.lo, v.hi), (IVec3::ZERO, IVec3::splat(15)));
    let world = v.index_to_world.transform_point3(DVec3::ZERO);
    assert!((world - DVec3::splat(-15.0 / 32.0)).length() < 1e-12, "{world}");
    for p in [DVec3::ZERO, DVec3::splat(7.5), DVec3::new(15.0, 3.2, 9.9)] {
        assert!((v.density_at(p) - 1.0).abs() < 1e-6, "{p}");
    }
    // Half way out of the last voxel the interpolant is half; a voxel beyond it, nothing.
    assert!((v.density_at(DVec3::new(15.5, 4.0, 4.0)) - 0.5).abs() < 1e-6);
    assert_eq!(v.density_at(DVec3::new(16.0, 4.0, 4.0)), 0.0);
    let ramp = load_example("box.vdb", "ramp", None);
    for i in 0..16 {
        let want = 0.25 + 1.5 * (i as f64 + 0.5) / 16.0;
        assert!((ramp.density_at(DVec3::new(i as f64, 3.0, 12.0)) - want).abs() < 1e-6, "voxel {i}");
    }
}

#[test]
fn colour_half_level_set_and_affine_grids() {
    let smoke = load_example("smoke.vdb", "density", Some("Cd"));
    let c = smoke.color_at(DVec3::splat(15.5));
    assert!(c[0] > 0.5 && c[0] < 0.7 && smoke.density_at(DVec3::splat(15.5)) > 0.5, "{c:?}");
    // The level set sphere (radius 0.8, voxel 0.08): density 1 at the centre, 0 beyond the
    // surface, 1/2 on it (band: one voxel).
    let ls = load_example("sphere_level_set.vdb", "surface", None);
    assert!(ls.density_at(DVec3::ZERO) > 1.0 - 1e-9);
    assert_eq!(ls.density_at(DVec3::new(12.0, 0.0, 0.0)), 0.0);
    assert!((ls.density_at(DVec3::new(10.0, 0.0, 0.0)) - 0.5).abs() < 0.1);
    // Interior tiles (inactive, -background) are inside: every voxel within 8 of the centre.
    assert!((0..8).all(|i| ls.density_at(DVec3::new(i as f64, 0.3, -0.2)) > 1.0 - 1e-9));
    // A rotated half-precision grid (an AffineMap): its matrix as written.
    let half = load_example("half_rotated.vdb", "density", None);
    let m = half.index_to_world;
    assert!((m.x_axis.y - (0.5f64).sin() / 12.0).abs() < 1e-9, "{m:?}");
    assert!(half.max_density > 0.5);
}

#[test]
fn grids_are_chosen_by_name() {
    let all = grids(&file("scenes/volumes/several_grids.vdb")).unwrap();
    let names: Vec<&str> = all.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["density", "temperature", "Cd"]);
    let t = load_example("several_grids.vdb", "temperature", Some("Cd"));
    let d = load_example("several_grids.vdb", "density", None);
    assert!(t.max_density < d.max_density);
    let e = load(&file("scenes/volumes/several_grids.vdb"), &request("heat", None)).unwrap_err().to_string();
    assert!(e.contains("no grid named `heat`") && e.contains("`temperature` (float, fog volume)"), "{e}");
}

#[test]
fn two_far_blobs_stay_sparse() {
    // 16^3 blobs 1000 voxels apart: a dense grid over their bounds would be 1016^3 floats (4 GB).
    let v = load_example("far_apart.vdb", "density", None);
    assert!(v.hi.min_element() >= 1000);
    let dense = 1016u64.pow(3) * 4;
    let bytes = v.gpu_bytes(2048);
    assert!(bytes < 2 << 20, "{bytes} bytes for {} bricks", v.bricks());
    assert!(bytes * 1000 < dense);
}

#[test]
fn bad_files_name_file_grid_and_what_is_wrong() {
    let cases = [
        ("int", "density", "found a int32 grid"),
        ("bool", "density", "found a bool grid"),
        ("points", "points", "found a ptdataidx32 grid"),
        ("nan", "density", "voxel (3, 3, 3) holds NaN"),
        ("empty", "density", "the grid is empty"),
        ("absurd_extents", "density", "top grid would need"),
        ("frustum", "density", "NonlinearFrustumMap"),
    ];
    for (name, grid, words) in cases {
        let path = file(&format!("tests/vdb/{name}.vdb"));
        let e = load(&path, &request(grid, None)).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(e.contains(&format!("grid `{grid}`")) && e.contains(words), "{name}: {e}");
    }
}
