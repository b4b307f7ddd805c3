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
