//! `bench --json`, `bench-hyper --json`, `bench-report` and the `--trace` files of `render`,
//! `bench` and `preview`: the JSON's shape (every row's keys, the truth each error names), errors
//! that are computed from the images (never a duration is asserted), the cost model and the
//! adapter limits present, the performance page's section generated from the files, and traces
//! with one complete event per graph pass, named as the graph's passes.

use crate::common;

use std::path::Path;
use std::process::{Command, Stdio};

use voltex::bench::json::Report;

fn report(path: &Path) -> Report {
    // `Report` denies unknown fields: the file has exactly the documented shape.
    Report::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn finite(v: Option<f64>, what: &str) -> f64 {
    let v = v.unwrap_or_else(|| panic!("{what} missing"));
    assert!(v.is_finite() && v >= 0.0, "{what} = {v}");
    v
}

/// The complete events (`"ph": "X"`) of a trace per track (thread id): their names in order.
fn trace_events(path: &Path) -> Vec<Vec<String>> {
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut tracks: Vec<Vec<String>> = Vec::new();
    for e in v["traceEvents"].as_array().expect("traceEvents") {
        if e["ph"] != "X" {
            continue;
        }
        assert!(
            e["ts"].as_f64().is_some_and(|t| t >= 0.0) && e["dur"].as_f64().is_some_and(|d| d >= 0.0),
            "{e}"
        );
        let tid = e["tid"].as_u64().unwrap() as usize;
        tracks.resize(tracks.len().max(tid + 1), Vec::new());
        tracks[tid].push(e["name"].as_str().unwrap().to_string());
    }
    tracks
}

/// The names of the passes a scene's plan runs at `size`.
fn plan_passes(scene: &Path, size: (u32, u32), graph: Option<&str>) -> Vec<String> {
    let scene = voltex::scene::load(scene).unwrap();
    let opts = voltex::render::RenderOptions {
        size: Some(size),
        graph: graph.map(|g| common::root().join(g)),
        ..Default::default()
    };
    let bp = voltex::render::Blueprint::new(&scene, &opts).unwrap();
    bp.plan.passes.iter().map(|p| p.decl.name().to_string()).collect()
}

#[test]
fn bench_writes_json_rows_limits_cost_model_and_trace() {
    let dir = common::scratch_dir("voltex-bench-json");
    let (json, trace) = (dir.join("bench.json"), dir.join("bench.trace.json"));
    let scene = common::root().join("scenes/view_slices/flat_box.ron");
    common::ok(common::voltex(&[
        "bench",
        common::s(&scene),
        "--size",
        "32x32",
        "--planes",
        "8,16,32",
        "--frames",
        "1",
        "--reference-planes",
        "128",
        "--limits",
        "--json",
        common::s(&json),
        "--trace",
        common::s(&trace),
    ]));
    let r = report(&json);
    assert_eq!((r.command.as_str(), r.size, r.frames), ("bench", [32, 32], 1));
    // Progress on stderr, a line per setting and phase (none with -q); the tables on stdout.
    let args = |quiet: bool| {
        let mut a = vec!["bench", common::s(&scene), "--size", "16x16", "--planes", "4", "--frames", "1"];
        a.extend(["--reference-planes", "16"]);
        if quiet {
            a.push("-q");
        }
        common::voltex(&a)
    };
    let said = args(false);
    let err = common::stderr(&said);
    assert!(
        said.status.success() && String::from_utf8_lossy(&said.stdout).contains("| flat_box | 4 |"),
        "{err}"
    );
    for line in [
        "[1/4",
        "planes=4 reject=true Raster slicing alone: ",
        "[4/4] flat_box planes=4 reject=false Raster frame: ",
    ] {
        assert!(err.contains(line), "{line:?} not in {err}");
    }
    let quiet = args(true);
    assert!(quiet.status.success() && quiet.stderr.is_empty(), "{}", common::stderr(&quiet));
    assert!(r.adapter.contains("(") && r.date.len() == 16, "{} {}", r.adapter, r.date);
    assert_eq!(r.rows.len(), 6, "3 plane counts x trivial reject on and off");
    for row in &r.rows {
        assert_eq!(
            (row.table.as_str(), row.scene.as_deref(), row.method.as_str()),
            ("table1", Some("flat_box"), "ViewSlices")
        );
        assert!(row.planes.is_some() && row.trivial_reject.is_some());
        assert!(row.frame_ms.is_finite() && row.fps.is_finite());
        finite(row.flip, "flip");
        finite(row.rel_rmse, "rel_rmse");
        assert_eq!(row.truth.as_deref(), Some("ViewSlices, 128 planes"));
        assert_eq!(row.work_unit.as_deref(), Some("slice triangles"));
        assert!(row.work.unwrap() > 0.0 && row.extra.contains_key("blend_limit_share"), "{row:?}");
    }
    // Errors come from the images: the trivial reject changes no pixel, more planes fewer errors.
    let err = |planes: u32, reject: bool| {
        let row =
            r.rows.iter().find(|x| x.planes == Some(planes) && x.trivial_reject == Some(reject)).unwrap();
        (row.flip.unwrap(), row.rel_rmse.unwrap())
    };
    assert_eq!(err(8, true), err(8, false));
    assert!(err(8, true).1 > err(32, true).1, "{:?} {:?}", err(8, true), err(32, true));
    let limits = r.limits.as_ref().expect("--limits");
    for rate in [limits.blend_fragments_per_s, limits.texture_samples_per_s, limits.noise_per_s] {
        assert!(rate.is_finite() && rate > 0.0);
    }
    // None only where the adapter's triangles cost under 5% of their draw.
    assert!(limits.triangles_per_s.is_none_or(|r| r.is_finite() && r > 0.0), "{limits:?}");
    for row in &r.rows {
        let bound = row.extra["frame_over_adapter_bound"];
        assert!(bound.is_finite() && bound > 0.0 && bound <= row.extra["frame_over_blend_limit"], "{row:?}");
    }
    // One per trivial reject: classifying every prism against every plane is a cost of its own.
    assert_eq!(r.cost_models.len(), 2);
    assert!(r.cost_models.iter().all(|f| f.r2 <= 1.0 && f.rows == 3), "{:?}", r.cost_models);

    // A track per setting and phase, one event per pass of its graph.
    let tracks = trace_events(&trace);
    assert_eq!(tracks.len(), 12, "{tracks:?}");
    let alone = plan_passes(&scene, (32, 32), Some("graphs/slices_only.ron"));
    let whole = plan_passes(&scene, (32, 32), None);
    for (i, names) in tracks.iter().enumerate() {
        assert_eq!(names, if i < 6 { &alone } else { &whole }, "track {i}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bench_hyper_writes_json_with_errors_against_named_truths() {
    let dir = common::scratch_dir("voltex-bench-hyper-json");
    let (json, trace) = (dir.join("hyper.json"), dir.join("hyper.trace.json"));
    let out = common::ok(common::voltex(&[
        "bench-hyper",
        "--segments",
        "--shadows",
        "--quick",
        "--size",
        "24x24",
        "--frames",
        "1",
        "--json",
        common::s(&json),
        "--trace",
        common::s(&trace),
    ]));
    assert!(out.contains("cost model"), "{out}");
    let r = report(&json);
    assert_eq!(r.command, "bench-hyper");
    let table = |t: &str| r.rows.iter().filter(|x| x.table == t).collect::<Vec<_>>();
    let (segments, shadows) = (table("segments"), table("shadows"));
    assert_eq!((segments.len(), shadows.len()), (3, 5), "{:?}", r.rows);
    for row in r.rows.iter() {
        assert!(row.object.is_some() && row.scene.is_none() && row.method == "RayMarch");
        assert!(
            row.quality.is_some() && row.step.is_some() && row.shading.is_some() && row.segments.is_some()
        );
        assert!(row.truth.as_deref().is_some_and(|t| t.starts_with("RayMarch, step 0.001")), "{row:?}");
        finite(row.flip, "flip");
        finite(row.rel_rmse, "rel_rmse");
        assert!(row.work.unwrap() > 0.0 && row.work_unit.as_deref() == Some("density evaluations"));
    }
    let by = |s: &str| shadows.iter().find(|x| x.shadows.as_deref() == Some(s)).unwrap();
    // Shadow rays against shadow rays at the same step: the same image.
    assert_eq!(by("rays").extra["flip_vs_rays_same_step"], 0.0);
    assert!(by("none").extra["flip_vs_rays_same_step"] > by("volume:64").extra["flip_vs_rays_same_step"]);
    for s in ["volume:32", "volume:64", "volume:128"] {
        assert!(
            by(s).extra.contains_key("light_volume_bake_ms")
                && by(s).shading.as_deref() == Some("PhongShadows")
        );
    }
    assert!(!by("none").extra.contains_key("light_volume_bake_ms"));
    let tracks = trace_events(&trace);
    assert_eq!(tracks.len(), 8);
    assert!(
        tracks
            .iter()
            .all(|t| t.contains(&"ray_march".to_string()) || t.contains(&"splat_segments".to_string())),
        "{tracks:?}"
    );

    // The performance page's section from both files.
    // A `bench` file (made here: the bench itself is measured in the test above).
    let bench = dir.join("bench.json");
    let mut b = Report::new("bench", "an adapter (Vulkan)".into(), (8, 8), 1);
    b.rows = (1..=3)
        .map(|i| voltex::bench::json::Row {
            scene: Some("flat_box".into()),
            planes: Some(8 * i),
            flip: Some(0.1 / i as f64),
            work: Some(100.0 * i as f64),
            work_unit: Some("slice triangles".into()),
            ..voltex::bench::json::Row::new("table1", "ViewSlices", 2.0 * i as f64)
        })
        .collect();
    b.cost_models = voltex::bench::cost::fit(&b.rows);
    b.write(&bench).unwrap();
    let md = common::ok(common::voltex(&["bench-report", common::s(&json), common::s(&bench)]));
    assert!(
        md.contains("### `voltex bench-hyper` on ") && md.contains(&r.adapter) && md.contains(&r.date),
        "{md}"
    );
    assert!(
        md.contains("Table `shadows`; errors against: RayMarch, step 0.001") && md.contains("| object |"),
        "{md}"
    );
    assert!(md.contains("### `voltex bench` on ") && md.contains("cost model, table `table1`"), "{md}");
    let page = dir.join("page.md");
    let begin = voltex::bench::json::BEGIN;
    let end = voltex::bench::json::END;
    std::fs::write(&page, format!("# Perf\n\nbefore\n\n{begin}\n\nold\n\n{end}\n\nafter\n")).unwrap();
    common::ok(common::voltex(&["bench-report", common::s(&json), "--update", common::s(&page)]));
    let text = std::fs::read_to_string(&page).unwrap();
    assert!(
        text.starts_with("# Perf\n\nbefore\n\n") && text.ends_with(&format!("{end}\n\nafter\n")),
        "{text}"
    );
    assert!(!text.contains("old") && text.contains("Table `segments`"), "{text}");
    // A page without the markers is an error naming it; it is left as it was.
    std::fs::write(&page, "no markers\n").unwrap();
    let out = common::voltex(&["bench-report", common::s(&json), "--update", common::s(&page)]);
    assert!(!out.status.success() && common::stderr(&out).contains("page.md"), "{}", common::stderr(&out));
    assert_eq!(std::fs::read_to_string(&page).unwrap(), "no markers\n");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn render_trace_has_one_event_per_graph_pass() {
    let dir = common::scratch_dir("voltex-render-trace");
    let scene = common::root().join("scenes/hypertextures/fig4_holes.ron");
    let trace = dir.join("render.trace.json");
    common::ok(common::voltex(&[
        "render",
        common::s(&scene),
        "--size",
        "32x16",
        "--shadows",
        "volume:16",
        "-o",
        common::s(&dir.join("holes.exr")),
        "--trace",
        common::s(&trace),
    ]));
    let tracks = trace_events(&trace);
    assert_eq!(tracks, vec![plan_passes(&scene, (32, 16), None)]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn preview_trace_has_one_event_per_graph_pass() {
    let have_xvfb =
        Command::new("xvfb-run").arg("--help").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok();
    assert!(have_xvfb, "xvfb-run is missing: apt-get install -y xvfb (.ci/run installs it)");
    let dir = common::scratch_dir("voltex-preview-trace");
    let scene = common::root().join("scenes/view_slices/flat_box.ron");
    let trace = dir.join("preview.trace.json");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_voltex"), "preview"])
        .arg(&scene)
        .args(["--size", "48x48", "--quit-after", "3", "--trace"])
        .arg(&trace)
        .env("VOLTEX_ROOT", common::root())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", common::stderr(&out));
    let tracks = trace_events(&trace);
    assert_eq!(tracks.len(), 1);
    let passes = plan_passes(&scene, (48, 48), None);
    assert!(!tracks[0].is_empty() && tracks[0].len().is_multiple_of(passes.len()), "{tracks:?}");
    assert!(tracks[0].chunks(passes.len()).all(|frame| frame == passes.as_slice()), "{tracks:?}");
    std::fs::remove_dir_all(&dir).ok();
}
