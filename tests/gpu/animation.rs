//! Animation (Meyer & Neyret 1998, section 5): `render --frames A..B` writes a numbered sequence at
//! time N / fps, each frame the same as a single render at that `--time`; motions animate the
//! shell; bad motions and frame ranges are errors.

use crate::common;

use common::{ok, root, s, voltex};
use std::path::Path;

fn largest_difference(a: &Path, b: &Path) -> f64 {
    let text = ok(voltex(&["compare", s(a), s(b)]));
    let line = text.lines().find(|l| l.starts_with("largest difference")).unwrap();
    line.split_whitespace().last().unwrap().parse().unwrap()
}

#[test]
fn frames_are_renders_at_their_time() {
    let dir = std::env::temp_dir().join(format!("voltex-frames-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = root().join("scenes/meyer_neyret/waving_flag.ron");
    let seq = dir.join("flag.exr");
    ok(voltex(&["render", s(&scene), "--size", "64x48", "--frames", "2..4", "--fps", "4", "-o", s(&seq)]));
    let frame = |n: u32| dir.join(format!("flag_{n:04}.exr"));
    assert!(frame(2).is_file() && frame(3).is_file() && frame(4).is_file() && !frame(1).exists());
    // Frame 3 at 4 fps is the scene at 0.75 s.
    let single = dir.join("single.exr");
    ok(voltex(&["render", s(&scene), "--size", "64x48", "--time", "0.75", "-o", s(&single)]));
    assert_eq!(largest_difference(&frame(3), &single), 0.0);
    // The flag moves between frames.
    assert!(largest_difference(&frame(2), &frame(4)) > 0.05);

    for (args, word) in [
        (vec!["--frames", "4..2"], "expected A..B"),
        (vec!["--frames", "0..2", "--time", "1"], "cannot be used with"),
    ] {
        let mut all = vec!["render", s(&scene), "-o", s(&seq)];
        all.extend(args);
        let out = voltex(&all);
        assert_eq!(out.status.code(), Some(2), "clap rejects it");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(word),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = voltex(&["render", s(&scene), "--frames", "0..1", "--fps", "0", "-o", s(&seq)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--fps 0: expected a positive frame rate"));
    let out = voltex(&["render", s(&scene), "--criteria", "0,1", "-o", s(&seq)]);
    assert_eq!(out.status.code(), Some(2), "clap rejects it");
    assert!(String::from_utf8_lossy(&out.stderr).contains("each in (0, 1024]"));
    // A motion with a zero wavelength is an error at its line:col.
    let text = std::fs::read_to_string(&scene).unwrap().replace("wavelength: 1.2", "wavelength: 0.0");
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, &text).unwrap();
    let out = voltex(&["render", s(&bad), "-o", s(&seq)]);
    let err = String::from_utf8_lossy(&out.stderr);
    let line = text.lines().position(|l| l.contains("wavelength: 0.0")).unwrap() + 1;
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("bad.ron:{line}:")) && err.contains("positive"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A cycling volume sequence draws `texels[floor(t * fps) mod n]`; its frames must be texels of
/// its resolution and no sequences, reported at their `line:col`.
#[test]
fn volume_sequences_cycle() {
    let path = root().join("scenes/meyer_neyret/waving_flag.ron");
    let scene = voltex::scene::load(&path).unwrap();
    let at = |t: f64| scene.objects_at(t).unwrap()[0].texel.clone().unwrap();
    let drawn: Vec<String> = [0.0, 0.2, 0.4, 0.6, 0.7, -0.1].iter().map(|&t| at(t)).collect();
    assert_eq!(drawn, ["tufts_1", "tufts_2", "tufts_3", "tufts_2", "tufts_1", "tufts_2"]);

    let text = std::fs::read_to_string(&path).unwrap();
    let dir = std::env::temp_dir().join(format!("voltex-sequence-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (from, to, needle, word) in [
        ("\"tufts_3\", \"tufts_2\"]", "\"tufts_9\", \"tufts_2\"]", "\"tufts_9\"", "unknown texel"),
        ("\"tufts_3\", \"tufts_2\"]", "\"tufts\", \"tufts_2\"]", "\"tufts\", \"tufts_2\"]", "is a sequence"),
        (
            "\"tufts_1\": (\n            resolution: (32, 32, 32)",
            "\"tufts_1\": (\n            resolution: (32, 32, 16)",
            "\"tufts_1\", \"tufts_2\", \"tufts_3\"",
            "resolution",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let bad = text.replace(from, to);
        let file = dir.join("bad.ron");
        std::fs::write(&file, &bad).unwrap();
        let e = voltex::scene::load(&file).expect_err(word).to_string();
        let offset = bad.find(needle).unwrap();
        let line = bad[..offset].lines().count();
        assert!(e.contains(&format!("bad.ron:{line}:")) && e.contains(word), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
