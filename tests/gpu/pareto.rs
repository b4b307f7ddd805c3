//! `voltex pareto` through the real binary: reduced sweeps on a small scene write the CSV (one
//! row per setting, error falling with the plane count and rising with the ray step), the SVG
//! with every point and the truth; bad input fails with status 1 before any rendering. No test
//! asserts a duration.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-pareto-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `voltex pareto ARGS` against this checkout's kernels and scenes.
fn pareto(args: &[&str]) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.arg("pareto").args(args).env("VOLTEX_ROOT", root());
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    cmd.output().unwrap()
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

fn scene(name: &str) -> String {
    root().join("scenes/view_slices").join(name).to_str().unwrap().to_string()
}

/// The CSV as header → column index, and rows of fields.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let csv = std::fs::read_to_string(path).unwrap();
    let mut lines = csv.lines().map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>());
    let header = lines.next().unwrap();
    let rows: Vec<Vec<String>> = lines.collect();
    for r in &rows {
        assert_eq!(r.len(), header.len(), "row {r:?} against header {header:?}");
    }
    (header, rows)
}

#[test]
fn view_slices_sweep_writes_csv_svg_and_fronts() {
    let dir = temp_dir("sweep");
    let out = dir.join("result");
    let args = [
        scene("torus_egg.ron"),
        "--size".into(),
        "48x48".into(),
        "--frames".into(),
        "1".into(),
        "--planes".into(),
        "16,64".into(),
        "--methods".into(),
        "view-slices".into(),
        "--truth".into(),
        "view-slices:1024".into(),
        "--out".into(),
        out.to_str().unwrap().into(),
    ];
    let run = pareto(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let log = text(&run);
    println!("{log}");
    assert_eq!(run.status.code(), Some(0), "{log}");
    assert!(log.contains("adapter: ") && log.contains("overall front:"), "{log}");

    let (header, rows) = read_csv(&out.join("pareto.csv"));
    let col =
        |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    for c in [
        "method",
        "knobs",
        "gpu_ms",
        "wall_ms",
        "flip",
        "rel_rmse",
        "method_front",
        "overall_front",
        "passes",
    ] {
        col(c);
    }
    assert_eq!(rows.len(), 4, "16 and 64 planes, reject on and off: {rows:?}");
    let get = |planes: &str, reject: &str, c: &str| -> String {
        rows.iter()
            .find(|r| r[col("planes")] == planes && r[col("trivial_reject")] == reject)
            .unwrap_or_else(|| panic!("no row planes={planes} reject={reject}"))[col(c)]
        .clone()
    };
    let num = |planes: &str, reject: &str, c: &str| get(planes, reject, c).parse::<f64>().unwrap();
    for reject in ["true", "false"] {
        assert_eq!(get("16", reject, "method"), "ViewSlices");
        let (coarse, fine) = (num("16", reject, "flip"), num("64", reject, "flip"));
        println!("reject {reject}: FLIP {coarse:.4} at 16 planes, {fine:.4} at 64");
        assert!(coarse > fine, "error should fall with the plane count: {coarse} vs {fine}");
        assert!(num("16", reject, "rel_rmse") > num("64", reject, "rel_rmse"));
        assert!(num("64", reject, "wall_ms").is_finite());
        assert!(get("64", reject, "passes").contains("draw_slices="));
    }
    // The trivial reject changes speed, not the image (up to blending order within a plane).
    assert!((num("64", "true", "flip") - num("64", "false", "flip")).abs() < 1e-4);
    // The most accurate setting (the faster of the two at 64 planes) is on both fronts.
    let on = |c: &str| rows.iter().filter(|r| r[col("planes")] == "64" && r[col(c)] == "true").count();
    assert!(on("overall_front") >= 1 && on("method_front") >= 1, "{rows:?}");

    let svg = std::fs::read_to_string(out.join("pareto.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches(r#"class="point""#).count(), 4);
    assert!(svg.contains(">ViewSlices</text>"));
    assert!(out.join("truth.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reference_truth_and_step_sweep() {
    let dir = temp_dir("reference");
    let out = dir.join("result");
    let out_s = out.to_str().unwrap().to_string();
    let scene = scene("torus_egg.ron");
    let args =
        [&scene, "--size", "40x40", "--frames", "1", "--planes", "16", "--steps", "8,32", "--out", &out_s];
    let run = pareto(&args);
    let log = text(&run);
    println!("{log}");
    assert_eq!(run.status.code(), Some(0), "{log}");
    assert!(log.contains("truth: Reference, default step"), "{log}");
    assert!(log.contains("Reference front:") && log.contains("ViewSlices front:"), "{log}");

    let (header, rows) = read_csv(&out.join("pareto.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let reference: Vec<&Vec<String>> = rows.iter().filter(|r| r[col("method")] == "Reference").collect();
    assert_eq!(reference.len(), 2, "{rows:?}");
    assert_eq!(rows.len(), 4, "ViewSlices at 16 planes, reject on and off, and two steps: {rows:?}");
    let by = |k: &str| reference.iter().find(|r| r[col("knobs")] == k).unwrap_or_else(|| panic!("no {k}"));
    let f = |k: &str, c: &str| by(k)[col(c)].parse::<f64>().unwrap();
    let ratio = f("step=32x", "step") / f("step=8x", "step");
    assert!((ratio - 4.0).abs() < 1e-3, "steps are multiples of one default step: {ratio}");
    println!("Reference FLIP {:.4} at 8x, {:.4} at 32x", f("step=8x", "flip"), f("step=32x", "flip"));
    assert!(f("step=32x", "flip") > f("step=8x", "flip"), "error should grow with the step");
    assert!(by("step=8x")[col("passes")].contains("trace_reference="));
    let svg = std::fs::read_to_string(out.join("pareto.svg")).unwrap();
    assert_eq!(svg.matches(r#"class="point""#).count(), 4);
    assert!(svg.contains(">Reference</text>") && svg.contains(">ViewSlices</text>"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_scene_fails_at_its_line_and_column() {
    let dir = temp_dir("bad-scene");
    let file = dir.join("scene.ron");
    std::fs::write(&file, "Scene(\n    output: (width: 64, hieght: 64),\n)\n").unwrap();
    let out = dir.join("result");
    let run = pareto(&[file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let log = text(&run);
    assert_eq!(run.status.code(), Some(1), "{log}");
    assert!(log.contains(&format!("{}:2:", file.display())), "{log}");
    assert!(!log.contains("panicked"), "{log}");
    assert!(!out.exists(), "nothing should be written");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unwritable_output_fails_before_rendering() {
    let dir = temp_dir("bad-out");
    let blocker = dir.join("file");
    std::fs::write(&blocker, "not a folder").unwrap();
    let out = blocker.join("result");
    let run = pareto(&[&scene("flat_box.ron"), "--out", out.to_str().unwrap(), "--truth", "view-slices:64"]);
    let log = text(&run);
    assert_eq!(run.status.code(), Some(1), "{log}");
    assert!(log.contains(out.to_str().unwrap()), "the error names the folder: {log}");
    assert!(!log.contains("compute passes") && !log.contains("panicked"), "{log}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sweep_values_are_errors() {
    let dir = temp_dir("bad-values");
    let out = dir.join("result");
    let run = pareto(&[&scene("flat_box.ron"), "--out", out.to_str().unwrap(), "--planes", "0,16"]);
    let log = text(&run);
    assert_eq!(run.status.code(), Some(1), "{log}");
    assert!(log.contains("--planes 0"), "{log}");
    let run = pareto(&[&scene("flat_box.ron"), "--truth", "view-slices:x"]);
    assert_eq!(run.status.code(), Some(2), "clap rejects the value: {}", text(&run));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--methods axis-slices` sweeps the criteria d = p: finer criteria draw more slices (more GPU
/// work) and are closer to the truth.
#[test]
fn axis_slices_criteria_sweep() {
    let dir = temp_dir("axis");
    let out = dir.join("result");
    let out_s = out.to_str().unwrap().to_string();
    let scene = root().join("scenes/meyer_neyret/pear.ron").to_str().unwrap().to_string();
    let args = [
        &scene,
        "--size",
        "48x48",
        "--frames",
        "1",
        "--methods",
        "axis-slices",
        "--criteria",
        "0.25,8",
        "--out",
        &out_s,
    ];
    let run = pareto(&args);
    let log = text(&run);
    assert_eq!(run.status.code(), Some(0), "{log}");
    let (header, rows) = read_csv(&out.join("pareto.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let get = |k: &str, c: &str| {
        let r = rows.iter().find(|r| r[col("knobs")] == k).unwrap_or_else(|| panic!("no {k}: {rows:?}"));
        r[col(c)].parse::<f64>().unwrap()
    };
    assert_eq!(rows.len(), 2, "{rows:?}");
    println!(
        "AxisSlices FLIP {:.4} at d=p=0.25, {:.4} at d=p=8",
        get("d=p=0.25", "flip"),
        get("d=p=8", "flip")
    );
    assert!(get("d=p=0.25", "flip") < get("d=p=8", "flip"), "finer criteria are closer to the truth");
    let bad = pareto(&[&scene, "--methods", "axis-slices", "--criteria", "0", "--out", &out_s]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(text(&bad).contains("--criteria 0"), "{}", text(&bad));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--methods ray-march` sweeps the hypertextures' step, segments and adaptive strides against a
/// converged march: the finer step is closer to the truth, depth peeling as close as the bounds
/// march, the adaptive stride nearly as close with fewer density evaluations; a bad step,
/// adaptive pair or truth fails before rendering, and a scene without
/// hypertextures has nothing to sweep.
#[test]
fn ray_march_step_sweep() {
    let dir = temp_dir("ray");
    let out = dir.join("result");
    let out_s = out.to_str().unwrap().to_string();
    let scene = root().join("scenes/hypertextures/fig4_craters.ron").to_str().unwrap().to_string();
    let args = [
        &scene,
        "--size",
        "32x32",
        "--frames",
        "1",
        "--methods",
        "ray-march",
        "--ray-steps",
        "0.06,0.01",
        "--ray-segments",
        "bounds,depth-peeling,splatting",
        "--ray-adaptive",
        "0.01:0.06",
        "--truth",
        "ray-march:0.0025",
        "--out",
        &out_s,
    ];
    let run = pareto(&args);
    let log = text(&run);
    assert_eq!(run.status.code(), Some(0), "{log}");
    assert!(log.contains("truth: RayMarch, step 0.0025"), "{log}");
    let (header, rows) = read_csv(&out.join("pareto.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let value = |k: &str, c: &str| {
        let r = rows.iter().find(|r| r[col("knobs")] == k).unwrap_or_else(|| panic!("no {k}: {rows:?}"));
        assert_eq!(r[col("method")], "RayMarch");
        r[col(c)].parse::<f64>().unwrap()
    };
    let get = |k: &str| value(k, "flip");
    assert_eq!(rows.len(), 9, "{rows:?}");
    let bounds = |k: &str| format!("{k} segments=Bounds");
    let (fine, coarse, adaptive) =
        (get(&bounds("step=0.01")), get(&bounds("step=0.06")), get(&bounds("step=0.01 max_step=0.06")));
    let evaluations = |k: &str| value(&bounds(k), "evaluations");
    let (fine_n, coarse_n, adaptive_n) =
        (evaluations("step=0.01"), evaluations("step=0.06"), evaluations("step=0.01 max_step=0.06"));
    let peeled = get("step=0.01 segments=DepthPeeling(4)");
    println!(
        "RayMarch FLIP {fine:.4} at step 0.01 ({fine_n} density evaluations), {coarse:.4} at step 0.06 \
         ({coarse_n}), {adaptive:.4} adaptive 0.01 to 0.06 ({adaptive_n}), {peeled:.4} depth-peeled at 0.01"
    );
    assert!(fine < coarse, "a finer step is closer to the converged march");
    // The adaptive stride skips empty space: fewer evaluations than its fine step, and the
    // error of the fine step rather than the coarse one.
    assert!(coarse_n < adaptive_n && adaptive_n < fine_n, "{coarse_n} {adaptive_n} {fine_n}");
    assert!(adaptive < 0.5 * (fine + coarse), "{adaptive} vs {fine} and {coarse}");
    // Depth peeling takes the bounds march's samples where there is matter: the same error.
    assert!((peeled - fine).abs() < 0.002, "depth peeling {peeled} against bounds {fine}");
    // Splatting reconstructs from overlapping spheres and slab means: converging with the step
    // too, and more costly (each sample once per sphere covering it).
    let (splat_fine, splat_coarse) =
        (get("step=0.01 segments=Splatting(16)"), get("step=0.06 segments=Splatting(16)"));
    let splat_n = value("step=0.01 segments=Splatting(16)", "evaluations");
    println!(
        "Splatting FLIP {splat_fine:.4} at step 0.01 ({splat_n} evaluations), {splat_coarse:.4} at 0.06"
    );
    assert!(splat_fine < splat_coarse && splat_n > fine_n, "{splat_fine} {splat_coarse} {splat_n} {fine_n}");
    for (flag, value, expected) in [
        ("--ray-steps", "0", "--ray-steps 0"),
        ("--truth", "ray-march:-1", "expected a positive step"),
        ("--ray-adaptive", "0.01:0.005", "MAX_STEP >= STEP"),
        ("--ray-adaptive", "0.01", "expected STEP:MAX_STEP"),
        ("--ray-adaptive", "0.01:inf", "expected STEP:MAX_STEP"),
    ] {
        let bad = pareto(&[&scene, "--methods", "ray-march", flag, value, "--out", &out_s]);
        assert!(bad.status.code().is_some_and(|c| c != 0), "{}", text(&bad));
        assert!(text(&bad).contains(expected), "{flag} {value}: {}", text(&bad));
    }
    let texels = root().join("scenes/meyer_neyret/pear.ron").to_str().unwrap().to_string();
    let none = pareto(&[&texels, "--methods", "ray-march", "--out", &out_s]);
    assert_eq!(none.status.code(), Some(1));
    assert!(text(&none).contains("no hypertexture"), "{}", text(&none));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--peers`: the rows of other renderers (tools/peers/ on the absorbing box, checked in as
/// tests/peers/absorbing_box.csv) stand beside voltex's volume settings, which the sweep now
/// measures on a volume scene (Reference switched from RayMarch, RayMarch's step): in the
/// printed table and as their own series in the chart. A bad row fails at its file:line:col
/// before any rendering, and nothing is written.
#[test]
fn peers_join_the_table_and_the_chart() {
    let dir = temp_dir("peers");
    let out = dir.join("result");
    let scene = root().join("scenes/volumes/absorbing_box.ron");
    let csv = root().join("tests/peers/absorbing_box.csv");
    let (scene, csv, o) = (scene.to_str().unwrap(), csv.to_str().unwrap(), out.to_str().unwrap());
    let common = ["--size", "32x32", "--frames", "1", "--methods", "reference,ray-march", "--steps", "8"];
    let run =
        pareto(&[&[scene], &common[..], &["--ray-steps", "0.0625", "--out", o, "--peers", csv]].concat());
    let log = text(&run);
    println!("{log}");
    assert_eq!(run.status.code(), Some(0), "{log}");
    let peers = std::fs::read_to_string(root().join("tests/peers/absorbing_box.csv")).unwrap();
    let rows = peers.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()).count() - 1;
    assert!(log.contains("peers (--peers"), "{log}");
    assert!(log.contains("| Mitsuba volpath |") && log.contains("| Cycles |"), "{log}");
    assert!(
        log.contains(&format!("absorbing_box.csv:{}", peers.lines().count())),
        "every row names its line: {log}"
    );
    let (header, measured) = read_csv(&out.join("pareto.csv"));
    let method = header.iter().position(|h| h == "method").unwrap();
    for m in ["Reference", "RayMarch"] {
        assert!(measured.iter().any(|r| r[method] == m), "{m} measured on the volume: {measured:?}");
    }
    let svg = std::fs::read_to_string(out.join("pareto.svg")).unwrap();
    assert!(
        svg.contains(">Mitsuba volpath</text>") && svg.contains(">Cycles</text>"),
        "peer series in the legend"
    );
    assert_eq!(svg.matches(r#"class="point""#).count(), measured.len() + rows);

    let bad = dir.join("bad.csv");
    std::fs::write(&bad, peers.replacen(",2,", ",two,", 1)).unwrap();
    let bad_out = dir.join("bad-result");
    let args =
        [&[scene], &common[..], &["--out", bad_out.to_str().unwrap(), "--peers", csv, bad.to_str().unwrap()]];
    let run = pareto(&args.concat());
    let log = text(&run);
    assert_eq!(run.status.code(), Some(1), "{log}");
    assert!(log.contains(&format!("{}:", bad.display())) && log.contains("`threads` is `two`"), "{log}");
    assert!(!log.contains("panicked") && !bad_out.exists(), "{log}");
    let _ = std::fs::remove_dir_all(&dir);
}
