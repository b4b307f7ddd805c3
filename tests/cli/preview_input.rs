//! The preview window driven as a user would, under Xvfb with synthetic input (`xdotool`, Debian
//! package `xdotool`; `.ci/run` installs it): keys and a curve drag, each checked against the
//! scene file on disk and the recorded frame (its pixels, and `frame-N.json`: the selection, the
//! view, the messages and where the panel's widgets are).

use crate::common;

use common::window::Preview;
use std::path::Path;
use voltex::scene::hypertexture::ShapeTransfer;

/// A textured plane and a ray-marched hypertexture, small enough to redraw in a blink.
const SCENE: &str = r#"// keys and panel test scene
#![enable(implicit_some)]
Scene(
    output: (width: 40, height: 40),
    camera: (eye: (0.0, -3.0, 1.6), target: (0.0, 0.0, 0.2), up: (0.0, 0.0, 1.0), fov_y: 40.0),
    background: (0.05, 0.05, 0.08),
    lights: [Directional(direction: (-0.4, 0.5, -0.8))], // the sun
    texels: {
        "fog": (resolution: (4, 4, 4), opacity_length: 0.5, source: Constant(color: (0.8, 0.6, 0.4), opacity: 0.5)),
    },
    hypertextures: {
        "blob": (
            object: Sphere(radius: 0.5),
            noises: [(shape: Curve([(0.0, 0.0, 0.0), (0.5, 1.0, 0.0), (1.0, 0.0, 0.0)]), amplitude: 0.2, frequency: 3.0)],
            color: Ramp([(0.0, (1.0, 1.0, 1.0, 0.0)), (0.3, (0.9, 0.5, 0.3, 1.0)), (1.0, (0.9, 0.8, 0.7, 1.0))]),
            opacity_length: 0.02,
        ),
    },
    nodes: [
        (name: "ground", surface: Plane(size: (2.0, 2.0), cells: (2, 2)), height: (length: 0.3), texel: "fog",
         method: ViewSlices(planes: 16)),
        (name: "ball", transform: (translate: (0.0, 0.0, 0.6)), hypertexture: "blob", method: RayMarch(step: 0.02)),
    ],
)
"#;

/// The image part of recorded frame `n` (left of the panel).
fn pixels(p: &Preview, n: usize) -> Vec<[u8; 4]> {
    let (w, _, px) = voltex::io::png::read_rgba8(&p.record.join(format!("frame-{n}.png"))).unwrap();
    let keep = (w as usize).saturating_sub(360);
    px.chunks(w as usize).flat_map(|row| row[..keep].to_vec()).collect()
}

fn changed(a: &[[u8; 4]], b: &[[u8; 4]]) -> usize {
    a.iter().zip(b).filter(|(p, q)| p != q).count()
}

fn text(scene: &Path) -> String {
    std::fs::read_to_string(scene).unwrap()
}

/// The centre of widget `path` in frame `n`, in window pixels.
fn widget(p: &Preview, n: usize, path: &str) -> (f64, f64, f64, f64) {
    let s = p.state(n);
    let r = s["editors"][path].as_array().unwrap_or_else(|| panic!("no widget {path} in frame {n}: {s}"));
    let v: Vec<f64> = r.iter().map(|x| x.as_f64().unwrap()).collect();
    (v[0], v[1], v[2], v[3])
}

/// Clicks the middle of widget `path` of frame `n`.
fn click(p: &Preview, n: usize, path: &str) {
    let (x0, y0, x1, y1) = widget(p, n, path);
    let (cx, cy) = (format!("{}", (0.5 * (x0 + x1)).round()), format!("{}", (0.5 * (y0 + y1)).round()));
    p.xdo(&["mousemove", &cx, &cy, "click", "1"]);
}

/// Clicks number field `path` of frame `n`, selects its text and types `value` and Enter.
fn type_into(p: &Preview, n: usize, path: &str, value: &str) {
    click(p, n, path);
    // The field takes the keyboard in the panel's next frame.
    std::thread::sleep(std::time::Duration::from_millis(1500));
    p.xdo(&["key", "ctrl+a", value, "Return"]);
}

/// Tab until the ball is selected: the frame that shows it. The first key after the window's
/// focus can be lost on a loaded machine (the selection stayed "ground" for 30 s beside two fuzz
/// campaigns): again, then.
fn select_ball(p: &mut Preview) -> usize {
    for _ in 0..4 {
        let after = p.after(|p| drop(p.xdo(&["key", "Tab"])));
        if let Ok(m) = p.within(10, "ball selected", |p, n| p.state(n)["selected"] == "ball") {
            return m.max(after);
        }
    }
    p.until("ball selected", |p, n| p.state(n)["selected"] == "ball")
}

/// A pause between the steps of a drag (the window sees each move).
fn pause() {
    std::thread::sleep(std::time::Duration::from_millis(200));
}

fn start(name: &str) -> (std::path::PathBuf, std::path::PathBuf, Preview) {
    let dir = common::scratch_dir(name);
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, SCENE).unwrap();
    let mut p = Preview::start(&scene, "40x40", dir.join("frames"), &[]);
    p.frame(0);
    p.focus();
    (dir, scene, p)
}

/// Stops the preview of [`start`]: it must not have panicked; its folder is removed.
fn finish(p: Preview, dir: &Path) {
    let out = p.stop();
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn keys_and_a_curve_drag_edit_the_scene_file() {
    let (dir, scene, mut p) = start("voltex-keys");
    let key = |k: &'static str| move |p: &Preview| drop(p.xdo(&["key", k]));

    // Tab: the next object.
    let n = select_ball(&mut p);
    let before = pixels(&p, n);

    // M on a hypertexture: its shading, None to Phong, in the file and the frame.
    p.after(key("m"));
    let n = p.until("Phong", |p, n| p.state(n)["method"].as_str().unwrap_or("").contains("Phong"));
    assert!(text(&scene).contains("method: RayMarch(step: 0.02, shading: Phong)"), "{}", text(&scene));
    assert!(changed(&before, &pixels(&p, n)) > 100, "Phong shading changed nothing");

    // + and -: the step halved and back; Ctrl+Z undoes the -, Ctrl+Shift+Z redoes it.
    let path = scene.clone();
    let file_has = move |s: &'static str| {
        let path = path.clone();
        move |_: &Preview, _: usize| text(&path).contains(s)
    };
    p.after(key("shift+equal"));
    p.until("+: step 0.01", file_has("RayMarch(step: 0.01, shading: Phong)"));
    p.after(key("minus"));
    p.until("-: step 0.02", file_has("RayMarch(step: 0.02, shading: Phong)"));
    p.after(key("ctrl+z"));
    p.until("undo: step 0.01", file_has("RayMarch(step: 0.01, shading: Phong)"));
    p.after(key("ctrl+shift+z"));
    p.until("redo: step 0.02", file_has("RayMarch(step: 0.02, shading: Phong)"));
    // Comments and the rest of the file stay.
    assert!(
        text(&scene).starts_with("// keys and panel test scene\n") && text(&scene).contains("// the sun")
    );

    // Tab back to the plane; M: ViewSlices -> AxisSlices.
    p.after(key("Tab"));
    p.after(key("m"));
    let n =
        p.until("AxisSlices", |p, n| p.state(n)["method"].as_str().unwrap_or("").starts_with("AxisSlices"));
    assert!(text(&scene).contains("method: AxisSlices()),"), "{}", p.state(n));
    assert_eq!(p.state(n)["selected"], "ground");

    // 2, 3, 1: the reference, the difference, the image.
    let image = pixels(&p, n);
    p.after(key("2"));
    p.until("reference view", |p, n| p.state(n)["mode"] == "Truth");
    p.after(key("3"));
    let n = p.until("difference view", |p, n| p.state(n)["mode"] == "Difference");
    assert!(changed(&image, &pixels(&p, n)) > 1000, "the difference view looks like the image");
    p.after(key("1"));
    let n = p.until("image view", |p, n| p.state(n)["mode"] == "Image");
    assert_eq!(changed(&image, &pixels(&p, n)), 0, "back to the image");

    // An orbit drag on the image moves the view, not the file; R resets it; C writes it.
    let file = text(&scene);
    // A hand moves over time: events all at once are merged by the X server.
    let orbit = |p: &Preview| {
        p.xdo(&["mousemove", "200", "360", "mousedown", "1"]);
        for x in ["230", "260"] {
            pause();
            p.xdo(&["mousemove", x, "350"]);
        }
        pause();
        p.xdo(&["mouseup", "1"]);
    };
    let n = p.after(orbit);
    let moved = changed(&image, &pixels(&p, n));
    assert!(moved > 1000, "the orbit moved {moved} pixels: frame {n}: {}", p.state(n));
    assert_eq!(text(&scene), file);
    p.after(key("r"));
    let n = p.until("camera reset", |p, n| p.state(n)["status"] == "camera reset to the scene's");
    assert_eq!(changed(&image, &pixels(&p, n)), 0, "R brought the scene's camera back");
    p.after(orbit);
    p.after(key("c"));
    let n = p.until("camera written", |p, n| {
        p.state(n)["status"].as_str().unwrap_or("").starts_with("camera written")
    });
    let written = voltex::scene::parse(&text(&scene), &scene).unwrap();
    assert_ne!(written.camera.eye, glam::DVec3::new(0.0, -3.0, 1.6), "{}", p.state(n));
    assert!(text(&scene).contains("// the sun"));

    // S: a screenshot under out/ (the preview runs in the scene's folder).
    p.after(key("s"));
    let n =
        p.until("screenshot", |p, n| p.state(n)["status"].as_str().unwrap_or("").starts_with("screenshot"));
    assert!(
        dir.join("out/preview-scene-0.exr").exists() && dir.join("out/preview-scene-0.png").exists(),
        "{}",
        p.state(n)
    );

    // A curve drag: the shape function's peak pulled down, in the file and the frame.
    p.after(key("Tab"));
    let n = p.until("ball selected", |p, n| p.state(n)["selected"] == "ball");
    let curve = "hypertextures[\"blob\"].noises[0].shape";
    let (x0, y0, x1, y1) = widget(&p, n, curve);
    // The editor's plot is inset by 6 pixels; the point (0.5, 1.0) is at its top middle.
    let (px, top, bottom) = ((0.5 * (x0 + x1)).round(), (y0 + 6.0).round(), y1 - 6.0);
    let before = pixels(&p, n);
    // Grabbed 5 pixels below its centre, the point moves with the pointer (relative drag), not
    // to it (it jumped by the grab's offset).
    let grab = 5.0;
    let drag = |p: &Preview| {
        p.xdo(&["mousemove", &format!("{px}"), &format!("{}", top + grab), "mousedown", "1"]);
        for k in 1..=4 {
            pause();
            let y = (top + grab + (bottom - top) * 0.15 * k as f64).round();
            p.xdo(&["mousemove", &format!("{px}"), &format!("{y}")]);
        }
        pause();
        p.xdo(&["mouseup", "1"]);
    };
    p.after(drag);
    let n = p.until("the curve written", |_, _| !text(&scene).contains("(0.5, 1.0, 0.0)"));
    let t = text(&scene);
    let parsed = voltex::scene::parse(&t, &scene).unwrap();
    let ShapeTransfer::Curve(c) = &parsed.hypertextures["blob"].noises[0].shape else { panic!() };
    let (x, y) = (c[1].0, c[1].1);
    // Within a pixel and a half of 0.4 (pointer positions are whole pixels); the grab's offset
    // is 5 pixels.
    let pixel = 1.0 / (bottom - top);
    assert!(
        (x - 0.5).abs() < 0.02 && (y - 0.4).abs() < 1.5 * pixel,
        "peak moved to ({x}, {y}), not 0.4 (one pixel is {pixel}): {t}\n{}",
        p.state(n)
    );
    assert!(t.contains("shape: Curve([(0.0, 0.0, 0.0), ("), "{t}");
    assert!(changed(&before, &pixels(&p, n)) > 20, "the curve drag changed no pixel");
    // One undo takes the whole drag back.
    p.after(key("ctrl+z"));
    p.until("the drag undone", file_has("(0.5, 1.0, 0.0)"));

    // H hides the panel.
    p.after(key("h"));
    p.until("panel hidden", |p, n| p.state(n)["panel"] == false);
    let out = p.stop();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad input in the window: a value typed out of range is refused (message, field marked, file
/// untouched); a read-only file keeps edits in memory and says so; the file changed on disk while
/// the panel holds such an edit wins.
#[test]
fn the_panel_refuses_bad_values_and_yields_to_the_file() {
    let (dir, scene, mut p) = start("voltex-panel-bad");
    let planes = "nodes[0].method.planes";
    let original = text(&scene);
    // Click to type into the field, select its text, type 0, press Enter.
    p.after(|p| type_into(p, 0, planes, "0"));
    let n = p.until("refused", |p, n| !p.state(n)["refused"].is_null());
    let s = p.state(n);
    assert_eq!(text(&scene), original, "an out-of-range value was written");
    assert_eq!(s["refused"][0], planes, "{s}");
    assert!(s["refused"][1].as_str().unwrap().contains("plane count in 1..=16384, found 0"), "{s}");

    // Read-only: + changes the frame, not the file; the panel says so.
    let mut perms = std::fs::metadata(&scene).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&scene, perms.clone()).unwrap();
    let before = pixels(&p, n);
    p.after(|p| drop(p.xdo(&["key", "shift+equal"])));
    let n = p.until("read-only", |p, n| p.state(n)["read_only"] == true);
    let s = p.state(n);
    assert_eq!(text(&scene), original);
    assert_eq!(s["read_only"], true, "{s}");
    assert!(s["note"].as_str().unwrap().contains("read-only"), "{s}");
    assert!(changed(&before, &pixels(&p, n)) > 0, "the edit in memory is not shown");
    // The file replaced on disk (renamed over, as editors save) while the panel holds that
    // edit: the file wins, the panel says so.
    let external = original.replace("planes: 16", "planes: 8");
    let tmp = dir.join("scene.ron.tmp");
    std::fs::write(&tmp, &external).unwrap();
    std::fs::rename(&tmp, &scene).unwrap();
    let n =
        p.until("the file's planes", |p, n| p.state(n)["method"] == "ViewSlices(planes: 8, lighting: Baked)");
    let s = p.state(n);
    assert_eq!(text(&scene), external, "{s}");
    assert_eq!(s["method"], "ViewSlices(planes: 8, lighting: Baked)", "{s}");
    assert!(s["note"].as_str().unwrap_or("").contains("the file wins"), "{s}");
    finish(p, &dir);
}

/// Moss on a UV-less glb in one command, then edited in the panel without opening the RON file
/// (issue 32's goal): `import --preset moss`, the preview on the scene, the moss's bright colour
/// typed into its field; the file gets the value (its comments kept), and the frame changes.
#[test]
fn moss_imported_in_one_command_is_edited_in_the_panel() {
    let dir = common::scratch_dir("voltex-moss-panel");
    let mesh = crate::assets::uvless_glb(&dir);
    let scene = dir.join("mossy.ron");
    common::ok(common::voltex(&[
        "import",
        common::s(&mesh),
        "--preset",
        "moss",
        "-o",
        common::s(&scene),
        "-q",
    ]));
    let original = text(&scene);
    assert!(original.contains("color_high: (0.45, 0.62, 0.2)"), "{original}");
    let mut p = Preview::start(&scene, "40x40", dir.join("frames"), &[]);
    p.frame(0);
    p.focus();
    let field = "texels[\"moss\"].source.color_high[0]";
    let n = p.until("the moss's colour field", |p, n| p.state(n)["editors"][field].is_array());
    let before = pixels(&p, n);
    p.after(|p| type_into(p, n, field, "1"));
    let path = scene.clone();
    let n = p.until("the edit in the file", move |_, _| text(&path).contains("color_high: (1.0, 0.62, 0.2)"));
    let after = pixels(&p, n);
    let out = p.stop();
    let edited = text(&scene);
    // Only that value changed: the import's comments and the rest stay.
    assert_eq!(edited, original.replace("color_high: (0.45, 0.62, 0.2)", "color_high: (1.0, 0.62, 0.2)"));
    assert!(changed(&before, &after) > 20, "the redder moss changed nothing on screen");
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    std::fs::remove_dir_all(&dir).ok();
}

/// The panel duplicates and removes objects (issue 32, item 2): "duplicate object" writes a
/// copy of the selected node with a free name after it, undo takes it back, "remove object"
/// on the copy removes it.
#[test]
fn the_panel_duplicates_and_removes_an_object() {
    let (dir, scene, mut p) = start("voltex-panel-items");
    let original = text(&scene);
    let n = p.until("the object's buttons", |p, n| p.state(n)["editors"]["nodes[0] duplicate"].is_array());
    p.after(|p| click(p, n, "nodes[0] duplicate"));
    let path = scene.clone();
    p.until("a copy in the file", move |_, _| text(&path).contains("name: \"ground_2\""));
    let copied = text(&scene);
    assert_eq!(copied.matches("name: \"ground").count(), 2, "{copied}");
    p.after(|p| drop(p.xdo(&["key", "ctrl+z"])));
    let (path, want) = (scene.clone(), original.clone());
    p.until("undone", move |_, _| text(&path) == want);
    p.after(|p| drop(p.xdo(&["key", "ctrl+shift+z"])));
    let (path, want) = (scene.clone(), copied.clone());
    p.until("redone", move |_, _| text(&path) == want);
    // The copy is nodes[1]: select it (Tab), remove it.
    p.after(|p| drop(p.xdo(&["key", "Tab"])));
    let n = p.until("the copy selected", |p, m| p.state(m)["editors"]["nodes[1] remove"].is_array());
    p.after(|p| click(p, n, "nodes[1] remove"));
    let path = scene.clone();
    p.until("the copy removed", move |_, _| text(&path) == original);
    finish(p, &dir);
}

/// A click on the image selects the textured object under the pointer (issue 32, item 2): with
/// the ball selected (Tab), a click where the ground's shell is (a point on its top, projected
/// through the scene's camera) selects the ground.
#[test]
fn a_click_in_the_view_selects_the_object_under_it() {
    let (dir, _scene, mut p) = start("voltex-click-select");
    let n = select_ball(&mut p);
    // The ground's top at (0.6, -0.6, 0.3), through the camera of SCENE (a pinhole, 40x40), into
    // the window: the image fits the area left of the panel (340 pixels), centred.
    let (eye, target, up) =
        (glam::DVec3::new(0.0, -3.0, 1.6), glam::DVec3::new(0.0, 0.0, 0.2), glam::DVec3::Z);
    let f = (target - eye).normalize();
    let r = f.cross(up).normalize();
    let u = r.cross(f);
    let focal = 20.0 / (20f64.to_radians()).tan();
    let d = glam::DVec3::new(0.6, -0.6, 0.3) - eye;
    let pixel = (20.0 + focal * d.dot(r) / d.dot(f), 20.0 - focal * d.dot(u) / d.dot(f));
    let (w, h, _) = voltex::io::png::read_rgba8(&p.record.join(format!("frame-{n}.png"))).unwrap();
    let area = (w as f64 - 340.0, h as f64);
    let scale = (area.0 / 40.0).min(area.1 / 40.0);
    let at =
        (0.5 * (area.0 - 40.0 * scale) + pixel.0 * scale, 0.5 * (area.1 - 40.0 * scale) + pixel.1 * scale);
    let (x, y) = (format!("{}", at.0.round()), format!("{}", at.1.round()));
    p.after(|p| drop(p.xdo(&["mousemove", &x, &y, "click", "1"])));
    let n = p.until("the ground selected", |p, n| p.state(n)["selected"] == "ground");
    assert_eq!(p.state(n)["status"], "selected ground");
    finish(p, &dir);
}

/// A 2D shape function (`Grid`) is painted in the panel (Gilet & Dischler's Figure 6; issue 32,
/// item 2): a click on a cell of its image writes the brush's density (1 by default) into that
/// cell of the file, and nothing else changes.
#[test]
fn a_grid_shape_is_painted_in_the_panel() {
    let dir = common::scratch_dir("voltex-grid-paint");
    let scene = dir.join("grid.ron");
    let original = text(&common::root().join("scenes/hypertextures/fig7_2d_transfer.ron"));
    std::fs::write(&scene, &original).unwrap();
    let mut p = Preview::start(&scene, "24x16", dir.join("frames"), &[]);
    p.frame(0);
    p.focus();
    let grid = "hypertextures[\"constant\"].noises[0].shape";
    let n = p.until("the grid's image", |p, n| p.state(n)["editors"][grid].is_array());
    // Row 0 (density 0, at the top), column 0 (noise 0, at the left) of a 2 x 5 grid.
    let (x0, y0, x1, y1) = widget(&p, n, grid);
    let (x, y) =
        (format!("{}", (x0 + 0.1 * (x1 - x0)).round()), format!("{}", (y0 + 0.25 * (y1 - y0)).round()));
    p.after(|p| drop(p.xdo(&["mousemove", &x, &y, "click", "1"])));
    let (path, before) = (scene.clone(), original.clone());
    p.until("the cell painted", move |_, _| text(&path) != before);
    let painted = original.replacen("Grid([[0.0, 0.0, 0.0, 0.5, 1.0]", "Grid([[1.0, 0.0, 0.0, 0.5, 1.0]", 1);
    assert_eq!(text(&scene), painted);
    finish(p, &dir);
}

/// A curve point's tangent has a handle (issue 32: new points got slope 0 and slopes could not be
/// edited): dragging the peak's handle from its right down by as much as across sets the peak's
/// slope to minus the editor's width over its height (one pixel of rounding aside).
#[test]
fn a_tangent_handle_sets_the_slope() {
    let (dir, scene, mut p) = start("voltex-tangent");
    let n = select_ball(&mut p);
    let curve = "hypertextures[\"blob\"].noises[0].shape";
    let n = p.until("the curve editor", |p, m| m >= n && p.state(m)["editors"][curve].is_array());
    let (x0, y0, x1, y1) = widget(&p, n, curve);
    // The plot is inset by 6 pixels; the peak (0.5, 1.0, slope 0) is at its top middle and its
    // handle 18 pixels to its right.
    let (w, h) = (x1 - x0 - 12.0, y1 - y0 - 12.0);
    let (hx, hy) = ((x0 + 6.0 + 0.5 * w + 18.0).round(), (y0 + 6.0).round());
    p.after(|p| {
        p.xdo(&["mousemove", &format!("{hx}"), &format!("{hy}"), "mousedown", "1"]);
        for k in 1..=3 {
            pause();
            p.xdo(&["mousemove", &format!("{hx}"), &format!("{}", hy + 6.0 * k as f64)]);
        }
        pause();
        p.xdo(&["mouseup", "1"]);
    });
    let path = scene.clone();
    p.until("the slope written", move |_, _| !text(&path).contains("(0.5, 1.0, 0.0)"));
    let t = text(&scene);
    let parsed = voltex::scene::parse(&t, &scene).unwrap();
    let ShapeTransfer::Curve(c) = &parsed.hypertextures["blob"].noises[0].shape else { panic!() };
    let want = -w / h;
    assert!((c[1].0 - 0.5).abs() < 1e-9 && (c[1].1 - 1.0).abs() < 1e-9, "the point itself moved: {t}");
    assert!((c[1].2 - want).abs() < 0.1 * want.abs(), "slope {} against {want}: {t}", c[1].2);
    finish(p, &dir);
}
