//! The first hour with voltex (issue 32, items 7 and 10): what `--help` says of a scene argument
//! and of the preview's keys, and `plan`'s pruned section at a length one can read.

use crate::common::{ok, root, voltex};

/// Every subcommand that takes a scene says what it may be; the preview's help points at the
/// page that lists its keys (it pointed at the README, which does not).
#[test]
fn scene_arguments_have_help_and_the_preview_points_at_its_keys() {
    for cmd in ["render", "preview", "plan", "pareto", "bake", "export"] {
        let help = ok(voltex(&[cmd, "--help"]));
        // The entry's first line, and the next (clap's long help puts the text under the name).
        let at = help.find("  <SCENE>").unwrap_or_else(|| panic!("{cmd}: no <SCENE>:\n{help}"));
        let entry: String = help[at..].lines().take(2).collect();
        assert!(entry.contains("A scene file (.ron), or an asset"), "{cmd}: {entry:?}\n{help}");
    }
    let help = ok(voltex(&["preview", "--help"]));
    assert!(help.contains("docs/src/preview.md") && !help.contains("the README"), "{help}");
    let page = std::fs::read_to_string(root().join("docs/src/preview.md")).unwrap();
    assert!(page.contains("| `M`") || page.contains("`M`"), "docs/src/preview.md lists the keys");
}

/// A one-object scene's plan counts the pruned passes and resources by reason (it printed 35+
/// lines, one per pass of every method the scene does not use); `--verbose` lists them.
#[test]
fn plan_counts_what_it_pruned_and_verbose_lists_it() {
    let scene = root().join("scenes/shell_march/torus_egg.ron").display().to_string();
    let section = |text: &str| -> Vec<String> {
        let from = text.find("\npruned:\n").expect("a pruned section") + 9;
        text[from..].lines().take_while(|l| !l.is_empty()).map(str::to_string).collect()
    };
    let short = section(&ok(voltex(&["plan", &scene, "--size", "32x32"])));
    assert!(short.len() <= 6, "{short:#?}");
    assert!(short.iter().any(|l| l.contains("pass(es) of methods and object kinds this scene does not use")));
    let long = section(&ok(voltex(&["plan", &scene, "--size", "32x32", "--verbose"])));
    assert!(
        long.iter().any(|l| l.contains("pass trace_reference: no object matches Reference")),
        "{long:#?}"
    );
    let counted: usize = short.iter().filter_map(|l| l.trim().split(' ').next()?.parse::<usize>().ok()).sum();
    assert_eq!(counted, long.len(), "the counts add up to the lines --verbose lists");
}

/// `render -q` prints nothing on stdout and still writes its images; `-v` adds the wall times of
/// its stages; `import -q` does not print the written path (issue 32, item 7: `-q` was on bake,
/// export and regress only).
#[test]
fn render_and_import_take_quiet_and_render_verbose() {
    let dir = crate::common::scratch_dir("voltex-quiet");
    let scene = root().join("scenes/view_slices/flat_box.ron").display().to_string();
    let out = dir.join("q.exr");
    let quiet = voltex(&["render", &scene, "--size", "16x16", "-o", crate::common::s(&out), "-q"]);
    assert!(quiet.status.success() && quiet.stdout.is_empty(), "{}", String::from_utf8_lossy(&quiet.stdout));
    assert!(out.exists() && out.with_extension("png").exists());
    let loud = ok(voltex(&["render", &scene, "--size", "16x16", "-o", crate::common::s(&out), "--verbose"]));
    assert!(loud.contains("wall: planned") && loud.contains("written"), "{loud}");
    let both = voltex(&["render", &scene, "-q", "-v"]);
    assert!(!both.status.success(), "--quiet and --verbose conflict");
    let mesh = root().join("scenes/view_slices/meshes/dome.glb");
    let imported = dir.join("dome.ron");
    let run = voltex(&["import", crate::common::s(&mesh), "-o", crate::common::s(&imported), "-q"]);
    assert!(run.status.success() && run.stdout.is_empty() && imported.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `plan -q` is a silent check (the exit status says whether the scene plans); `bake` and
/// `export` take `-v` beside their `-q` (issue 32, item 7: `-q/-v` everywhere).
#[test]
fn plan_takes_quiet_and_bake_and_export_take_verbose() {
    let scene = root().join("scenes/view_slices/flat_box.ron").display().to_string();
    let quiet = voltex(&["plan", &scene, "-q"]);
    assert!(quiet.status.success() && quiet.stdout.is_empty(), "{}", String::from_utf8_lossy(&quiet.stdout));
    let dir = crate::common::scratch_dir("voltex-plan-quiet");
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, "Scene(nodes: 3)").unwrap();
    let failed = voltex(&["plan", crate::common::s(&bad), "-q"]);
    assert!(!failed.status.success() && crate::common::stderr(&failed).contains("bad.ron"));
    for cmd in ["bake", "export"] {
        let out = dir.join(cmd);
        let run = voltex(&[cmd, &scene, "--out", crate::common::s(&out), "-v"]);
        assert!(run.status.success(), "{cmd} -v: {}", crate::common::stderr(&run));
        assert!(crate::common::stderr(&run).contains("[1/1"), "{cmd} -v: {}", crate::common::stderr(&run));
        assert!(!voltex(&[cmd, &scene, "-q", "-v"]).status.success(), "{cmd}: -q and -v conflict");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A long render says how far its frame is (issue 32, item 7: a 20 s render printed nothing):
/// with `--verbose` (or on a terminal) the frame is rendered in steps, a line at each tenth of
/// its units of work, and the image is the one a single submission makes, bit for bit; the
/// printed pass list names each pass once, as without steps.
#[test]
fn a_verbose_render_shows_its_progress_and_the_same_image() {
    let dir = crate::common::scratch_dir("voltex-render-progress");
    let scene = root().join("scenes/shell_march/torus_egg.ron").display().to_string();
    let (plain, stepped) = (dir.join("plain.exr"), dir.join("stepped.exr"));
    let args = ["render", &scene, "--method", "reference", "--size", "48x48", "-o"];
    let quiet = voltex(&[&args[..], &[crate::common::s(&plain), "-q"]].concat());
    assert!(quiet.status.success() && quiet.stderr.is_empty(), "{}", crate::common::stderr(&quiet));
    let loud = voltex(&[&args[..], &[crate::common::s(&stepped), "-v"]].concat());
    let (out, err) = (ok(loud.clone()), crate::common::stderr(&loud));
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("] frame: ") && l.contains(" units")).collect();
    assert!(lines.last().is_some_and(|l| l.starts_with("[100%]")), "{err}");
    assert_eq!(out.matches("  trace_reference ").count(), 1, "{out}");
    let read = |p: &std::path::Path| voltex::io::exr::read(p).unwrap().0;
    let (a, b) = (read(&plain), read(&stepped));
    let bits = |i: &voltex::io::Image| i.pixels.iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b), "the stepped frame is the single submission's");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An error at a position shows the source line with carets under the word there, below the
/// `error: file:line:col: message` line it always had (issue 32, item 4: annotated errors); a
/// line too long to quote (a minified file) is left out.
#[test]
fn errors_show_the_source_line_with_a_caret() {
    let dir = crate::common::scratch_dir("voltex-caret");
    let text = std::fs::read_to_string(root().join("scenes/view_slices/flat_box.ron")).unwrap();
    let bad = text.replacen("opacity_length", "opacity_lenght", 1);
    let scene = dir.join("typo.ron");
    std::fs::write(&scene, &bad).unwrap();
    let out = voltex(&["plan", crate::common::s(&scene)]);
    assert_eq!(out.status.code(), Some(1));
    let err = crate::common::stderr(&out);
    let (line, col) =
        bad.lines().enumerate().find_map(|(n, l)| l.find("opacity_lenght").map(|c| (n + 1, c + 1))).unwrap();
    let head = format!("error: {}:{line}:{col}: ", scene.display());
    assert!(err.starts_with(&head), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    let quoted = lines.iter().position(|l| l.ends_with(bad.lines().nth(line - 1).unwrap())).expect(&err);
    let (gutter, source) = lines[quoted].split_once(" | ").unwrap();
    assert_eq!(gutter.trim(), line.to_string(), "{err}");
    let carets = lines[quoted + 1];
    let at = carets.find('^').expect(&err);
    assert_eq!(at, gutter.len() + 3 + col - 1, "the caret is under column {col}:\n{err}");
    assert_eq!(carets[at..].trim_end(), "^".repeat("opacity_lenght".len()), "{err}");
    assert!(source.contains("opacity_lenght"));

    let long = format!("Scene(output: (width: 64, heigt: 64), {})\n", " ".repeat(500));
    std::fs::write(&scene, long).unwrap();
    let err = crate::common::stderr(&voltex(&["plan", crate::common::s(&scene)]));
    assert!(err.starts_with(&format!("error: {}:1:", scene.display())) && err.lines().count() == 1, "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `import mesh.glb -o scene.ron` run in the mesh's folder (bare file names) names the mesh
/// relative to the scene (issue 32, item 4: the scene's folder was "", which has no absolute
/// form, and the mesh's absolute path was written, breaking the scene when the folder moves).
#[test]
fn import_with_bare_names_writes_a_relative_mesh_path() {
    let dir = crate::common::scratch_dir("voltex-import-bare");
    std::fs::copy(root().join("scenes/view_slices/meshes/dome.glb"), dir.join("dome.glb")).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_voltex"))
        .args(["import", "dome.glb", "-o", "dome.ron", "-q"])
        .current_dir(&dir)
        .env("VOLTEX_ROOT", root())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", crate::common::stderr(&out));
    let text = std::fs::read_to_string(dir.join("dome.ron")).unwrap();
    assert!(text.contains("surface: Mesh(path: \"dome.glb\")"), "{text}");
    // The pair moves together.
    let moved = dir.with_extension("moved");
    let _ = std::fs::remove_dir_all(&moved);
    std::fs::rename(&dir, &moved).unwrap();
    ok(voltex(&["plan", crate::common::s(&moved.join("dome.ron"))]));
    std::fs::remove_dir_all(&moved).unwrap();
}

/// `compare -q` prints nothing and still writes its heat map; `-v` adds the FLIP map's
/// percentiles, in order, the largest at least the mean (issue 32, item 7: -q/-v everywhere).
#[test]
fn compare_takes_quiet_and_verbose() {
    let dir = crate::common::scratch_dir("voltex-compare-qv");
    let scene = root().join("scenes/view_slices/flat_box.ron").display().to_string();
    let (a, b, heat) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("heat.png"));
    let s = crate::common::s;
    ok(voltex(&["render", &scene, "--size", "16x16", "-o", s(&a), "-q"]));
    ok(voltex(&["render", &scene, "--size", "16x16", "--planes", "8", "-o", s(&b), "-q"]));
    let quiet = ok(voltex(&["compare", s(&a), s(&b), "-q", "--diff", s(&heat)]));
    assert!(quiet.is_empty() && heat.exists(), "{quiet}");
    let loud = ok(voltex(&["compare", s(&a), s(&b), "-v"]));
    let number = |key: &str| -> f64 {
        let at = loud.find(key).unwrap_or_else(|| panic!("no {key}: {loud}")) + key.len();
        loud[at..].trim_start().split([',', '\n']).next().unwrap().trim().parse().unwrap()
    };
    let (mean, median, p95, p99, max) =
        (number("FLIP (mean)"), number("median"), number("95th"), number("99th"), number("largest"));
    assert!(median <= p95 && p95 <= p99 && p99 <= max && max >= mean && mean > 0.0, "{loud}");
    assert!(!voltex(&["compare", s(&a), s(&b), "-q", "-v"]).status.success());
    std::fs::remove_dir_all(&dir).unwrap();
}
