//! Every example scene states its error bound against an independent truth (`regress.truth`),
//! so that `voltex regress` can say "right", not only "unchanged" (docs: regression.md).

use std::path::{Path, PathBuf};

fn scenes(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            scenes(&p, out);
        } else if p.extension().is_some_and(|x| x == "ron") {
            out.push(p);
        }
    }
}

#[test]
fn every_example_scene_states_a_truth_bound() {
    let mut files = Vec::new();
    scenes(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"), &mut files);
    assert!(files.len() >= 60, "{} scenes", files.len());
    let missing: Vec<String> = files
        .iter()
        .filter(|f| voltex::scene::load(f).unwrap().regress.truth.is_none())
        .map(|f| f.display().to_string())
        .collect();
    assert!(missing.is_empty(), "scenes without `regress: (truth: (max_flip: ..))`:\n{}", missing.join("\n"));
}
