//! A method lives in its folders (`src/methods/<method>/`, `wgsl/<method>/`) and is registered by
//! one line (in `for_each_method!`, `src/methods/knobs.rs`): code elsewhere that names a method
//! (its scene-file name, or its folder as a path: `view_slices::`, `view_slices/`) is counted
//! here per file. Comments, unit tests (`#[cfg(test)]` onwards, `tests.rs`) and the
//! registration list do not count. The counts may only fall: `OUTSIDE` lists what is left to
//! move, and a file that names a method anew, or more often, fails with the lines that do.

use std::collections::BTreeMap;
use std::path::PathBuf;

use voltex::render::MethodKind;

/// Files outside the methods' folders that still name a method, with how many lines do.
/// The goal is an empty list.
const OUTSIDE: &[(&str, usize)] = &[
    // The hypertexture benchmarks (the paper's figures) sit above the methods.
    ("src/bench/hyper.rs", 19),
    ("src/bench/mod.rs", 4),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The registered methods' scene-file names and folders.
fn methods() -> Vec<(String, String)> {
    MethodKind::all().map(|k| (k.to_string(), k.cli_name().replace('-', "_"))).collect()
}

/// Whether `line` (code, not a comment) names a method: its scene-file name as a word, or its
/// folder as a path.
fn names_a_method(line: &str, methods: &[(String, String)]) -> bool {
    let code = line.trim_start();
    if code.starts_with("//") {
        return false;
    }
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    // `w` with no identifier character before it (and none after where `whole`).
    let word = |w: &str, whole: bool| {
        code.match_indices(w).any(|(i, _)| {
            let before = code[..i].chars().next_back().is_none_or(|c| !ident(c));
            let after = code[i + w.len()..].chars().next().is_none_or(|c| !ident(c));
            before && (after || !whole)
        })
    };
    methods.iter().any(|(name, folder)| {
        word(name, true) || word(&format!("{folder}::"), false) || word(&format!("{folder}/"), false)
    })
}

/// Lines naming a method, per file outside the methods' own folders.
fn count() -> BTreeMap<String, Vec<String>> {
    let methods = methods();
    // Every folder under src/methods/ is a method's (volumes' too), and each method's WGSL folder.
    let mut own: Vec<String> = std::fs::read_dir(root().join("src/methods"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| format!("src/methods/{}/", p.file_name().unwrap().to_string_lossy()))
        .collect();
    own.extend(methods.iter().map(|(_, f)| format!("wgsl/{f}/")));
    let mut all = crate::common::files_under(&root().join("src"), &["rs", "wgsl"]);
    all.extend(crate::common::files_under(&root().join("wgsl"), &["rs", "wgsl"]));
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for file in all {
        let rel = file.strip_prefix(root()).unwrap().display().to_string();
        let test_file =
            file.file_name().is_some_and(|n| n == "tests.rs" || n.to_string_lossy().ends_with("_tests.rs"));
        if own.iter().any(|o| rel.starts_with(o)) || test_file {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let mut registration = false;
        for (n, line) in text.lines().enumerate() {
            if line.trim() == "#[cfg(test)]" {
                break;
            }
            // The registration list: `for_each_method!`'s body.
            if line.starts_with("macro_rules! for_each_method") {
                registration = true;
            } else if registration && line.starts_with('}') {
                registration = false;
            }
            if !registration && names_a_method(line, &methods) {
                out.entry(rel.clone()).or_default().push(format!("{rel}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    out
}

#[test]
fn code_outside_a_methods_folders_names_no_method() {
    let found = count();
    let known: BTreeMap<&str, usize> = OUTSIDE.iter().copied().collect();
    let mut more = Vec::new();
    let mut fewer = Vec::new();
    for (file, lines) in &found {
        match known.get(file.as_str()) {
            Some(&k) if lines.len() <= k => {
                if lines.len() < k {
                    fewer.push(format!("{file}: {} (listed {k})", lines.len()));
                }
            }
            _ => more.extend(lines.iter().cloned()),
        }
    }
    for (file, k) in &known {
        if !found.contains_key(*file) {
            fewer.push(format!("{file}: 0 (listed {k})"));
        }
    }
    let table: Vec<String> = found.iter().map(|(f, l)| format!("    (\"{f}\", {}),", l.len())).collect();
    assert!(
        more.is_empty(),
        "code outside the methods' folders names a method (move it into the method's plug-in):\n{}\n\
         (all counts now:\n{})",
        more.join("\n"),
        table.join("\n")
    );
    assert!(fewer.is_empty(), "fewer lines name a method now: lower OUTSIDE to\n{}", fewer.join("\n"));
}

#[test]
fn the_scan_sees_names_and_folders_but_not_comments() {
    let m = methods();
    assert!(m.len() >= 4, "{m:?}");
    assert!(names_a_method("let x = Method::ViewSlices(v);", &m));
    assert!(names_a_method("load(\"view_slices/emit.wgsl\")", &m));
    assert!(names_a_method("use crate::methods::view_slices::Plan;", &m));
    assert!(!names_a_method("/// ViewSlices draws it", &m));
    assert!(!names_a_method("let reference = image();", &m));
    assert!(!names_a_method("let x = MyViewSlicesThing;", &m));
    assert!(!names_a_method("power_preference: wgpu::PowerPreference::HighPerformance,", &m));
}
