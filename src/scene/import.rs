//! Open and look: a scene written around a mesh asset (`.glb`, `.gltf`, `.obj`) so that
//! `voltex render|preview|plan FILE.glb` show it directly and `voltex import` writes it out as an
//! editable, commented scene file. The mesh is a base surface under a default texel, framed by a
//! camera and lit by one light.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};

use crate::error::{Error, Result};

/// Whether `path` names a mesh asset rather than a scene file.
pub fn is_asset(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("glb" | "gltf" | "obj"))
}

/// Scene text around the mesh asset `asset`, which the scene names as `mesh_path` (relative to
/// the scene file's folder, or absolute).
pub fn scene_text(asset: &Path, mesh_path: &str) -> Result<String> {
    let mesh = crate::mesh::load(asset)?;
    let gltf = !asset.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if mesh.uvs_missing {
        return Err(Error::file(asset, "a primitive has no TEXCOORD_0: a base surface needs uvs"));
    }
    // glTF is y-up (and so are most OBJ exports); voltex scenes are z-up.
    let rotate = DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
    let (lo, hi) = mesh.positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        let p = rotate.transform_point3(*p);
        (lo.min(p), hi.max(p))
    });
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let height = 0.04 * 2.0 * radius;
    // Uv tiles about four heights wide, over the surface's extent.
    let area: f64 = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let tiles = (area.sqrt() / (4.0 * height)).round().clamp(1.0, 64.0);
    let fov: f64 = 40.0;
    let distance = 1.15 * radius / (0.5 * fov.to_radians()).sin();
    let eye = centre + DVec3::new(0.55, -1.0, 0.6).normalize() * distance;
    let name = asset.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").replace('"', "'");
    let v = |p: DVec3| format!("({}, {}, {})", num(p.x), num(p.y), num(p.z));
    Ok(format!(
        r#"// Written by `voltex import` around {file} ({triangles} triangles after welding).
// Edit freely: the mesh is a base surface under the texel "grain", drawn with ViewSlices.
#![enable(implicit_some)]
Scene(
    output: (width: 512, height: 512),
    regress: (size: (128, 128)),
    // Framing the mesh's bounds {lo} to {hi} (after the rotation below).
    camera: (eye: {eye}, target: {centre}, up: (0.0, 0.0, 1.0), fov_y: {fov:.1}),
    background: (0.05, 0.05, 0.07),
    ambient: 0.25,
    lights: [Directional(direction: (-0.4, 0.55, -0.75), intensity: 1.0)],
    texels: {{
        // The default texel: grains of sand, one per uv tile.
        "grain": (
            resolution: (32, 32, 32),
            opacity_length: 0.05,
            source: Implicit(shapes: [
                Sphere(center: (0.5, 0.5, 0.35), radius: 0.3, color: (0.85, 0.7, 0.45), opacity: 1.0),
            ]),
        ),
    }},
    nodes: [
        (
            name: "{name}",
            // {up} is y-up; voltex scenes are z-up.
            transform: (rotate: (90.0, 0.0, 0.0)),
            surface: Obj(path: {mesh}),
            height: (length: {height}),
            uv_tiling: ({tiles:.0}, {tiles:.0}),
            texel: "grain",
            base_color: (0.35, 0.3, 0.28),
            method: ViewSlices(planes: 256),
        ),
    ],
)
"#,
        file = asset.file_name().and_then(|s| s.to_str()).unwrap_or("the mesh"),
        triangles = mesh.triangles.len(),
        lo = v(lo),
        hi = v(hi),
        eye = v(eye),
        centre = v(centre),
        height = num(height),
        mesh = ron_string(mesh_path),
        up = if gltf { "glTF" } else { "An OBJ export" },
    ))
}

/// A number rounded to 6 significant digits (an editable file, not a dump).
fn num(x: f64) -> String {
    let s = format!("{:.6e}", x);
    let v: f64 = s.parse().unwrap_or(x);
    let mut out = format!("{v}");
    if !out.contains('.') && !out.contains('e') {
        out += ".0";
    }
    out
}

fn ron_string(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// The path by which a scene written to `scene` names `asset`: relative when the asset lies in
/// the scene's folder or below, else absolute.
pub fn mesh_path(asset: &Path, scene: &Path) -> PathBuf {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (asset, dir) = (absolute(asset), absolute(scene.parent().unwrap_or(Path::new(""))));
    asset.strip_prefix(&dir).map(Path::to_path_buf).unwrap_or(asset)
}
