//! Every example scene states its error bound against an independent truth (`regress.truth`),
//! so that `voltex regress` can say "right", not only "unchanged" (docs: regression.md).

use std::path::Path;

#[test]
fn every_example_scene_states_a_truth_bound() {
    let files = crate::common::files_under(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"), &["ron"]);
    assert!(files.len() >= 60, "{} scenes", files.len());
    let missing: Vec<String> = files
        .iter()
        .filter(|f| voltex::scene::load(f).unwrap().regress.truth.is_none())
        .map(|f| f.display().to_string())
        .collect();
    assert!(missing.is_empty(), "scenes without `regress: (truth: (max_flip: ..))`:\n{}", missing.join("\n"));
}
