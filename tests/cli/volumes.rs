//! OpenVDB files through the `voltex` binary: a `.vdb` opens directly and imports as the same
//! scene; bad files and bad grids fail with the file and grid named, status 1 and no output;
//! plan checks a volume's GPU memory against the budget before anything is allocated.

use crate::common;

use common::{ok, root, s, scratch_dir, stderr, voltex};

fn example(name: &str) -> std::path::PathBuf {
    root().join("scenes/volumes").join(name)
}

/// `voltex render FILE.vdb` opens the file as the scene `voltex import` writes: both render the
/// same image; the written scene says which grids the file holds and which it draws.
#[test]
fn a_vdb_opens_directly_and_imports_as_the_same_scene() {
    let dir = scratch_dir("voltex-vdb-import");
    let vdb = dir.join("smoke.vdb");
    std::fs::copy(example("smoke.vdb"), &vdb).unwrap();
    ok(voltex(&["import", s(&vdb)]));
    let scene = dir.join("smoke.ron");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(
        text.contains(
            "Written by `voltex import` around smoke.vdb: grids density (float, fog volume), Cd (vec3s)"
        ),
        "{text}"
    );
    assert!(text.contains("file: \"smoke.vdb\"") && text.contains("color: \"Cd\""), "{text}");
    let mut images = Vec::new();
    for (input, out) in [(&vdb, "direct.exr"), (&scene, "imported.exr")] {
        let out = dir.join(out);
        ok(voltex(&["render", s(input), "--size", "24x24", "-o", s(&out)]));
        images.push(voltex::io::exr::read(&out).unwrap().0);
    }
    assert_eq!(images[0].pixels, images[1].pixels);
    let background = images[0].pixels[0];
    assert!(images[0].pixels.iter().any(|p| (p[0] - background[0]).abs() > 0.05), "the volume is drawn");
    assert!(ok(voltex(&["plan", s(&vdb)])).contains("of volume \"smoke\""));
    // A level set imports with its band; a file whose densities are faint is scaled, and says so.
    let ls = dir.join("ls.ron");
    ok(voltex(&["import", s(&example("sphere_level_set.vdb")), "-o", s(&ls)]));
    let text = std::fs::read_to_string(&ls).unwrap();
    assert!(text.contains("grid: \"surface\"") && text.contains("band: 1.0"), "{text}");
    let far = dir.join("far.ron");
    ok(voltex(&["import", s(&example("far_apart.vdb")), "-o", s(&far)]));
    assert!(std::fs::read_to_string(&far).unwrap().contains("would give an optical depth of"));
}

/// The scene `absorbing_box.ron` reading `file` and `grid`.
fn box_scene(dir: &std::path::Path, name: &str, file: &std::path::Path, grid: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(example("absorbing_box.ron")).unwrap();
    let text = text
        .replace("file: \"box.vdb\"", &format!("file: {:?}", s(file)))
        .replace("grid: \"density\"", &format!("grid: {grid:?}"));
    let scene = dir.join(format!("{name}.ron"));
    std::fs::write(&scene, text).unwrap();
    scene
}

/// `bytes` with the 8-byte floats from `at` replaced by `values`.
fn with_doubles(mut bytes: Vec<u8>, at: usize, values: &[f64]) -> Vec<u8> {
    for (i, v) in values.iter().enumerate() {
        bytes[at + 8 * i..at + 8 * i + 8].copy_from_slice(&v.to_le_bytes());
    }
    bytes
}

fn find(bytes: &[u8], what: &[u8]) -> usize {
    bytes.windows(what.len()).position(|w| w == what).unwrap() + what.len()
}

#[test]
fn bad_vdb_files_name_file_and_grid_exit_1_and_write_nothing() {
    let dir = scratch_dir("voltex-vdb-bad");
    let boxed = std::fs::read(example("box.vdb")).unwrap();
    let rotated = std::fs::read(example("half_rotated.vdb")).unwrap();
    // The first grid's UniformScaleTranslateMap: translation, then scale (three doubles each).
    let map = find(&boxed, b"UniformScaleTranslateMap");
    let affine = find(&rotated, b"AffineMap");
    let bad = |f: &str| root().join("tests/vdb").join(f);
    // (case, the file's bytes to write (or an existing file), the file, the grid, the error).
    type Case<'a> = (&'a str, Option<Vec<u8>>, std::path::PathBuf, &'a str, &'a str);
    let cases: Vec<Case> = vec![
        (
            "truncated",
            Some(boxed[..boxed.len() / 2].to_vec()),
            dir.join("truncated.vdb"),
            "density",
            "truncated?",
        ),
        (
            "junk",
            Some(b"not an OpenVDB file at all".to_vec()),
            dir.join("junk.vdb"),
            "density",
            "not an OpenVDB file",
        ),
        (
            "zero scale",
            Some(with_doubles(boxed.clone(), map + 24, &[0.0, 0.0, 0.0])),
            dir.join("zero.vdb"),
            "density",
            "singular",
        ),
        (
            "singular",
            Some(with_doubles(rotated.clone(), affine, &[0.0; 4])),
            dir.join("singular.vdb"),
            "density",
            "singular",
        ),
        (
            "unknown grid",
            None,
            example("box.vdb"),
            "heat",
            "no grid named `heat`: its grids are `density` (float, fog volume), `ramp` (float, fog volume)",
        ),
        ("int", None, bad("int.vdb"), "density", "expected a float grid"),
        ("bool", None, bad("bool.vdb"), "density", "found a bool grid"),
        ("points", None, bad("points.vdb"), "points", "found a ptdataidx32 grid"),
        ("nan", None, bad("nan.vdb"), "density", "holds NaN: expected finite values"),
        ("empty", None, bad("empty.vdb"), "density", "the grid is empty"),
        ("absurd extents", None, bad("absurd_extents.vdb"), "density", "at most 2097152"),
        ("frustum", None, bad("frustum.vdb"), "density", "NonlinearFrustumMap"),
    ];
    for (name, bytes, file, grid, expected) in cases {
        if let Some(b) = bytes {
            std::fs::write(&file, b).unwrap();
        }
        let scene = box_scene(&dir, &name.replace(' ', "_"), &file, grid);
        let out = dir.join(format!("{}.exr", name.replace(' ', "_")));
        let run = voltex(&["render", s(&scene), "--size", "16x16", "-o", s(&out)]);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(s(&file)) && err.contains(expected), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(!out.exists() && !out.with_extension("png").exists(), "{name}");
        // Positioned at the volume's `file` in the scene.
        assert!(err.contains(&format!("{}:", s(&scene))), "{name}: {err}");
        // The grid is named, except where the file fails before any grid is read.
        if !["truncated", "junk"].contains(&name) {
            assert!(err.contains(&format!("grid `{grid}`")) || name == "unknown grid", "{name}: {err}");
        }
    }
}

/// A volume's table and atlases count against the budget at plan time, before any allocation.
#[test]
fn plan_checks_a_volume_against_the_budget() {
    let scene = example("smoke.ron");
    let text = ok(voltex(&["plan", s(&scene)]));
    assert!(text.contains("bricks of 9^3") && text.contains("density atlas, colour atlas"), "{text}");
    let run = voltex(&["plan", s(&scene), "--size", "16x16", "--budget", "256K"]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(err.contains("volume \"smoke\""), "{err}");
}

/// The truth of a RayMarch volume (`--method reference`, what `regress` renders) is the same
/// look integrated exactly: its shading is kept (`level_set.ron` is Phong without shadows; a
/// truth with shadows was FLIP 0.163 from it), and a Reference written in a scene is lit by
/// its `lighting`.
#[test]
fn the_truth_of_a_volume_keeps_its_shading() {
    let plan = |scene: &str, method: &[&str]| {
        let scene = example(scene);
        let mut args = vec!["plan", s(&scene)];
        args.extend_from_slice(method);
        ok(voltex(&args))
    };
    let method = |text: &str| text.lines().find(|l| l.contains("of volume")).unwrap_or("").to_string();
    for (scene, shading) in
        [("level_set.ron", "Phong"), ("smoke.ron", "PhongShadows"), ("absorbing_box.ron", "None")]
    {
        let own = method(&plan(scene, &[]));
        let truth = method(&plan(scene, &["--method", "reference"]));
        assert!(own.contains("RayMarch(step: ") && own.contains(&format!("shading: {shading},")), "{own}");
        assert!(truth.contains("exact cells") && truth.contains(&format!("shading: {shading})")), "{truth}");
    }
}
