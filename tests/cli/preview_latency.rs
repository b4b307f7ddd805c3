//! `voltex preview --measure-latency` on a tiny scene: every edit the scene has a value for is
//! measured, the JSON has every stage of every sample, the copy it edits is gone afterwards and
//! the scene is untouched. No duration is asserted.

use crate::common;

const SCENE: &str = r#"// A tiny scene with a camera, a light, a texel and a hypertexture to edit.
#![enable(implicit_some)]
Scene(
    output: (width: 24, height: 16),
    camera: (eye: (0.0, -2.5, 2.0), target: (0.0, 0.0, 0.1), up: (0.0, 0.0, 1.0), fov_y: 40.0),
    lights: [Directional(direction: (-0.3, 0.2, -1.0))],
    texels: {
        "balls": (resolution: (8, 8, 8), opacity_length: 0.05,
            source: Implicit(shapes: [Sphere(center: (0.5, 0.5, 0.4), radius: 0.3, color: (0.9, 0.5, 0.2))])),
    },
    hypertextures: {
        "blob": (object: Sphere(radius: 0.3),
            noises: [(shape: Curve([(0.0, 0.0, 1.0), (1.0, 1.0, 1.0)]), amplitude: 0.1, frequency: 3.0)],
            color: Step(threshold: 0.3, color: (0.8, 0.7, 0.6)), opacity_length: 0.05),
    },
    nodes: [
        (name: "ground", surface: Plane(size: (2.0, 2.0), cells: (2, 2)), height: (length: 0.4),
            texel: "balls", method: ViewSlices(planes: 16)),
        (name: "blob", transform: (translate: (0.0, 0.0, 0.6)), hypertexture: "blob",
            method: RayMarch(step: 0.02, shading: Phong)),
    ],
)
"#;

const STAGES: &[&str] = &[
    "write", "watch", "parse", "plan", "bake", "build", "render", "readback", "total", "files", "io",
    "shaders", "validate",
];

#[test]
fn measure_latency_writes_every_stage_of_every_edit() {
    let dir = common::scratch_dir("voltex-latency");
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let json = dir.join("latency.json");
    let out = common::ok(common::voltex(&[
        "preview",
        common::s(&scene),
        "--measure-latency",
        "--repeat",
        "2",
        "--json",
        common::s(&json),
    ]));
    assert!(out.contains("save-to-frame latency") && out.contains("total"), "{out}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(!v["adapter"].as_str().unwrap().is_empty());
    assert_eq!(v["size"], serde_json::json!([24, 16]));
    assert_eq!(v["repeat"], 2);
    let rows = v["rows"].as_array().unwrap();
    let edits: Vec<&str> = rows.iter().map(|r| r["edit"].as_str().unwrap()).collect();
    for e in ["camera", "light", "knob", "texel", "noise", "orbit"] {
        assert!(edits.contains(&e), "no `{e}` row in {edits:?}");
    }
    for r in rows {
        let samples = r["samples"].as_array().unwrap();
        assert_eq!(samples.len(), 2, "{r}");
        for s in samples.iter().chain([&r["median"]]) {
            for stage in STAGES {
                let t = s[stage].as_f64().unwrap_or_else(|| panic!("no `{stage}` in {s}"));
                assert!(t.is_finite() && t >= 0.0, "{stage} = {t}");
            }
        }
        let edit = r["edit"].as_str().unwrap();
        // What each edit had to make: the texel, and the light it bakes in (ViewSlices' default
        // lighting is baked), are baked again; nothing compiles.
        assert_eq!(r["bakes"], u32::from(["texel", "light"].contains(&edit)), "{r}");
        assert_eq!((&r["modules"], &r["pipelines"]), (&0.into(), &0.into()), "{r}");
        // The file edits went through the watcher and read the scene file; a camera move in the
        // window opens no file. No edit validates a shader again (none changed).
        let count = |stage: &str| samples.iter().map(|s| s[stage].as_f64().unwrap()).fold(0.0, f64::max);
        if !["orbit", "drag"].contains(&edit) {
            assert!(samples.iter().all(|s| s["watch"].as_f64().unwrap() > 0.0), "{r}");
            assert!(samples.iter().all(|s| s["files"].as_f64().unwrap() >= 1.0), "{r}");
        } else {
            assert_eq!(count("files"), 0.0, "a camera move opened a file: {r}");
        }
        assert_eq!(count("shaders"), 0.0, "{edit} validated a shader again: {r}");
        assert!(out.contains(&format!("\n{edit} ")), "{edit} not in the table:\n{out}");
    }
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), SCENE);
    assert_eq!(common::entries(&dir), ["latency.json", "scene.ron"]);
    std::fs::remove_dir_all(&dir).ok();
}
