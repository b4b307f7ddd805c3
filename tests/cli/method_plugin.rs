//! The test-only method (`tests/method/probe_slices/`, registered by one line under the
//! `test-method` feature) through the binary: `--method`, `plan` and `pareto --methods` know it
//! with no edit outside its folder.

use crate::common::{ok, root, s, scratch_dir, voltex};

fn scene() -> String {
    root().join("scenes/view_slices/flat_box.ron").display().to_string()
}

#[test]
fn the_test_method_is_a_command_line_method() {
    let help = ok(voltex(&["render", "--help"]));
    assert!(help.contains("probe-slices"), "--method lists it: {help}");
    let plan =
        ok(voltex(&["plan", &scene(), "--method", "probe-slices", "--planes", "12", "--size", "32x32"]));
    assert!(plan.contains("ProbeSlices (ViewSlices planes 12"), "{plan}");
}

#[test]
fn pareto_sweeps_the_test_method() {
    let out = scratch_dir("voltex-probe-pareto");
    let args = ["--methods", "probe-slices", "--planes", "4,8", "--size", "16x16", "--frames", "1"];
    ok(voltex(&[&["pareto", &scene(), "--out", s(&out)][..], &args[..]].concat()));
    let csv = std::fs::read_to_string(out.join("pareto.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().filter(|l| l.starts_with("ProbeSlices,")).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// Names the registry does not know are refused before any work, saying what is expected.
#[test]
fn unknown_method_and_truth_names_are_refused_with_the_known_ones() {
    let out = voltex(&["plan", &scene(), "--method", "ray-march"]);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() && err.contains("view-slices") && err.contains("reference"), "{err}");
    for (truth, words) in [
        (
            "axis-slices",
            &["`axis-slices`: expected", "reference", "view-slices:PLANES", "ray-march:STEP"][..],
        ),
        ("view-slices:0", &["`0`: expected a plane count in 1..="][..]),
        ("reference:2", &["the Reference takes no argument"][..]),
        ("ray-march:-1", &["`-1`: expected a positive step"][..]),
    ] {
        let out = voltex(&["pareto", &scene(), "--truth", truth, "--frames", "1"]);
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!out.status.success(), "{truth}: {err}");
        for w in words {
            assert!(err.contains(w), "{truth}: expected {w:?} in {err}");
        }
    }
}
