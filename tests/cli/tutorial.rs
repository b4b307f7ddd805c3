//! The tutorial (`docs/src/tutorial.md`) run as written (issue 32): its shell blocks in order, in
//! a folder that holds the project's `scenes` as the tutorial's reader does, with `cargo run
//! --release --` standing for the built binary; its RON block written into the file it says to
//! edit; its example error made and compared word for word; and the files it says each step
//! writes checked. The preview runs under Xvfb with `--quit-after` and `--record` added (a user
//! closes the window), and must show a frame.

use std::path::Path;
use std::process::Command;

use crate::common;

/// A fenced block of the tutorial: its language, its text and the prose before it.
struct Block {
    lang: String,
    text: String,
    before: String,
}

fn blocks(page: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut prose = String::new();
    let mut lines = page.lines();
    while let Some(line) = lines.next() {
        if let Some(lang) = line.strip_prefix("```") {
            let text: Vec<&str> = lines.by_ref().take_while(|l| !l.starts_with("```")).collect();
            out.push(Block {
                lang: lang.trim().to_string(),
                text: text.join("\n") + "\n",
                before: prose.clone(),
            });
            prose.clear();
        } else {
            prose.push_str(line);
            prose.push('\n');
        }
    }
    out
}

/// The text between the first `start` in `text` and the next backtick.
fn quoted<'a>(text: &'a str, start: &str) -> Option<&'a str> {
    let from = text.find(start)? + start.len();
    Some(&text[from..from + text[from..].find('`')?])
}

/// Runs one shell block with `cargo run --release --` meaning the built binary (and the preview
/// closing itself after a while, recording what it shows into `record`).
fn run_block(dir: &Path, block: &str, record: &Path) {
    let shim = format!(
        r#"set -e
cargo() {{
  [ "$1 $2 $3" = "run --release --" ] || {{ echo "not the tutorial's cargo line: $*" >&2; return 2; }}
  shift 3
  if [ "$1" = preview ]; then
    xvfb-run -a -s "-screen 0 1280x800x24" "$VOLTEX" "$@" --quit-after 15 --record '{record}'
  else
    "$VOLTEX" "$@"
  fi
}}
"#,
        record = record.display()
    );
    let out = Command::new("sh")
        .arg("-c")
        .arg(shim + block)
        .current_dir(dir)
        .env("VOLTEX", env!("CARGO_BIN_EXE_voltex"))
        .env("VOLTEX_ROOT", common::root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "the tutorial's block failed:\n{block}\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stdout),
        common::stderr(&out)
    );
}

#[test]
fn the_tutorial_runs_as_written() {
    let page = std::fs::read_to_string(common::root().join("docs/src/tutorial.md")).unwrap();
    let dir = common::scratch_dir("voltex-tutorial");
    std::os::unix::fs::symlink(common::root().join("scenes"), dir.join("scenes")).unwrap();
    let record = dir.join("preview-frames");
    let mut edited = None;
    for block in blocks(&page) {
        match block.lang.as_str() {
            "sh" => run_block(&dir, &block.text, &record),
            "ron" => {
                // "Open `my/balls.ron` and make ...": the block is that file after the edit.
                let file = quoted(&block.before, "Open `").expect("the RON block names the file it edits");
                std::fs::write(dir.join(file), &block.text).unwrap();
                edited = Some(file.to_string());
            }
            other => panic!("a {other:?} block in the tutorial: say how to run it here"),
        }
        if block.text.contains(" preview ") {
            let frames = common::entries(&record);
            assert!(frames.iter().any(|f| f.ends_with(".png")), "the preview showed no frame: {frames:?}");
        }
    }
    let edited = edited.expect("the tutorial edits a scene");

    // What the steps say they write.
    for file in [
        "my/balls.ron",
        "out/my/balls.exr",
        "out/my/balls.png",
        "out/my/balls_50.exr",
        "out/my/balls_axis.exr",
        "out/my/balls_ref.exr",
        "out/my/diff.png",
        "out/my/pareto/pareto.csv",
        "out/my/pareto/pareto.svg",
        "my/balls.ref.exr",
        "out/regress/index.html",
    ] {
        assert!(dir.join(file).is_file(), "the tutorial says it writes {file}");
    }

    // The example mistake, made where the tutorial says it is, reads as the tutorial prints it.
    let error = quoted(&page, "`error: ").map(|e| format!("error: {e}")).expect("an example error");
    let place = error.strip_prefix(&format!("error: {edited}:")).expect("the error names the edited file");
    let mut at = place.split(':');
    let line: usize = at.next().unwrap().parse().unwrap();
    let col: usize = at.next().unwrap().parse().unwrap();
    let found = error.rsplit("found ").next().unwrap();
    let text = std::fs::read_to_string(dir.join(&edited)).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let target = &mut lines[line - 1];
    let number_end = target[col - 1..].find(|c: char| c != '.' && !c.is_ascii_digit()).unwrap() + col - 1;
    target.replace_range(col - 1..number_end, found);
    std::fs::write(dir.join(&edited), lines.join("\n")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_voltex"))
        .args(["plan", &edited])
        .current_dir(&dir)
        .env("VOLTEX_ROOT", common::root())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        common::stderr(&out).contains(&error),
        "the tutorial prints {error:?}; voltex said:\n{}",
        common::stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
