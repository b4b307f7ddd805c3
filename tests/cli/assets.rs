//! Assets in through the `voltex` binary. glTF 2.0 meshes: `meshes/dome.glb` (per-corner vertices under a
//! scaled, translated parent node, v flipped) and `meshes/dome.obj` (the same surface as OBJ,
//! written by `tools/gen_dome.py`) load to the same mesh and render the same image; broken glTF
//! files fail with the file named, status 1 and no output. EXR height images: the same heights
//! as a PNG's render the same image.

use crate::common;

use common::{ok, root, s, scratch_dir, stderr, voltex};

fn dome(file: &str) -> String {
    let text = std::fs::read_to_string(root().join("scenes/view_slices/gltf_dome.ron")).unwrap();
    let dir = root().join("scenes/view_slices/meshes");
    text.replace("\"meshes/dome.glb\"", &format!("{:?}", dir.join(file)))
}

#[test]
fn glb_and_obj_load_the_same_mesh() {
    let dir = root().join("scenes/view_slices/meshes");
    let glb = voltex::mesh::load(&dir.join("dome.glb")).unwrap();
    let obj = voltex::mesh::load(&dir.join("dome.obj")).unwrap();
    assert_eq!(glb.triangles.len(), 288);
    assert_eq!(glb.positions, obj.positions);
    assert_eq!(glb.triangles, obj.triangles);
    assert_eq!(glb.corner_uvs, obj.corner_uvs);
    assert_eq!(glb.colors, obj.colors);
    assert_eq!(glb.normals, obj.normals);
}

#[test]
fn glb_and_obj_render_the_same_image() {
    let dir = scratch_dir("voltex-gltf-render");
    let mut images = Vec::new();
    for file in ["dome.glb", "dome.obj"] {
        let scene = dir.join(format!("{file}.ron"));
        std::fs::write(&scene, dome(file)).unwrap();
        let out = dir.join(format!("{file}.exr"));
        ok(voltex(&["render", s(&scene), "--size", "32x32", "-o", s(&out)]));
        images.push(voltex::io::exr::read(&out).unwrap().0);
    }
    assert!(images[0].pixels.iter().any(|p| p[0] > 0.1), "the dome is drawn");
    assert_eq!(images[0].pixels, images[1].pixels);
}

#[test]
fn broken_gltf_names_the_file_and_writes_nothing() {
    let dir = scratch_dir("voltex-gltf-broken");
    let glb = std::fs::read(root().join("scenes/view_slices/meshes/dome.glb")).unwrap();
    let cases: [(&str, Vec<u8>, &str); 3] = [
        ("truncated.glb", glb[..glb.len() / 2].to_vec(), "not a valid glTF 2.0 file"),
        ("empty.gltf", b"{\"asset\": {\"version\": \"2.0\"}}".to_vec(), "expected at least one triangle"),
        ("junk.glb", b"glTF\x02\0\0\0junk".to_vec(), "not a valid glTF 2.0 file"),
    ];
    for (name, bytes, expected) in cases {
        let mesh = dir.join(name);
        std::fs::write(&mesh, bytes).unwrap();
        let scene = dir.join(format!("{name}.ron"));
        std::fs::write(
            &scene,
            dome("dome.glb").replace(s(&root().join("scenes/view_slices/meshes/dome.glb")), s(&mesh)),
        )
        .unwrap();
        let out = dir.join(format!("{name}.exr"));
        let run = voltex(&["render", s(&scene), "--size", "16x16", "-o", s(&out)]);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains(s(&mesh)) && err.contains(expected), "{name}: {err}");
        assert!(!out.exists());
    }
}

/// The dome's glb with TEXCOORD_0 dropped from its primitive, written as `dir/no_uvs.glb`.
pub(crate) fn uvless_glb(dir: &std::path::Path) -> std::path::PathBuf {
    let glb = std::fs::read(root().join("scenes/view_slices/meshes/dome.glb")).unwrap();
    let at = String::from_utf8_lossy(&glb).find("\"TEXCOORD_0\":1,").unwrap();
    let mut edited = glb.clone();
    edited.splice(at..at + 15, b"               ".iter().copied());
    let mesh = dir.join("no_uvs.glb");
    std::fs::write(&mesh, edited).unwrap();
    mesh
}

/// A glTF primitive without uvs takes planar ones, as an OBJ without `vt` does (issue 32: it was
/// refused), with a warning at its path; `import` and the asset opened directly take it too.
#[test]
fn a_base_surface_without_uvs_gets_planar_uvs_and_a_warning_at_its_path() {
    let dir = scratch_dir("voltex-gltf-no-uvs");
    let mesh = uvless_glb(&dir);
    let scene = dir.join("no_uvs.ron");
    let text = dome("dome.glb").replace(s(&root().join("scenes/view_slices/meshes/dome.glb")), s(&mesh));
    let line = text.lines().position(|l| l.contains("no_uvs.glb")).unwrap() + 1;
    std::fs::write(&scene, text).unwrap();
    let run = voltex(&["render", s(&scene), "--size", "16x16", "-o", s(&dir.join("no_uvs.exr"))]);
    let err = stderr(&run);
    assert!(run.status.success(), "{err}");
    assert!(err.contains(&format!("no_uvs.ron:{line}:")) && err.contains("planar uvs"), "{err}");
    let (image, _) = voltex::io::exr::read(&dir.join("no_uvs.exr")).unwrap();
    assert!(image.pixels.iter().any(|p| p[3] > 0.0), "nothing drawn");
    let imported = dir.join("imported.ron");
    let run = voltex(&["import", s(&mesh), "-o", s(&imported)]);
    assert!(run.status.success() && stderr(&run).contains("planar uvs"), "{}", stderr(&run));
    ok(voltex(&["plan", s(&imported)]));
}

/// `voltex render FILE.glb` opens the asset as the scene `voltex import` writes, so both render
/// the same image; the written scene names the mesh relative to itself and says where it came from.
#[test]
fn an_asset_opens_directly_and_imports_as_the_same_scene() {
    let dir = scratch_dir("voltex-gltf-import");
    let glb = dir.join("dome.glb");
    std::fs::copy(root().join("scenes/view_slices/meshes/dome.glb"), &glb).unwrap();
    let scene = dir.join("scenes/dome.ron");
    std::fs::create_dir_all(scene.parent().unwrap()).unwrap();
    ok(voltex(&["import", s(&glb), "-o", s(&scene)]));
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("Written by `voltex import` around dome.glb"), "{text}");
    // Outside the scene's folder: relative all the same (issue 32), so the pair can move.
    assert!(text.contains("surface: Mesh(path: \"../dome.glb\")"), "{text}");
    let mut images = Vec::new();
    for (input, out) in [(&glb, "direct.exr"), (&scene, "imported.exr")] {
        let out = dir.join(out);
        ok(voltex(&["render", s(input), "--size", "24x24", "-o", s(&out)]));
        images.push(voltex::io::exr::read(&out).unwrap().0);
    }
    assert_eq!(images[0].pixels, images[1].pixels);
    // Beside the asset, the path is relative; `plan` reads the asset too.
    ok(voltex(&["import", s(&glb)]));
    assert!(std::fs::read_to_string(dir.join("dome.ron")).unwrap().contains("Mesh(path: \"dome.glb\")"));
    assert!(ok(voltex(&["plan", s(&glb)])).contains("ViewSlices planes 256"));
    // Not an asset: a clear error, nothing written.
    let run = voltex(&["import", s(&scene), "-o", s(&dir.join("x.ron"))]);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains("expected an asset: a mesh (.glb, .gltf or .obj) or an OpenVDB file (.vdb)")
    );
    assert!(!dir.join("x.ron").exists());
}

/// Writes `values` (row-major from the top) as a one-channel (`Y`) f32 EXR.
fn write_grey_exr(path: &std::path::Path, width: usize, height: usize, values: Vec<f32>) {
    use exr::prelude::*;
    let channel = AnyChannel::new("Y", FlatSamples::F32(values));
    let layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(vec![channel].into()),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn an_exr_height_image_renders_as_the_png_with_its_values() {
    let dir = scratch_dir("voltex-exr-heights");
    let scenes = root().join("scenes/meyer_neyret");
    let png = voltex::scene::HeightImage::load(&scenes.join("cobbles.png")).unwrap();
    let grey: Vec<f32> = png.data.iter().step_by(png.channels).copied().collect();
    let exr = dir.join("cobbles.exr");
    write_grey_exr(&exr, png.width, png.height, grey.clone());
    let loaded = voltex::scene::HeightImage::load(&exr).unwrap();
    assert_eq!((loaded.width, loaded.height, loaded.channels), (png.width, png.height, 1));
    assert_eq!(loaded.data, grey);
    let text = std::fs::read_to_string(scenes.join("heightfield_image.ron")).unwrap();
    let mut images = Vec::new();
    for image in [scenes.join("cobbles.png"), exr.clone()] {
        let scene = dir.join("scene.ron");
        std::fs::write(&scene, text.replace("\"cobbles.png\"", &format!("{:?}", s(&image)))).unwrap();
        let out = dir.join("out.exr");
        ok(voltex(&["render", s(&scene), "--size", "24x24", "-o", s(&out)]));
        images.push(voltex::io::exr::read(&out).unwrap().0);
    }
    assert_eq!(images[0].pixels, images[1].pixels);
    // A non-finite height is an error naming the channel and pixel.
    let mut bad = grey;
    bad[png.width + 2] = f32::NAN;
    write_grey_exr(&exr, png.width, png.height, bad);
    let e = voltex::scene::HeightImage::load(&exr).unwrap_err().to_string();
    assert!(e.contains("cobbles.exr") && e.contains("channel Y: pixel (2, 1) is not finite"), "{e}");
}
