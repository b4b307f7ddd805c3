//! `voltex export` through the binary: a scene's texels written as VDB files, and bad input (an
//! unwritable output folder, a name that is no file name, a texel too large, an unknown
//! `--only`, a bad option) failing with status 1, a message naming what is wrong, and nothing
//! written.

use crate::common;

use common::{entries, stderr, voltex};

use std::path::PathBuf;

fn temp(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-export-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn flat_box() -> String {
    std::fs::read_to_string(common::root().join("scenes/view_slices/flat_box.ron")).unwrap()
}

#[track_caller]
fn fails(out: &std::process::Output, words: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "stderr:\n{err}");
    assert!(err.starts_with("error: ") && !err.contains("panicked"), "stderr:\n{err}");
    for w in words {
        assert!(err.contains(w), "expected {w:?} in:\n{err}");
    }
}

#[test]
fn export_writes_one_vdb_per_texel_into_a_new_folder() {
    let dir = temp("ok");
    let scene = common::root().join("scenes/view_slices/flat_box.ron");
    let out = dir.join("vdb");
    let run = voltex(&["export", scene.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let progress = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(progress.contains("[1/1] texel \"fog\" 8x8x8: "), "{progress}");
    let text = common::ok(run);
    assert!(text.contains("fog.vdb") && text.contains("8x8x8, 512 active voxels"), "{text}");
    assert_eq!(entries(&out), ["fog.vdb"]);
    let file = std::fs::File::open(out.join("fog.vdb")).unwrap();
    let mut r = vdb_rs::VdbReader::new(std::io::BufReader::new(file)).unwrap();
    let mut names = r.available_grids();
    names.sort();
    assert_eq!(names, ["Cd", "density"]);
    assert_eq!(r.read_grid::<f32>("density").unwrap().iter().count(), 512);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_exports_fail_cleanly_and_write_nothing() {
    let dir = temp("bad");
    let out = dir.join("out");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let scene = write("box.ron", &flat_box());
    let o = out.to_str().unwrap();
    // An output "folder" below a regular file.
    let file = write("file.txt", "not a folder");
    let below = format!("{file}/sub");
    fails(&voltex(&["export", &scene, "--out", &below]), &[&below, "cannot make the output folder"]);
    fails(&voltex(&["export", &scene, "--out", &file]), &[&file, "not a folder"]);
    // A texel whose name cannot be a file name, and one too large to read back.
    let slash = write("slash.ron", &flat_box().replace("\"fog\"", "\"a/b\""));
    fails(&voltex(&["export", &slash, "--out", o]), &["slash.ron", "texel \"a/b\"", "is not a file name"]);
    let big = write("big.ron", &flat_box().replace("resolution: (8, 8, 8)", "resolution: (1024, 1024, 128)"));
    fails(&voltex(&["export", &big, "--out", o]), &["big.ron", "134217728 voxels", "lower its resolution"]);
    // Unknown names and bad options.
    fails(&voltex(&["export", &scene, "--out", o, "--only", "moss"]), &["--only \"moss\"", "fog"]);
    fails(&voltex(&["export", &scene, "--out", o, "--resolution", "0"]), &["--resolution 0"]);
    fails(&voltex(&["export", &scene, "--out", o, "--time", "NaN"]), &["--time NaN"]);
    assert!(!out.exists(), "the output folder was made: {:?}", entries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene drawing `file` (scenes/volumes/) as a volume object, moved by `transform`.
fn volume_scene(file: &str, color: &str, transform: &str) -> String {
    let vdb = common::root().join("scenes/volumes").join(file);
    format!(
        r#"#![enable(implicit_some)]
Scene(
    output: (width: 16, height: 16),
    camera: (eye: (3.0, -6.0, 4.0), target: (1.0, 2.0, 3.0)),
    volumes: {{ "fog": (file: {vdb:?}, {color} density_scale: 3.0, albedo: (0.5, 0.8, 1.0)) }},
    nodes: [(name: "cloud", volume: "fog", transform: {transform}, method: RayMarch())],
)"#
    )
}

/// `(i, j, k) -> value` of every active voxel of grid `name` read by vdb-rs, and its transform.
fn read_grid<T: bytemuck::Pod + Copy>(
    path: &std::path::Path,
    name: &str,
) -> (std::collections::HashMap<[i32; 3], T>, vdb_rs::Map) {
    let file = std::fs::File::open(path).unwrap();
    let mut r = vdb_rs::VdbReader::new(std::io::BufReader::new(file)).unwrap();
    let g = r.read_grid::<T>(name).unwrap_or_else(|e| panic!("{}: {name}: {e}", path.display()));
    let mut values = std::collections::HashMap::new();
    for (p, v, level) in g.iter() {
        assert!(matches!(level, vdb_rs::VdbLevel::Voxel), "{}: {name} has tiles", path.display());
        values.insert([p.x as i32, p.y as i32, p.z as i32], v);
    }
    (values, g.transform)
}

/// The map's scale and translation (vdb-rs has its own glam).
fn scale_translate(m: &vdb_rs::Map) -> (glam::DVec3, glam::DVec3) {
    let (s, t) = match m {
        vdb_rs::Map::ScaleTranslateMap { translation, scale_values, .. } => {
            (*scale_values, translation.to_array())
        }
        vdb_rs::Map::UniformScaleMap { scale_values, .. } => (*scale_values, [0.0; 3]),
    };
    (glam::DVec3::from_array(s.to_array()), glam::DVec3::from_array(t))
}

/// A volume node (the smoke's density and Cd, scaled and moved by its node) written voxel for
/// voxel: vdb-rs reads back the source's densities times `density_scale`, `albedo` times its
/// colours, and the node's transform composed with the file's.
#[test]
fn export_writes_volume_nodes_with_scaled_density_colour_and_world_transform() {
    let dir = temp("volume");
    let scene = dir.join("smoke.ron");
    let text =
        volume_scene("smoke.vdb", "color: \"Cd\",", "(translate: (1.0, 2.0, 3.0), scale: (2.0, 2.0, 2.0))");
    std::fs::write(&scene, text).unwrap();
    let out = dir.join("vdb");
    let text = common::ok(voltex(&[
        "export",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
        "--view",
    ]));
    assert!(text.contains("volume \"fog\" of node \"cloud\"") && text.contains("density_scale 3"), "{text}");
    assert_eq!(entries(&out), ["cloud.vdb", "view.json"]);
    // The view other renderers are given: the scene's size and camera, the files written.
    let view: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("view.json")).unwrap()).unwrap();
    assert_eq!((view["width"].as_u64(), view["height"].as_u64()), (Some(16), Some(16)));
    assert_eq!(view["camera"]["eye"], serde_json::json!([3.0, -6.0, 4.0]));
    assert_eq!(view["camera"]["target"], serde_json::json!([1.0, 2.0, 3.0]));
    assert_eq!(view["files"][0]["file"], "cloud.vdb");
    let source = common::root().join("scenes/volumes/smoke.vdb");
    let (src, src_map) = read_grid::<f32>(&source, "density");
    let (got, got_map) = read_grid::<f32>(&out.join("cloud.vdb"), "density");
    let (_, cd_map) = read_grid::<[f32; 3]>(&out.join("cloud.vdb"), "Cd");
    let nonzero: Vec<_> = src.iter().filter(|(_, v)| **v != 0.0).collect();
    assert!(nonzero.len() > 1000, "{}", nonzero.len());
    assert_eq!(got.len(), nonzero.len(), "one active voxel per voxel with density");
    // Colours through voltex's reader: at every voxel with density, and interpolated at the
    // middle of its cell (Cd reaches every voxel the object's interpolant read).
    let request = voltex::vdb::Request { density: "density".into(), color: Some("Cd".into()), band: 1.0 };
    let before = voltex::vdb::load(&source, &request).unwrap();
    let after = voltex::vdb::load(&out.join("cloud.vdb"), &request).unwrap();
    for (ijk, v) in nonzero {
        assert_eq!(got.get(ijk), Some(&(v * 3.0)), "density at {ijk:?}");
        for p in [glam::IVec3::from_array(*ijk).as_dvec3(), glam::IVec3::from_array(*ijk).as_dvec3() + 0.5] {
            let (c, w) = (after.color_at(p), before.color_at(p));
            let want = [w[0] * 0.5, w[1] * 0.8, w[2]];
            assert!(c.iter().zip(want).all(|(a, b)| (a - b).abs() <= 1e-6), "Cd at {p}: {c:?} != {want:?}");
            assert!((after.density_at(p) - 3.0 * before.density_at(p)).abs() <= 1e-5 * after.density_at(p));
        }
    }
    let ((s0, t0), (s1, t1)) = (scale_translate(&src_map), scale_translate(&got_map));
    assert!((s1 - 2.0 * s0).abs().max_element() < 1e-12, "{s0} {s1}");
    assert!((t1 - (2.0 * t0 + glam::DVec3::new(1.0, 2.0, 3.0))).abs().max_element() < 1e-12, "{t0} {t1}");
    assert_eq!(scale_translate(&cd_map), (s1, t1), "Cd shares the density's voxels");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--world` through the binary: one file per textured object named after its node, on a lattice
/// of the voxel given, a numbered sequence with `--frames`, the base surface as OBJ with
/// `--with-mesh`.
#[test]
fn world_export_writes_a_sequence_of_world_voxels_and_meshes() {
    let dir = temp("world");
    let scene = common::root().join("scenes/view_slices/flat_box.ron");
    let out = dir.join("vdb");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let run =
        voltex(&["export", s, "--out", o, "--world", "--voxel", "0.1", "--frames", "1..2", "--with-mesh"]);
    // The estimate before any work: the voxels of the leaves the shell meets, and their bytes.
    let err = stderr(&run);
    assert!(err.contains("voxels in the leaves its shell meets") && err.contains("MiB read back"), "{err}");
    let text = common::ok(run);
    assert!(text.contains("object \"box\"") && text.contains("voxel 0.100000"), "{text}");
    assert_eq!(entries(&out), ["box.0001.obj", "box.0001.vdb", "box.0002.obj", "box.0002.vdb"]);
    let file = std::fs::File::open(out.join("box.0002.vdb")).unwrap();
    let mut r = vdb_rs::VdbReader::new(std::io::BufReader::new(file)).unwrap();
    let grid = r.read_grid::<f32>("density").unwrap();
    let (scale, translation) = scale_translate(&grid.transform);
    assert!((scale - glam::DVec3::splat(0.1)).length() < 1e-12 && translation.length() < 1e-12);
    // The 2 x 2 x 0.5 box of fog: ln 2 / 0.5 inside, less in the voxels its sides cut.
    let sigma = 2f32.ln() / 0.5;
    let voxels: Vec<([i32; 3], f32)> =
        grid.iter().map(|(p, d, _)| ([p.x, p.y, p.z].map(|c| c.round() as i32), d)).collect();
    assert!(
        voxels.iter().all(|(_, d)| *d > 0.0 && *d <= sigma * (1.0 + 1e-5)),
        "densities within (0, {sigma}]"
    );
    let inner = voxels.iter().filter(|(p, _)| p[0].abs() < 10 && p[1].abs() < 10 && (1..4).contains(&p[2]));
    assert_eq!(inner.clone().count(), 19 * 19 * 3);
    assert!(inner.into_iter().all(|(_, d)| (d / sigma - 1.0).abs() < 1e-5));
    let obj = std::fs::read_to_string(out.join("box.0001.obj")).unwrap();
    let count = |prefix: &str| obj.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!((count("v "), count("vt "), count("f ")), (25, 96, 32), "{obj}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Bad `--world` input: a voxel too small for the budget (naming the voxels and the flag), an
/// `--only` object with no texel, a scene with nothing to export, bad numbers, an output that is
/// a file: status 1, a clear message, nothing written.
#[test]
fn bad_world_exports_fail_cleanly_and_write_nothing() {
    let dir = temp("world-bad");
    let out = dir.join("out");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let scene = write("box.ron", &flat_box());
    let o = out.to_str().unwrap();
    let world = |extra: &[&str]| {
        let mut args = vec!["export", scene.as_str(), "--out", o, "--world"];
        args.extend_from_slice(extra);
        voltex(&args)
    };
    fails(&world(&["--voxel", "0.0005"]), &["box.ron", "object \"box\"", "voxels or more", "--voxel"]);
    fails(&world(&["--voxel", "0"]), &["--voxel 0", "positive"]);
    fails(&world(&["--voxel", "NaN"]), &["--voxel NaN"]);
    fails(&world(&["--samples", "9"]), &["--samples 9", "1 to 8"]);
    let file = write("file.txt", "not a folder");
    fails(&voltex(&["export", &scene, "--out", &file, "--world"]), &[&file, "not a folder"]);
    // A base surface without a texel: nothing to export, and naming it says why.
    let bare = flat_box().replace("texel: \"fog\",", "base_color: (0.5, 0.5, 0.5),");
    let bare = write("bare.ron", &bare.replace("method: ViewSlices(planes: 256, lighting: Baked),", ""));
    fails(&voltex(&["export", &bare, "--out", o, "--world"]), &["bare.ron", "no textured object"]);
    fails(
        &voltex(&["export", &bare, "--out", o, "--world", "--only", "box"]),
        &["object \"box\" draws no texel"],
    );
    // --voxel means nothing without --world.
    let run = voltex(&["export", &scene, "--out", o, "--voxel", "0.1"]);
    assert!(!run.status.success() && stderr(&run).contains("--world"), "{}", stderr(&run));
    assert!(!out.exists(), "the output folder was made: {:?}", entries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}
