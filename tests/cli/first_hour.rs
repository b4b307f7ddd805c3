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
