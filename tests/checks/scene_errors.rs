//! Scene files: every user error is reported at its `file:line:col` with what was expected, and the
//! example scenes load and flatten.

use std::path::{Path, PathBuf};
use voltex::scene;

/// A valid scene; tests replace single lines (1-based) to break it.
const BASE: &str = r#"#![enable(implicit_some)]
Scene(
    output: (width: 64, height: 64),
    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),
    texels: {
        "t": (resolution: (8, 8, 8), source: Constant(color: (1.0, 1.0, 1.0))),
    },
    nodes: [
        (
            name: "n",
            surface: Plane(size: (1.0, 1.0), cells: (2, 2)),
            height: (length: 0.1),
            texel: "t",
            method: ViewSlices(planes: 16),
        ),
    ],
)
"#;

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-scene-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn with_lines(lines: &[(usize, &str)]) -> String {
    let mut v: Vec<&str> = BASE.lines().collect();
    for &(n, l) in lines {
        v[n - 1] = l;
    }
    v.join("\n") + "\n"
}

/// Writes `text` (and extra files) to a fresh folder and returns the scene path and the outcome.
fn load(test: &str, text: &str, files: &[(&str, &str)]) -> (PathBuf, voltex::Result<scene::Scene>) {
    let dir = temp_dir(test);
    for (name, content) in files {
        std::fs::write(dir.join(name), content).unwrap();
    }
    let path = dir.join("scene.ron");
    std::fs::write(&path, text).unwrap();
    let r = scene::load(&path);
    (path, r)
}

/// Asserts the error is at `file:line:col` and mentions `word`.
#[track_caller]
fn assert_err(test: &str, lines: &[(usize, &str)], file: &str, line: usize, col: usize, word: &str) {
    assert_err_files(test, &with_lines(lines), &[], file, line, col, word)
}

#[track_caller]
fn assert_err_files(
    test: &str,
    text: &str,
    files: &[(&str, &str)],
    file: &str,
    line: usize,
    col: usize,
    word: &str,
) {
    let (path, r) = load(test, text, files);
    let e = r.err().unwrap_or_else(|| panic!("{test}: expected an error")).to_string();
    let want = format!("{}:{line}:{col}: ", path.with_file_name(file).display());
    assert!(e.starts_with(&want), "{test}: want {want}..., got {e}");
    assert!(e.to_lowercase().contains(&word.to_lowercase()), "{test}: want `{word}` in {e}");
}

#[test]
fn base_scene_is_valid() {
    let (_, r) = load("base", BASE, &[]);
    let objects = r.unwrap().objects().unwrap();
    assert_eq!(objects.len(), 1);
    assert_eq!(objects[0].surface.triangles.len(), 8);
}

#[test]
fn missing_scene_file() {
    let e = scene::load(Path::new("/nonexistent/voltex/scene.ron")).unwrap_err();
    assert!(matches!(e, voltex::Error::File { .. }), "{e}");
}

#[test]
fn malformed_and_truncated() {
    assert_err("comma", &[(3, "    output: (width: 64 height: 64),")], "scene.ron", 3, 24, "expected");
    let truncated: String = BASE.lines().take(12).map(|l| format!("{l}\n")).collect();
    assert_err_files("truncated", &truncated, &[], "scene.ron", 12, 35, "expected the rest");
}

#[test]
fn unknown_field_lists_expected_names() {
    let l = "    camera: (eye: (0.0, -3.0, 2.0), target: (0.0, 0.0, 0.0), fovy: 40.0),";
    assert_err("field", &[(4, l)], "scene.ron", 4, 62, "`fov_y`");
}

#[test]
fn unknown_method_variant() {
    let l = "            method: ViewSlice(planes: 16),";
    assert_err("variant", &[(14, l)], "scene.ron", 14, 21, "`ViewSlices`");
}

#[test]
fn non_finite_numbers() {
    let l = "    camera: (eye: (0.0, NaN, 2.0), target: (0.0, 0.0, 0.0), fov_y: 40.0),";
    assert_err("nan", &[(4, l)], "scene.ron", 4, 25, "expected a finite number");
    let l = "            height: (length: inf),";
    assert_err("inf", &[(12, l)], "scene.ron", 12, 30, "expected a finite number");
}

/// The baked texel shadow's numbers and ViewSlices' level of detail, at their positions.
#[test]
fn texel_shadow_and_lod_values() {
    let t = r#"        "t": (resolution: (8, 8, 8), source: Constant(color: (1.0, 1.0, 1.0)), shadow: (extinction: -1.0)),"#;
    assert_err("extinction", &[(6, t)], "scene.ron", 6, 101, "expected a positive finite number");
    let t = r#"        "t": (resolution: (8, 8, 8), source: Constant(color: (1.0, 1.0, 1.0)), shadow: (extinction: 8.0, ambient: 1.5)),"#;
    assert_err("ambient", &[(6, t)], "scene.ron", 6, 115, "expected a number in [0, 1]");
    let l = "            method: ViewSlices(planes: 16, lod: Sometimes),";
    assert_err("lod", &[(14, l)], "scene.ron", 14, 49, "`Auto`");
}

/// `back_face_culling`, AxisSlices' culling knob before exact occlusion culling replaced it
/// (it changed images at silhouettes), is an unknown field whose error names the new one.
#[test]
fn former_culling_name_names_its_successor() {
    let l = "            method: AxisSlices(back_face_culling: true),";
    assert_err("former", &[(14, l)], "scene.ron", 14, 32, "`occlusion_culling`");
}

#[test]
fn regress_supersample() {
    let l = "    output: (width: 64, height: 64), regress: (supersample: 9),";
    assert_err("supersample9", &[(3, l)], "scene.ron", 3, 61, "expected samples per pixel axis in 1..=8");
}

#[test]
fn plane_counts() {
    let l = "            method: ViewSlices(planes: 0),";
    assert_err("planes0", &[(14, l)], "scene.ron", 14, 40, "expected a plane count in 1..=16384");
    let l = "            method: ViewSlices(planes: 100000),";
    assert_err("planes1e5", &[(14, l)], "scene.ron", 14, 40, "expected a plane count");
}

/// ShellMarch's footprint filter: a bias out of range, an unknown filter.
#[test]
fn shell_march_filter_knobs() {
    let l = "            method: ShellMarch(filter: Footprint, mip_bias: 9.0),";
    assert_err("mip_bias9", &[(14, l)], "scene.ron", 14, 61, "expected a MIP bias in [-4, 4] levels");
    let l = "            method: ShellMarch(filter: Box),";
    assert_err("filter_box", &[(14, l)], "scene.ron", 14, 40, "Footprint");
}

#[test]
fn output_sizes() {
    let l = "    output: (width: 0, height: 64),";
    assert_err("width0", &[(3, l)], "scene.ron", 3, 21, "expected an output size in 1..=16384");
    let l = "    output: (width: 64, height: 100000),";
    assert_err("height1e5", &[(3, l)], "scene.ron", 3, 33, "expected an output size");
}

#[test]
fn missing_obj_file() {
    let l = r#"            surface: Obj(path: "missing.obj"),"#;
    assert_err("noobj", &[(11, l)], "scene.ron", 11, 32, "expected a mesh file (.obj, .gltf or .glb)");
}

#[test]
fn unknown_texel_name() {
    let l = r#"            texel: "x","#;
    assert_err("texel", &[(13, l)], "scene.ron", 13, 20, "expected one of \"t\"");
}

#[test]
fn obj_face_index_out_of_range() {
    let l = r#"            surface: Obj(path: "mesh.obj"),"#;
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
    let text = with_lines(&[(11, l)]);
    assert_err_files("objindex", &text, &[("mesh.obj", obj)], "mesh.obj", 4, 7, "expected 1..=3");
}

#[test]
fn node_consistency() {
    let l = "            height: (length: 0.1, scale: VertexAttribute),";
    assert_err("vattr", &[(12, l)], "scene.ron", 12, 42, "built-in surfaces have no vertex attribute");
    assert_err("notexel", &[(13, "")], "scene.ron", 14, 21, "expected a `texel`");
    let l = r#"            height: (length: 0.1, scale: Texture(path: "h.png")),"#;
    assert_err("nopng", &[(12, l)], "scene.ron", 12, 56, "expected a PNG or EXR image");
}

#[test]
fn degenerate_camera() {
    let l = "    camera: (eye: (0.0, 0.0, 2.0), target: (0.0, 0.0, 0.0)),";
    assert_err("camup", &[(4, l)], "scene.ron", 4, 13, "not parallel");
}

#[test]
fn example_scenes_load_and_flatten() {
    let root = voltex::project_root().join("scenes");
    let mut stack = vec![root];
    let mut count = 0;
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "ron") {
                let s = scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
                let objects = s.objects().unwrap_or_else(|e| panic!("{e}"));
                assert!(!objects.is_empty(), "{}", p.display());
                // The hard-case catalogue is degenerate on purpose: only the prism checks'
                // degenerate-triangle and zero-height warnings are expected there.
                let hard_case = p.parent().is_some_and(|d| d.ends_with("hard_cases"));
                for o in &objects {
                    let expected =
                        |w: &String| hard_case && (w.contains("degenerate") || w.contains("zero-length"));
                    assert!(o.report.warnings.iter().all(expected), "{}: {:?}", p.display(), o.report);
                }
                count += 1;
            }
        }
    }
    assert!(count >= 4);
}

/// `ImageHeight` texels: a missing image, a file that is no PNG and a channel the image lacks are
/// errors naming the file (and `line:col` in the scene).
#[test]
fn image_height_errors() {
    let source = |channel: u32| {
        format!(
            r#"        "t": (resolution: (8, 8, 8), source: ImageHeight(image: "h.png", channel: {channel}, amplitude: 0.5, color_low: (0.1, 0.1, 0.1), color_high: (0.9, 0.9, 0.9))),"#
        )
    };
    let text = with_lines(&[(6, &source(0))]);
    assert_err_files("hmissing", &text, &[], "scene.ron", 6, 65, "expected a PNG or EXR image");
    let (_, r) = load("hgarbage", &text, &[("h.png", "not an image")]);
    let e = r.expect_err("a text file is no PNG").to_string();
    assert!(e.contains("h.png") && e.contains("expected a PNG image"), "{e}");
    let dir = temp_dir("hchannel");
    std::fs::copy(voltex::project_root().join("scenes/meyer_neyret/cobbles.png"), dir.join("h.png")).unwrap();
    let path = dir.join("scene.ron");
    std::fs::write(&path, with_lines(&[(6, &source(2))])).unwrap();
    let e = scene::load(&path).expect_err("a grey image has one channel").to_string();
    assert!(e.starts_with(&format!("{}:6:65: ", path.display())), "{e}");
    assert!(e.contains("expected a channel in 0..1"), "{e}");
    std::fs::write(&path, with_lines(&[(6, &source(0))])).unwrap();
    let s = scene::load(&path).unwrap();
    assert_eq!(s.image("h.png").map(|i| (i.width, i.height, i.channels)), Some((64, 64, 1)));
}
