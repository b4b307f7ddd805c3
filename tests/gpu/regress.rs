//! `voltex regress` through the real binary on temporary copies of scenes: pass, regressed, new,
//! `--update`, broken scenes and references, an unwritable output folder, shards merging into one
//! report, and the example scenes under `scenes/` against their committed references.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use voltex::io::Image;
use voltex::regress::{Record, Status};

const BIN: &str = env!("CARGO_BIN_EXE_voltex");

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn example(stem: &str) -> PathBuf {
    root().join("scenes/view_slices").join(stem)
}

/// A fresh folder for a test, removed when the test passes (kept for a look when it fails).
struct Temp(PathBuf);

impl Temp {
    fn new(test: &str) -> Self {
        let d = std::env::temp_dir().join(format!("voltex-regress-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Temp(d)
    }
}

impl std::ops::Deref for Temp {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Copies the example `flat_box.ron` to `dir/name` (with `edit` applied), and its reference to
/// `<stem>.ref.exr` beside it when `with_reference`.
fn flat_box(dir: &Path, name: &str, with_reference: bool, edit: impl Fn(String) -> String) -> PathBuf {
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let text = without_truth(std::fs::read_to_string(example("flat_box.ron")).unwrap());
    std::fs::write(&path, edit(text)).unwrap();
    if with_reference {
        std::fs::copy(example("flat_box.ref.exr"), reference(&path)).unwrap();
    }
    path
}

/// The scene without its `regress.truth` bound: the tests of "unchanged" render no truth.
fn without_truth(text: String) -> String {
    let Some(at) = text.find(", truth: (") else { return text };
    let end = at + text[at..].find(')').unwrap() + 1;
    format!("{}{}", &text[..at], &text[end..])
}

fn same(text: String) -> String {
    text
}

fn reference(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().unwrap().to_string_lossy();
    scene.with_file_name(format!("{stem}.ref.exr"))
}

/// Runs `voltex regress ARGS` (with this checkout's `wgsl/` and `graphs/`).
fn regress(args: &[&Path]) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.arg("regress").args(args).env("VOLTEX_ROOT", root());
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        cmd.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let out = cmd.output().unwrap();
    eprintln!(
        "voltex regress {args:?}: {}\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"), "the binary panicked");
    out
}

fn p(s: &str) -> &Path {
    Path::new(s)
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

fn record(out: &Path, folder: &str) -> Record {
    Record::read(&out.join(folder).join("result.json")).unwrap()
}

fn index(out: &Path) -> String {
    std::fs::read_to_string(out.join("index.html")).unwrap()
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The reference with a bright block painted into it.
fn perturb(path: &Path) {
    let (mut img, _) = voltex::io::exr::read(path).unwrap();
    for y in 40..90 {
        for x in 40..90 {
            img.set(x, y, [4.0, 0.2, 0.2, 1.0]);
        }
    }
    voltex::io::exr::write(path, &img, &[]).unwrap();
}

#[test]
fn unchanged_scene_passes() {
    let dir = Temp::new("pass");
    let scene = flat_box(&dir.join("scenes"), "flat_box.ron", true, same);
    let before = std::fs::read(reference(&scene)).unwrap();
    let out = dir.join("out");
    let run = regress(&[&dir.join("scenes"), p("--out"), &out]);
    assert_eq!(run.status.code(), Some(0));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("flat_box.ron") && stdout.contains("pass") && stdout.contains("GPU ms"),
        "{stdout}"
    );
    assert!(String::from_utf8_lossy(&run.stderr).contains("[1/1] flat_box.ron: pass"));
    let r = record(&out, "flat_box");
    assert_eq!((r.status, r.updated, r.size), (Status::Pass, false, Some([128, 128])));
    assert!(r.flip.unwrap() <= 0.01 && r.rel_rmse.unwrap() <= 0.02, "{r:?}");
    assert!(!r.adapter.is_empty());
    assert_eq!(
        files(&out.join("flat_box")),
        ["actual.exr", "actual.png", "diff.png", "reference.png", "result.json"]
    );
    let html = index(&out);
    assert!(html.contains("flat_box.ron") && html.contains("flat_box/diff.png"), "{html}");
    // The heat map says its mean FLIP and shows its colour scale (issue 32, item 8).
    let mean = format!("FLIP heat map, mean {:.5}", r.flip.unwrap());
    assert!(
        html.contains(&mean) && html.contains("class=\"scale\"") && html.contains("#000004 0.0%"),
        "{html}"
    );
    assert_eq!(std::fs::read(reference(&scene)).unwrap(), before, "a passing reference is never rewritten");
}

#[test]
fn perturbed_reference_regresses() {
    let dir = Temp::new("regressed");
    let scene = flat_box(&dir.join("scenes"), "flat_box.ron", true, same);
    perturb(&reference(&scene));
    let before = std::fs::read(reference(&scene)).unwrap();
    let out = dir.join("out");
    let run = regress(&[&dir.join("scenes"), p("--out"), &out]);
    assert_eq!(run.status.code(), Some(1));
    assert!(text(&run).contains("1 of 1 scene did not pass"), "{}", text(&run));
    let r = record(&out, "flat_box");
    assert_eq!(r.status, Status::Regressed);
    assert!(r.flip.unwrap() > 0.01 && r.rel_rmse.unwrap() > 0.02, "{r:?}");
    assert!(r.message.as_deref().unwrap().contains("mean FLIP"), "{r:?}");
    for f in ["actual.exr", "actual.png", "diff.png", "reference.png"] {
        assert!(out.join("flat_box").join(f).is_file(), "{f}");
    }
    // The heat map is bright where the block was painted, dark elsewhere.
    let (w, _, heat) = voltex::io::png::read_rgba8(&out.join("flat_box/diff.png")).unwrap();
    let lum = |x: usize, y: usize| heat[y * w as usize + x].iter().take(3).map(|&c| c as u32).sum::<u32>();
    assert!(lum(64, 64) > lum(5, 5) + 200, "{} vs {}", lum(64, 64), lum(5, 5));
    assert!(index(&out).contains("regressed"));
    assert_eq!(std::fs::read(reference(&scene)).unwrap(), before, "no reference is written without --update");
}

#[test]
fn new_scene_fails_and_writes_nothing_beside_it() {
    let dir = Temp::new("new");
    let scenes = dir.join("scenes");
    flat_box(&scenes, "flat_box.ron", false, same);
    let out = dir.join("out");
    let run = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(run.status.code(), Some(1));
    let r = record(&out, "flat_box");
    assert_eq!((r.status, r.updated), (Status::New, false));
    assert!(r.message.as_deref().unwrap().contains("no reference image"), "{r:?}");
    assert_eq!(files(&scenes), ["flat_box.ron"], "nothing written beside the scene");
    assert_eq!(files(&out.join("flat_box")), ["actual.exr", "actual.png", "result.json"]);
}

#[test]
fn update_writes_new_and_regressed_references_only() {
    let dir = Temp::new("update");
    let scenes = dir.join("scenes");
    let new = flat_box(&scenes, "a_new.ron", false, same);
    let regressed = flat_box(&scenes, "b_regressed.ron", true, same);
    let passing = flat_box(&scenes, "c_passing.ron", true, same);
    perturb(&reference(&regressed));
    let perturbed = std::fs::read(reference(&regressed)).unwrap();
    let passing_bytes = std::fs::read(reference(&passing)).unwrap();
    let passing_time = std::fs::metadata(reference(&passing)).unwrap().modified().unwrap();
    let out = dir.join("out");
    let run = regress(&[&scenes, p("--out"), &out, p("--update")]);
    assert_eq!(run.status.code(), Some(0), "updated scenes do not fail the run");
    assert!(reference(&new).is_file());
    assert_ne!(std::fs::read(reference(&regressed)).unwrap(), perturbed);
    assert_eq!(std::fs::read(reference(&passing)).unwrap(), passing_bytes);
    assert_eq!(std::fs::metadata(reference(&passing)).unwrap().modified().unwrap(), passing_time);
    assert_eq!((record(&out, "a_new").status, record(&out, "a_new").updated), (Status::New, true));
    assert_eq!(record(&out, "b_regressed").status, Status::Regressed);
    assert!(record(&out, "b_regressed").updated);
    assert!(!record(&out, "c_passing").updated);
    let (_, meta) = voltex::io::exr::read(&reference(&new)).unwrap();
    assert!(meta.iter().any(|(k, _)| k == "voltex_adapter"), "{meta:?}");
    assert!(files(&scenes).iter().all(|f| !f.contains(".tmp")), "{:?}", files(&scenes));

    let again = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(again.status.code(), Some(0));
    for f in ["a_new", "b_regressed", "c_passing"] {
        assert_eq!(record(&out, f).status, Status::Pass, "{f}");
    }
}

#[test]
fn broken_scene_is_reported_and_the_others_render() {
    let dir = Temp::new("broken-scene");
    let scenes = dir.join("scenes");
    let broken = flat_box(&scenes, "broken.ron", false, |t| t.replace("ambient: 1.0,", "ambient: 7.0,"));
    flat_box(&scenes, "good.ron", true, same);
    // A render graph in the tree is not a scene.
    std::fs::copy(root().join("graphs/frame.ron"), scenes.join("graph.ron")).unwrap();
    let out = dir.join("out");
    let run = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(run.status.code(), Some(3), "broken input");
    let text_of_scene = std::fs::read_to_string(&broken).unwrap();
    let line = text_of_scene.lines().position(|l| l.contains("ambient: 7.0")).unwrap() + 1;
    let loc = format!("{}:{line}:14", broken.display());
    let r = record(&out, "broken");
    assert_eq!(r.status, Status::BrokenScene);
    assert!(r.message.as_deref().unwrap().starts_with(&loc), "{r:?} should start with {loc}");
    assert!(text(&run).contains(&loc), "the error is printed too");
    assert_eq!(files(&out.join("broken")), ["result.json"]);
    assert_eq!(record(&out, "good").status, Status::Pass);
    assert!(!out.join("graph").exists() && !text(&run).contains("graph.ron"));
    assert!(index(&out).contains("broken scene"));
}

/// An EXR with a single `Y` channel: readable, but not an RGB image.
fn write_luminance_exr(path: &Path) {
    use exr::prelude::*;
    let channels = SpecificChannels::build().with_channel("Y").with_pixel_fn(|_| (0.5f32,));
    Image::from_channels((128, 128), channels).write().to_file(path).unwrap();
}

#[test]
fn wrong_size_garbage_and_channel_less_references_are_broken() {
    let dir = Temp::new("broken-ref");
    let scenes = dir.join("scenes");
    let small = flat_box(&scenes, "small.ron", false, same);
    voltex::io::exr::write(&reference(&small), &Image::filled(16, 16, [0.5; 4]), &[]).unwrap();
    let garbage = flat_box(&scenes, "garbage.ron", false, same);
    std::fs::write(reference(&garbage), "version https://git-lfs.github.com/spec/v1\n").unwrap();
    let grey = flat_box(&scenes, "grey.ron", false, same);
    write_luminance_exr(&reference(&grey));
    let out = dir.join("out");
    let run = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(run.status.code(), Some(3), "broken references");
    let r = record(&out, "small");
    assert_eq!(r.status, Status::BrokenReference);
    let m = r.message.unwrap();
    assert!(m.contains("reference is 16x16, the render is 128x128"), "{m}");
    for name in ["garbage", "grey"] {
        let r = record(&out, name);
        assert_eq!(r.status, Status::BrokenReference, "{name}");
        let m = r.message.unwrap();
        assert!(m.contains(&format!("{name}.ref.exr")) && m.contains("cannot read"), "{m}");
        assert!(out.join(name).join("actual.png").is_file(), "the scene still renders");
    }

    // --update rewrites a reference of another size, never one it cannot read.
    let garbage_bytes = std::fs::read(reference(&garbage)).unwrap();
    let run = regress(&[&scenes, p("--out"), &out, p("--update")]);
    assert_eq!(run.status.code(), Some(3), "the unreadable reference stays broken");
    assert!(record(&out, "small").updated);
    assert_eq!(voltex::io::exr::read(&reference(&small)).unwrap().0.width, 128);
    assert!(!record(&out, "garbage").updated && !record(&out, "grey").updated);
    assert_eq!(std::fs::read(reference(&garbage)).unwrap(), garbage_bytes);
}

#[test]
fn render_size_from_flag_then_regress_field_then_output() {
    let dir = Temp::new("size");
    let scenes = dir.join("scenes");
    flat_box(&scenes, "field.ron", false, |t| t.replace("size: (128, 128)", "size: (40, 30)"));
    flat_box(&scenes, "output.ron", false, |t| {
        t.replace("    regress: (size: (128, 128)),", "")
            .replace("(width: 128, height: 128)", "(width: 24, height: 24)")
    });
    let out = dir.join("out");
    assert_eq!(regress(&[&scenes, p("--out"), &out]).status.code(), Some(1), "new scenes");
    assert_eq!(record(&out, "field").size, Some([40, 30]));
    assert_eq!(record(&out, "output").size, Some([24, 24]));
    let run = regress(&[&scenes, p("--out"), &out, p("--size"), p("20x10")]);
    assert_eq!(run.status.code(), Some(1), "still new");
    assert_eq!(record(&out, "field").size, Some([20, 10]));
    assert_eq!(record(&out, "output").size, Some([20, 10]));
}

#[test]
fn unwritable_output_folder_fails_before_rendering() {
    let dir = Temp::new("unwritable");
    let scenes = dir.join("scenes");
    flat_box(&scenes, "flat_box.ron", true, same);
    std::fs::write(dir.join("file"), "in the way").unwrap();
    let out = dir.join("file/out");
    let run = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(run.status.code(), Some(3));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.starts_with("error: ") && err.contains("cannot create the output folder"), "{err}");
    assert!(err.contains(&out.display().to_string()), "{err}");
    assert!(!err.contains("[1/1]"), "nothing rendered: {err}");
    assert!(run.stdout.is_empty());
}

#[test]
fn shards_merge_into_one_report() {
    let dir = Temp::new("shards");
    let scenes = dir.join("scenes");
    for name in ["a.ron", "c.ron", "sub/b.ron"] {
        flat_box(&scenes, name, true, same);
    }
    let out = dir.join("out");
    // Sorted: a.ron, c.ron, sub/b.ron; their estimates are equal, so the plan deals them out in
    // order: shard 1/2 takes a.ron and sub/b.ron, shard 2/2 c.ron.
    let first = regress(&[&scenes, p("--out"), &out, p("--shard"), p("1/2")]);
    let stdout = String::from_utf8_lossy(&first.stdout);
    assert!(
        stdout.contains("a.ron") && stdout.contains("sub/b.ron") && !stdout.contains("\nc.ron "),
        "{stdout}"
    );
    assert!(stdout.contains("note: shard 2/2: missing"), "{stdout}");
    let second = regress(&[&scenes, p("--out"), &out, p("--shard"), p("2/2"), p("--jobs"), p("2")]);
    assert_eq!((first.status.code(), second.status.code()), (Some(0), Some(0)));
    let html = index(&out);
    for s in ["a.ron", "c.ron", "sub/b.ron"] {
        assert!(html.contains(s), "{s} in the merged report");
    }
    assert!(html.contains("sub/b/actual.png"));

    // Folders of shards run elsewhere, copied together, then the report alone.
    let merged = dir.join("merged");
    common::copy_dir(&out, &merged);
    std::fs::remove_file(merged.join("index.html")).unwrap();
    let run = regress(&[p("--report-only"), &merged]);
    assert_eq!(run.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&run.stdout).contains("3 scenes: 3 pass"));
    let html = index(&merged);
    for link in html.split("src=\"").skip(1).map(|s| &s[..s.find('"').unwrap()]) {
        assert!(merged.join(link).is_file(), "{link}");
    }
    assert_eq!(html.matches("<img").count(), 9);

    // A failing record makes --report-only fail too.
    let mut r = record(&merged, "c");
    r.status = Status::Regressed;
    r.write(&merged.join("c")).unwrap();
    assert_eq!(regress(&[p("--report-only"), &merged]).status.code(), Some(1));
}

#[test]
fn results_travel_and_current_scenes_are_not_rendered_again() {
    let dir = Temp::new("resume");
    let scenes = dir.join("scenes");
    for name in ["a.ron", "c.ron", "sub/b.ron"] {
        flat_box(&scenes, name, true, same);
    }
    let out = dir.join("out");
    let first = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(first.status.code(), Some(0));
    // Paths relative to the suite root, so that records from other machines merge.
    let b = record(&out, "sub/b");
    assert_eq!((b.scene_path.as_str(), b.reference_path.as_str()), ("sub/b.ron", "sub/b.ref.exr"));
    assert!(!b.suite.is_empty() && !b.inputs.is_empty());
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(junit.contains("tests=\"3\" failures=\"0\" errors=\"0\""), "{junit}");
    assert!(junit.contains("<testcase classname=\"sub\" name=\"b.ron\""), "{junit}");

    // Nothing changed: nothing is rendered; a changed scene is, and --force renders all.
    let before = std::fs::read(out.join("a/result.json")).unwrap();
    let again = regress(&[&scenes, p("--out"), &out]);
    assert_eq!(again.status.code(), Some(0));
    assert!(text(&again).contains("3 scene(s) current"), "{}", text(&again));
    assert_eq!(std::fs::read(out.join("a/result.json")).unwrap(), before);
    let c = scenes.join("c.ron");
    std::fs::write(&c, std::fs::read_to_string(&c).unwrap() + "// changed\n").unwrap();
    perturb(&reference(&scenes.join("a.ron")));
    let changed = regress(&[&scenes, p("--out"), &out, p("--junit"), &dir.join("j.xml")]);
    assert_eq!(changed.status.code(), Some(1), "a's reference was perturbed");
    assert!(text(&changed).contains("1 scene(s) current"), "{}", text(&changed));
    assert_eq!(record(&out, "a").status, Status::Regressed);
    let junit = std::fs::read_to_string(dir.join("j.xml")).unwrap();
    assert!(junit.contains("<failure type=\"regressed\""), "{junit}");
    // --json: the summary for scripts on stdout, -q: no progress.
    let forced = regress(&[&scenes, p("--out"), &out, p("--force"), p("--json"), p("-q")]);
    assert_eq!(forced.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&forced.stdout).unwrap();
    assert_eq!((json["verdict"].as_str(), json["exit_code"].as_u64()), (Some("regressions"), Some(1)));
    assert_eq!((json["counts"]["regressed"].as_u64(), json["counts"]["pass"].as_u64()), (Some(1), Some(2)));
    assert_eq!(json["counts"]["current_not_rendered"].as_u64(), Some(0), "--force renders all");
    assert_eq!(json["failed"][0]["scene"].as_str(), Some("a.ron"));
    assert!(!String::from_utf8_lossy(&forced.stderr).contains("[1/3"), "-q: no progress");
}

#[test]
fn merge_reports_missing_shards_duplicates_and_other_suites() {
    let dir = Temp::new("merge");
    let scenes = dir.join("scenes");
    for name in ["a.ron", "c.ron", "sub/b.ron"] {
        flat_box(&scenes, name, true, same);
    }
    // The plan, without rendering: equal estimates deal the scenes out in order.
    let plan = regress(&[&scenes, p("--out"), &dir.join("out"), p("--plan-shards"), p("2")]);
    assert_eq!(plan.status.code(), Some(0));
    let plan = String::from_utf8_lossy(&plan.stdout).into_owned();
    assert!(plan.contains("predicted makespan") && plan.contains("estimate"), "{plan}");
    assert!(!dir.join("out").exists(), "--plan-shards renders and writes nothing");

    // One of two shards: its own run passes, the merge names the missing shard.
    let one = dir.join("one");
    assert_eq!(regress(&[&scenes, p("--out"), &one, p("--shard"), p("2/2")]).status.code(), Some(0));
    let merge = regress(&[p("--report-only"), &one]);
    assert_eq!(merge.status.code(), Some(3), "a merge with problems is broken input");
    assert!(text(&merge).contains("shard 1/2: missing"), "{}", text(&merge));
    assert!(std::fs::read_to_string(one.join("junit.xml")).unwrap().contains("name=\"shard 1/2\""));
    // A shard that died: its manifest never says finished.
    let died = dir.join("died");
    assert_eq!(regress(&[&scenes, p("--out"), &died, p("--shard"), p("1/2")]).status.code(), Some(0));
    common::copy_dir(&one, &died);
    let manifest = died.join(".voltex/shard-1-of-2.json");
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    m["finished_unix"] = serde_json::Value::Null;
    std::fs::write(&manifest, m.to_string()).unwrap();
    std::fs::remove_dir_all(died.join("a")).unwrap();
    let merge = regress(&[p("--report-only"), &died]);
    assert!(
        text(&merge).contains("shard 1/2: started on") && text(&merge).contains("did not finish"),
        "{}",
        text(&merge)
    );
    assert_eq!(merge.status.code(), Some(3));

    // Both shards: the merge passes; shard folders copied side by side are duplicates.
    let both = dir.join("both");
    common::copy_dir(&one, &both);
    assert_eq!(regress(&[&scenes, p("--out"), &both, p("--shard"), p("1/2")]).status.code(), Some(0));
    assert_eq!(regress(&[p("--report-only"), &both]).status.code(), Some(0));
    common::copy_dir(&one, &both.join("copied"));
    let merge = regress(&[p("--report-only"), &both]);
    assert_eq!(merge.status.code(), Some(3));
    assert!(text(&merge).contains("c.ron: duplicate records in c, copied/c"), "{}", text(&merge));
    std::fs::remove_dir_all(both.join("copied")).unwrap();
    // A record of another suite.
    let mut r = record(&both, "c");
    r.suite = "0123456789abcdef".into();
    r.write(&both.join("c")).unwrap();
    let merge = regress(&[p("--report-only"), &both]);
    assert_eq!(merge.status.code(), Some(3));
    assert!(text(&merge).contains("results from different suites"), "{}", text(&merge));
}

#[test]
fn bad_arguments() {
    let dir = Temp::new("args");
    let run = regress(&[&dir.join("missing")]);
    assert_eq!(run.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&run.stderr).contains("missing"));
    let run = regress(&[&dir]);
    assert_eq!(run.status.code(), Some(3), "a folder without scenes");
    assert!(String::from_utf8_lossy(&run.stderr).contains("no scene files"));
    for shard in ["0/2", "3/2", "x"] {
        let run = regress(&[&dir, p("--shard"), p(shard)]);
        assert_ne!(run.status.code(), Some(0));
        assert!(String::from_utf8_lossy(&run.stderr).contains("expected a shard i/n"));
    }
    let run = regress(&[&dir, p("--shard"), p("auto/2")]);
    assert_ne!(run.status.code(), Some(0));
    assert!(
        String::from_utf8_lossy(&run.stderr).contains("neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX")
    );
    assert_ne!(regress(&[&dir, p("--jobs"), p("0")]).status.code(), Some(0));
    assert_eq!(regress(&[p("--report-only"), &dir]).status.code(), Some(3), "no records");
}

#[test]
fn regress_field_is_checked_at_its_position() {
    let base = without_truth(std::fs::read_to_string(example("flat_box.ron")).unwrap());
    let parse = |regress: &str| {
        let text = base.replace("regress: (size: (128, 128)),", regress);
        voltex::scene::parse(&text, Path::new("s.ron")).map(|s| s.regress).map_err(|e| e.to_string())
    };
    let r = parse("regress: (size: (64, 32), max_rel_rmse: 0.5),").unwrap();
    assert_eq!((r.size, r.max_flip, r.max_rel_rmse), (Some([64, 32]), 0.01, 0.5));
    let r = parse("").unwrap();
    assert_eq!((r.size, r.max_flip, r.max_rel_rmse), (None, 0.01, 0.02));
    for (field, words) in [
        ("regress: (size: (0, 32)),", &["s.ron:6:22", "output size"][..]),
        ("regress: (max_flip: 1.5),", &["s.ron:6:25", "[0, 1]"]),
        ("regress: (max_rel_rmse: -1),", &["s.ron:6:29", ">= 0"]),
        ("regress: (tolerance: 1),", &["s.ron:6:15", "tolerance", "max_flip"]),
    ] {
        let e = parse(field).unwrap_err();
        assert!(words.iter().all(|w| e.contains(w)), "{field}: {e}");
    }
}

/// The example scenes against their committed references and their truth bounds
/// (`regress.truth`): a scene that changed, or that left its bound, fails `cargo test`. About
/// 3.5 minutes on software Vulkan with two jobs (2 cores), most of it the hypertextures' truths.
#[test]
fn example_scenes_match_their_references_and_truths() {
    let dir = Temp::new("examples");
    let out = dir.join("out");
    let start = std::time::Instant::now();
    let run = regress(&[&root().join("scenes"), p("--out"), &out, p("--jobs"), p("2")]);
    eprintln!("voltex regress scenes/: {:.1} s", start.elapsed().as_secs_f64());
    assert_eq!(run.status.code(), Some(0), "see {}", out.join("index.html").display());
    // Every record was measured against its truth.
    let (found, bad) = voltex::regress::record::collect(&out).unwrap();
    assert!(bad.is_empty(), "{bad:?}");
    let unchecked: Vec<&str> = found
        .iter()
        .filter(|f| f.record.truth_flip.is_none() || f.record.max_truth_flip.is_none())
        .map(|f| f.record.scene.as_str())
        .collect();
    assert!(
        found.len() >= 60 && unchecked.is_empty(),
        "{} records; without a truth: {unchecked:?}",
        found.len()
    );
}

/// `regress.truth`: the render is measured against the scene's independent truth (the Reference
/// method here); beyond the bound the scene fails and `--update` writes no reference; within
/// it, `--update` writes one and the record holds the measured FLIP.
#[test]
fn truth_bound_fails_a_wrong_render_and_refuses_update() {
    let dir = Temp::new("truth");
    let bound = |max: &str| {
        let max = max.to_string();
        move |t: String| {
            t.replace(
                "regress: (size: (128, 128))",
                &format!("regress: (size: (32, 32), truth: (max_flip: {max}))"),
            )
        }
    };
    let tight = flat_box(&dir.join("tight"), "flat_box.ron", false, bound("0.0"));
    let out = dir.join("out");
    let run = regress(&[p("--update"), &dir.join("tight"), p("--out"), &out]);
    assert_eq!(run.status.code(), Some(1), "{}", text(&run));
    let r = record(&out, "flat_box");
    assert!(r.truth_flip.is_some_and(|f| f > 0.0), "{r:?}");
    assert_eq!(r.max_truth_flip, Some(0.0));
    let m = r.message.clone().unwrap_or_default();
    assert!(m.contains("against the truth > 0") && m.contains("--update refused"), "{m}");
    assert!(!r.updated && !reference(&tight).exists(), "no reference from a render beyond its truth bound");
    assert!(files(&out.join("flat_box")).contains(&"truth.png".to_string()));

    let loose = flat_box(&dir.join("loose"), "flat_box.ron", false, bound("0.5"));
    let out = dir.join("out2");
    let run = regress(&[p("--update"), &dir.join("loose"), p("--out"), &out]);
    assert!(run.status.success(), "{}", text(&run));
    let r = record(&out, "flat_box");
    assert!(r.updated && reference(&loose).exists(), "{r:?}");
    let flip = r.truth_flip.unwrap();
    assert!(flip > 0.0 && flip < 0.5, "{flip}");
    assert!(text(&run).contains(&format!("{flip:.5}")), "the table shows the truth FLIP: {}", text(&run));
}

/// `regress.supersample`: the regression render (so the reference `--update` writes) and its
/// truth both average N x N samples a pixel, exactly as `render --supersample N` does.
#[test]
fn supersample_averages_the_render_and_its_truth() {
    let dir = Temp::new("supersample");
    let scene = flat_box(&dir.join("s"), "flat_box.ron", false, |t| {
        t.replace(
            "regress: (size: (128, 128))",
            "regress: (size: (16, 16), supersample: 2, truth: (max_flip: 0.5))",
        )
    });
    let out = dir.join("out");
    let run = regress(&[p("--update"), &dir.join("s"), p("--out"), &out]);
    assert!(run.status.success(), "{}", text(&run));
    let render = |extra: &[&str], name: &str| {
        let file = dir.join(name);
        let mut cmd = Command::new(BIN);
        cmd.args(["render", "--size", "16x16", "--supersample", "2", "-o"])
            .arg(&file)
            .arg(&scene)
            .args(extra);
        let run = cmd.env("VOLTEX_ROOT", root()).output().unwrap();
        assert!(run.status.success(), "{}", text(&run));
        voltex::io::exr::read(&file).unwrap().0
    };
    let (written, _) = voltex::io::exr::read(&reference(&scene)).unwrap();
    let supersampled = render(&[], "ss.exr");
    assert_eq!(voltex::metrics::max_abs_diff(&written, &supersampled).unwrap(), 0.0);
    let truth = render(&["--method", "reference"], "truth.exr");
    let flip = voltex::metrics::flip(&written, &truth).unwrap().mean;
    let r = record(&out, "flat_box");
    assert!((r.truth_flip.unwrap() - flip).abs() < 1e-9, "{r:?} against {flip}");
}
