//! `voltex import MESH --preset NAME` (issue 32, item 3): a look from the presets built into the
//! binary on any mesh, in one command, as a normal editable scene.

use crate::assets::uvless_glb;
use crate::common::{ok, root, s, scratch_dir, stderr, voltex};

/// Moss on a glb without uvs, in one command: the scene names the preset's texel, parses, plans
/// and renders something (the mesh under moss), and says where the look comes from.
#[test]
fn moss_goes_on_a_uvless_glb_in_one_command() {
    let dir = scratch_dir("voltex-preset-moss");
    let mesh = uvless_glb(&dir);
    let scene = dir.join("mossy.ron");
    let run = voltex(&["import", s(&mesh), "--preset", "moss", "-o", s(&scene)]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("planar uvs"), "{}", stderr(&run));
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(
        text.contains("texel: \"moss\"")
            && text.contains("PerlinHeight(")
            && text.contains("preset \"moss\""),
        "{text}"
    );
    let out = dir.join("mossy.exr");
    ok(voltex(&["render", s(&scene), "--size", "24x24", "-o", s(&out)]));
    let (image, _) = voltex::io::exr::read(&out).unwrap();
    // Green dominates where the moss is drawn (the default grain is sand-coloured).
    let green = image.pixels.iter().filter(|p| p[3] > 0.5 && p[1] > p[0] && p[1] > p[2]).count();
    assert!(green > 20, "{green} green pixels");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every preset imports onto a mesh as a scene that plans; an unknown name lists them; a preset
/// on an OpenVDB file is refused (a volume has no surface to put a look on).
#[test]
fn every_preset_imports_and_an_unknown_one_is_refused_with_the_list() {
    let dir = scratch_dir("voltex-presets");
    let mesh = root().join("scenes/view_slices/meshes/dome.glb");
    let names = ["grain", "moss", "grass", "fur", "pears", "cobbles", "cloud"];
    // Every preset file is one of them, and `import --help` names them all.
    let mut files: Vec<String> = std::fs::read_dir(root().join("scenes/presets"))
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().to_str()?.strip_suffix(".ron").map(str::to_string))
        .collect();
    files.sort();
    let mut sorted = names.map(str::to_string).to_vec();
    sorted.sort();
    assert_eq!(files, sorted);
    let help = ok(voltex(&["import", "--help"]));
    assert!(names.iter().all(|n| help.contains(n)), "{help}");
    for name in names {
        let scene = dir.join(format!("{name}.ron"));
        ok(voltex(&["import", s(&mesh), "--preset", name, "-o", s(&scene)]));
        let plan = ok(voltex(&["plan", s(&scene)]));
        assert!(
            plan.lines().any(|l| l.trim_start().starts_with(name)),
            "{name}: its texel is baked:\n{plan}"
        );
    }
    let run = voltex(&["import", s(&mesh), "--preset", "chrome", "-o", s(&dir.join("x.ron"))]);
    let err = stderr(&run);
    assert!(!run.status.success() && err.contains("no preset `chrome`: expected one of"), "{err}");
    assert!(names.iter().all(|n| err.contains(n)), "{err}");
    assert!(!dir.join("x.ron").exists());
    let vdb = root().join("scenes/volumes/box.vdb");
    let run = voltex(&["import", s(&vdb), "--preset", "moss", "-o", s(&dir.join("v.ron"))]);
    assert!(
        !run.status.success() && stderr(&run).contains("--preset moss puts a look on a mesh"),
        "{}",
        stderr(&run)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
