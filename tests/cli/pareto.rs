//! `voltex pareto`'s orbit times, its supersampled truth and ShellMarch's tolerance sweep
//! (issue 31, items 4 and 7).

use crate::common::{ok, root, s, scratch_dir, voltex};

/// The CSV's rows of `method` as (knobs, column values by name).
fn rows(csv: &str, method: &str) -> Vec<(String, std::collections::HashMap<String, String>)> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .filter(|l| l.starts_with(&format!("{method},")))
        .map(|l| {
            let cells = header.iter().map(|h| h.to_string()).zip(l.split(',').map(str::to_string)).collect();
            (l.split(',').nth(1).unwrap().to_string(), cells)
        })
        .collect()
}

fn pareto(scene: &str, name: &str, extra: &[&str]) -> (String, String) {
    let out = scratch_dir(name);
    let args = [&["pareto", scene, "--out", s(&out), "--frames", "1"][..], extra].concat();
    let stdout = ok(voltex(&args));
    let csv = std::fs::read_to_string(out.join("pareto.csv")).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
    (stdout, csv)
}

/// Every row has an orbit time; a supersampled truth is said and changes the errors measured
/// against it (the same setting, the same image, another truth).
#[test]
fn rows_have_orbit_times_and_the_truth_can_be_supersampled() {
    let scene = root().join("scenes/view_slices/flat_box.ron").display().to_string();
    let args = ["--methods", "view-slices", "--planes", "16", "--size", "24x24"];
    let (_, plain) = pareto(&scene, "voltex-pareto-plain", &args);
    let (stdout, supersampled) =
        pareto(&scene, "voltex-pareto-ss", &[&args[..], &["--supersample", "3"]].concat());
    assert!(stdout.contains(", 3x3 samples per pixel"), "{stdout}");
    assert!(stdout.contains("orbit ms"), "{stdout}");
    let (a, b) = (rows(&plain, "ViewSlices"), rows(&supersampled, "ViewSlices"));
    assert_eq!(a.len(), 2, "{plain}");
    for (knobs, row) in a.iter().chain(&b) {
        let orbit: f64 = row["orbit_ms"].parse().unwrap_or(f64::NAN);
        assert!(orbit > 0.0, "{knobs}: orbit_ms {orbit}");
    }
    assert_ne!(a[0].1["flip"], b[0].1["flip"], "the supersampled truth is another image");
    let out = voltex(&["pareto", &scene, "--supersample", "9"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("--supersample 9: expected 1 to 8"), "{err}");
}

/// ShellMarch's sweep takes its tolerance and the footprint filter's MIP bias too, and the knobs
/// reach the kernel: a looser tolerance maps fewer pieces exactly, and each bias reads other MIP
/// levels, so their images differ.
#[test]
fn shell_march_sweeps_its_step_tolerance_and_filter() {
    let scene = root().join("scenes/shell_march/torus_egg.ron").display().to_string();
    let (_, csv) = pareto(&scene, "voltex-pareto-shell", &["--methods", "shell-march", "--size", "32x32"]);
    let rows = rows(&csv, "ShellMarch");
    let knobs: Vec<&str> = rows.iter().map(|r| r.0.as_str()).collect();
    assert_eq!(
        knobs,
        [
            "step=0.5 tolerance=0.25",
            "step=1 tolerance=0.25",
            "step=2 tolerance=0.25",
            "step=4 tolerance=0.25",
            "step=1 tolerance=1",
            "step=1 tolerance=4",
            "step=1 tolerance=0.25 filter=footprint mip_bias=-1",
            "step=1 tolerance=0.25 filter=footprint mip_bias=0",
            "step=1 tolerance=0.25 filter=footprint mip_bias=1"
        ]
    );
    let rmse = |k: &str| rows.iter().find(|r| r.0 == k).unwrap().1["rel_rmse"].clone();
    assert_ne!(rmse("step=1 tolerance=0.25"), rmse("step=1 tolerance=4"), "{csv}");
    let filtered = |b: &str| rmse(&format!("step=1 tolerance=0.25 filter=footprint mip_bias={b}"));
    assert_ne!(rmse("step=1 tolerance=0.25"), filtered("-1"), "{csv}");
    assert_ne!(filtered("-1"), filtered("1"), "{csv}");
}

/// `pareto -q` says nothing on stderr (no truth line, no progress) and still reports on stdout.
#[test]
fn quiet_pareto_prints_only_its_report() {
    let scene = root().join("scenes/view_slices/flat_box.ron").display().to_string();
    let out = scratch_dir("voltex-pareto-quiet");
    let args =
        ["pareto", &scene, "--methods", "view-slices", "--planes", "8", "--size", "16x16", "--frames", "1"];
    let run = voltex(&[&args[..], &["--out", s(&out), "-q"]].concat());
    assert!(run.status.success() && run.stderr.is_empty(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stdout).contains("ViewSlices front:"));
    let loud = voltex(&[&args[..], &["--out", s(&out)]].concat());
    assert!(
        String::from_utf8_lossy(&loud.stderr).contains("[1/2"),
        "{}",
        String::from_utf8_lossy(&loud.stderr)
    );
    // `-v` also shows the truth's frame as it renders (issue 32, item 10: the ETA left it out).
    let verbose = voltex(&[&args[..], &["--out", s(&out), "-v"]].concat());
    let err = String::from_utf8_lossy(&verbose.stderr);
    assert!(err.lines().any(|l| l.starts_with("[100%] truth: ")), "{err}");
    std::fs::remove_dir_all(&out).unwrap();
}
