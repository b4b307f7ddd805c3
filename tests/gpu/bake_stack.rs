//! `voltex bake` writes a texel as a slice stack, and a `Slices(dir: ..)` texel reads it back: the
//! scene renders the same from the stack as from its recipe. Bad stacks are errors at `line:col`.

use crate::common;

use common::{ok, root, s, voltex};

#[test]
fn a_baked_stack_renders_like_its_recipe() {
    let dir = std::env::temp_dir().join(format!("voltex-bake-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let recipe = root().join("scenes/meyer_neyret/heightfield_image.ron");
    let out = voltex(&["bake", s(&recipe), "--out", s(&dir)]);
    // Progress on stderr, one line per texel when it is not a terminal.
    let progress = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(progress.contains("[1/1] texel \"cobbles\" 64x64x16: "), "{progress}");
    let printed = ok(out);
    assert!(printed.contains("cobbles (64x64x16"), "{printed}");
    assert!(dir.join("cobbles/slice_015.png").is_file() && !dir.join("cobbles/slice_016.png").exists());

    // The same scene with the texel read from the stack.
    let text = std::fs::read_to_string(&recipe).unwrap();
    let start = text.find("source: ImageHeight(").unwrap();
    let end = start + text[start..].find("\n            ),").unwrap() + "\n            ),".len();
    // The opacity length comes from the stack's manifest, not the scene.
    let from_stack = format!("{}source: Slices(dir: \"cobbles\"),{}", &text[..start], &text[end..])
        .replace("opacity_length: 0.002,", "");
    let scene = dir.join("from_stack.ron");
    std::fs::write(&scene, &from_stack).unwrap();
    let manifest = std::fs::read_to_string(dir.join("cobbles/manifest.json")).unwrap();
    for field in [
        "\"bit_depth\": 16",
        "\"opacity_length\": 0.002",
        "\"premultiplied\": true",
        "\"lighting\": \"baked\"",
    ] {
        assert!(manifest.contains(field), "{field} in {manifest}");
    }
    let (a, b) = (dir.join("recipe.exr"), dir.join("stack.exr"));
    ok(voltex(&["render", s(&recipe), "--size", "64x64", "-o", s(&a)]));
    let same_as_recipe = |what: &str| {
        ok(voltex(&["render", s(&scene), "--size", "64x64", "-o", s(&b)]));
        let compared = ok(voltex(&["compare", s(&b), s(&a)]));
        assert!(compared.contains("largest difference  0.000e0"), "{what}: {compared}");
    };
    same_as_recipe("16-bit stack");
    // 8 bits, and 8 bits without a manifest (a stack from before manifests), render the same.
    ok(voltex(&["bake", s(&recipe), "--out", s(&dir), "--depth", "8"]));
    same_as_recipe("8-bit stack");
    std::fs::remove_file(dir.join("cobbles/manifest.json")).unwrap();
    let stated = from_stack.replacen("\"cobbles\": (", "\"cobbles\": (opacity_length: 0.002,", 1);
    std::fs::write(&scene, stated).unwrap();
    same_as_recipe("8-bit stack without a manifest");
    std::fs::write(&scene, &from_stack).unwrap();
    // The unlit float stack: straight albedo and alpha in EXR slices.
    let unlit = dir.join("unlit");
    ok(voltex(&["bake", s(&recipe), "--out", s(&unlit), "--depth", "32", "--unlit"]));
    let manifest = std::fs::read_to_string(unlit.join("cobbles/manifest.json")).unwrap();
    assert!(
        manifest.contains("\"lighting\": \"unlit\"") && manifest.contains("\"premultiplied\": false"),
        "{manifest}"
    );
    assert!(unlit.join("cobbles/slice_015.exr").is_file());
    ok(voltex(&["bake", s(&recipe), "--out", s(&dir)]));

    // A stack of another resolution, and a missing one, are errors at the `dir` string.
    let line = from_stack.lines().position(|l| l.contains("Slices(dir")).unwrap() + 1;
    let col = from_stack.lines().nth(line - 1).unwrap().find("\"cobbles\"").unwrap() + 1;
    for (name, edit, expected) in [
        ("other_res.ron", ("(64, 64, 16)", "(64, 64, 8)"), "the stack holds 64x64x16"),
        ("missing.ron", ("\"cobbles\"", "\"nothing\""), "expected a slice-stack folder"),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, from_stack.replace(edit.0, edit.1)).unwrap();
        let out = voltex(&["render", s(&path), "--size", "64x64", "-o", s(&dir.join("x.exr"))]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(&format!("{}:{line}:{col}", path.display())) && err.contains(expected), "{err}");
    }
    // Per-pixel lighting cannot relight baked shading.
    let path = dir.join("per_pixel.ron");
    std::fs::write(
        &path,
        from_stack
            .replace("AxisSlices(depth: 1.0, pixels: 1.0)", "ViewSlices(planes: 16, lighting: PerPixel)"),
    )
    .unwrap();
    let out = voltex(&["render", s(&path), "--size", "64x64", "-o", s(&dir.join("x.exr"))]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("lighting: Baked"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // An unknown texel name fails before any GPU work.
    let out = voltex(&["bake", s(&recipe), "--texel", "nope", "--out", s(&dir)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope"));
    std::fs::remove_dir_all(&dir).unwrap();
}
