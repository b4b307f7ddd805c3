//! `voltex export` through the binary: a scene's texels written as VDB files, and bad input (an
//! unwritable output folder, a name that is no file name, a texel too large, an unknown
//! `--only`, a bad option) failing with status 1, a message naming what is wrong, and nothing
//! written.

use crate::common;

use common::{entries, stderr, voltex};

use std::path::PathBuf;

fn temp(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voltex-export-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn flat_box() -> String {
    std::fs::read_to_string(common::root().join("scenes/view_slices/flat_box.ron")).unwrap()
}

#[track_caller]
fn fails(out: &std::process::Output, words: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "stderr:\n{err}");
    assert!(err.starts_with("error: ") && !err.contains("panicked"), "stderr:\n{err}");
    for w in words {
        assert!(err.contains(w), "expected {w:?} in:\n{err}");
    }
}

#[test]
fn export_writes_one_vdb_per_texel_into_a_new_folder() {
    let dir = temp("ok");
    let scene = common::root().join("scenes/view_slices/flat_box.ron");
    let out = dir.join("vdb");
    let run = voltex(&["export", scene.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let progress = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(progress.contains("[1/1] texel \"fog\" 8x8x8: "), "{progress}");
    let text = common::ok(run);
    assert!(text.contains("fog.vdb") && text.contains("8x8x8, 512 active voxels"), "{text}");
    assert_eq!(entries(&out), ["fog.vdb"]);
    let file = std::fs::File::open(out.join("fog.vdb")).unwrap();
    let mut r = vdb_rs::VdbReader::new(std::io::BufReader::new(file)).unwrap();
    let mut names = r.available_grids();
    names.sort();
    assert_eq!(names, ["Cd", "density"]);
    assert_eq!(r.read_grid::<f32>("density").unwrap().iter().count(), 512);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_exports_fail_cleanly_and_write_nothing() {
    let dir = temp("bad");
    let out = dir.join("out");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let scene = write("box.ron", &flat_box());
    let o = out.to_str().unwrap();
    // An output "folder" below a regular file.
    let file = write("file.txt", "not a folder");
    let below = format!("{file}/sub");
    fails(&voltex(&["export", &scene, "--out", &below]), &[&below, "cannot make the output folder"]);
    fails(&voltex(&["export", &scene, "--out", &file]), &[&file, "not a folder"]);
    // A texel whose name cannot be a file name, and one too large to read back.
    let slash = write("slash.ron", &flat_box().replace("\"fog\"", "\"a/b\""));
    fails(&voltex(&["export", &slash, "--out", o]), &["slash.ron", "texel \"a/b\"", "is not a file name"]);
    let big = write("big.ron", &flat_box().replace("resolution: (8, 8, 8)", "resolution: (1024, 1024, 128)"));
    fails(&voltex(&["export", &big, "--out", o]), &["big.ron", "134217728 voxels", "lower its resolution"]);
    // Unknown names and bad options.
    fails(&voltex(&["export", &scene, "--out", o, "--only", "moss"]), &["--only \"moss\"", "fog"]);
    fails(&voltex(&["export", &scene, "--out", o, "--resolution", "0"]), &["--resolution 0"]);
    fails(&voltex(&["export", &scene, "--out", o, "--time", "NaN"]), &["--time NaN"]);
    assert!(!out.exists(), "the output folder was made: {:?}", entries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}
