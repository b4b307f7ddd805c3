//! Open and look: a scene written around an asset (a mesh: `.glb`, `.gltf`, `.obj`; a volume:
//! `.vdb`) so that `voltex render|preview|plan FILE` show it directly and `voltex import` writes
//! it out as an editable, commented scene file. A mesh is a base surface under a default texel,
//! a volume a volume object; either is framed by a camera and lit by one light.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};

use crate::error::{Error, Result};

/// Whether `path` names an asset (a mesh or an OpenVDB file) rather than a scene file.
pub fn is_asset(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("glb" | "gltf" | "obj" | "vdb"))
}

fn is_volume(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
}

/// The preset a mesh gets without `--preset`.
pub(crate) const DEFAULT_PRESET: &str = "grain";

/// The presets `voltex import --preset` puts on a mesh: the scene files under `scenes/presets/`
/// (built into the binary), by name, sorted.
pub(crate) fn presets() -> Vec<&'static str> {
    let names = crate::gpu::sources::embedded_files().iter();
    names.filter_map(|(p, _)| p.strip_prefix("scenes/presets/")?.strip_suffix(".ron")).collect()
}

/// A preset's look, from its scene file: the text of its `texels` entries and its node's
/// texel, height, uv tiles, base colour and method, for a sphere of radius 1.
pub(crate) struct Look {
    name: String,
    /// What it is: the first comment line's text after the name.
    pub(crate) what: String,
    /// The lines inside the file's `texels: { ... }`.
    pub(crate) texels: String,
    pub(crate) texel: String,
    height: f64,
    /// The edge of a uv tile (the sphere's area over its tile count, square rooted).
    tile: f64,
    pub(crate) base_color: String,
    pub(crate) method: String,
}

/// The preset `name` (see [`presets`]), or an error listing them.
pub(crate) fn look(name: &str) -> Result<Look> {
    let rel = format!("scenes/presets/{name}.ron");
    let Some(text) = crate::gpu::sources::embedded(&rel) else {
        return Err(Error::Invalid(format!("no preset `{name}`: expected one of {}", presets().join(", "))));
    };
    let path = PathBuf::from(crate::gpu::sources::EMBEDDED_PREFIX).join(&rel);
    let scene = crate::scene::parse(text, &path)?;
    let node = scene.nodes.first().ok_or_else(|| Error::file(&path, "a preset has a node"))?;
    // The node's fields as written (comments and formatting kept), by their line.
    let field = |key: &str| -> Result<String> {
        let at = text.lines().find_map(|l| l.trim().strip_prefix(&format!("{key}: "))?.strip_suffix(','));
        at.map(str::to_string)
            .ok_or_else(|| Error::file(&path, format!("a preset's node writes `{key}` on a line")))
    };
    let start = text
        .find("\n    texels: {\n")
        .ok_or_else(|| Error::file(&path, "expected `texels: {` at the top"))?;
    let body = &text[start + "\n    texels: {\n".len()..];
    let end = body.find("\n    },\n").ok_or_else(|| Error::file(&path, "expected `}` closing `texels`"))?;
    let (u, v) = (node.uv_tiling[0].max(1e-6), node.uv_tiling[1].max(1e-6));
    Ok(Look {
        name: name.to_string(),
        what: text
            .lines()
            .next()
            .and_then(|l| l.split_once("): "))
            .map_or(String::new(), |w| w.1.to_string()),
        texels: body[..end].to_string(),
        texel: node.texel.as_ref().map(|t| t.to_string()).unwrap_or_default(),
        height: node.height.length,
        tile: (4.0 * std::f64::consts::PI / (u * v)).sqrt(),
        base_color: field("base_color")?,
        method: field("method")?,
    })
}

/// Scene text around the asset `asset`, which the scene names as `mesh_path` (relative to the
/// scene file's folder: see [`mesh_path`]); a mesh gets the look of `preset` (default
/// [`DEFAULT_PRESET`]).
pub fn scene_text(asset: &Path, mesh_path: &str, preset: Option<&str>) -> Result<String> {
    if is_volume(asset) {
        return match preset {
            Some(p) => Err(Error::Invalid(format!(
                "{}: --preset {p} puts a look on a mesh; an OpenVDB file is drawn as a volume",
                asset.display()
            ))),
            None => volume_scene_text(asset, mesh_path),
        };
    }
    let look = look(preset.unwrap_or(DEFAULT_PRESET))?;
    let mesh = crate::mesh::load(asset)?;
    let gltf = !asset.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if mesh.uvs_missing {
        eprintln!(
            "warning: {}: a primitive has no TEXCOORD_0: its corners take planar uvs from the mesh's x, y \
             bounds",
            asset.display()
        );
    }
    // glTF is y-up (and so are most OBJ exports); voltex scenes are z-up.
    let rotate = DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
    let (lo, hi) = mesh.positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        let p = rotate.transform_point3(*p);
        (lo.min(p), hi.max(p))
    });
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    // The preset's height and tile size, shown on a sphere of radius 1, scaled to the mesh's
    // bounding radius; the tiles over the surface's extent. The height is halved until the
    // mesh's prisms are valid: a mesh more curved than the sphere may not take it.
    let mut height = look.height * radius;
    let mut halved = 0;
    while halved < 8 && !crate::mesh::prism::check(&mesh.to_base(height, None, glam::DVec2::ONE)).is_ok() {
        height *= 0.5;
        halved += 1;
    }
    let height_note = match halved {
        0 => String::new(),
        n => format!(
            "            // The preset's height ({} x the mesh's radius) twists prisms at this mesh's curvature: halved {n} time(s).\n",
            num(look.height)
        ),
    };
    let area: f64 = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let tiles = (area.sqrt() / (look.tile * radius)).round().clamp(1.0, 64.0);
    let fov: f64 = 40.0;
    let distance = 1.15 * radius / (0.5 * fov.to_radians()).sin();
    let eye = centre + DVec3::new(0.55, -1.0, 0.6).normalize() * distance;
    let name = asset.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").replace('"', "'");
    let v = |p: DVec3| format!("({}, {}, {})", num(p.x), num(p.y), num(p.z));
    Ok(format!(
        r#"// Written by `voltex import` around {file} ({triangles} triangles after welding).
// Edit freely: the mesh is a base surface under the texel "{texel}" of the preset "{preset}"
// ({what}); scenes/presets/{preset}.ron shows it on a sphere.
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
{texels}
    }},
    nodes: [
        (
            name: "{name}",
            // {up} is y-up; voltex scenes are z-up.
            transform: (rotate: (90.0, 0.0, 0.0)),
            surface: Mesh(path: {mesh}),
{height_note}            height: (length: {height}),
            uv_tiling: ({tiles:.0}, {tiles:.0}),
            texel: "{texel}",
            base_color: {base_color},
            method: {method},
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
        texels = look.texels,
        texel = look.texel,
        preset = look.name,
        what = look.what.trim_end_matches('.'),
        base_color = look.base_color,
        // Without --preset, the method the registry's knobs name for imports (`MethodKnobs::imported`).
        method = if preset.is_some() { look.method.as_str() } else { crate::scene::Method::imported(false) },
    ))
}

/// Scene text around the OpenVDB file `asset` (named `vdb_path` by the scene): its density grid
/// (`density`, else its first float grid) with `Cd` as colour when the file has it, as a volume
/// object framed by a camera and lit by one light.
fn volume_scene_text(asset: &Path, vdb_path: &str) -> Result<String> {
    let grids = crate::vdb::grids(asset)?;
    let float = |g: &&crate::vdb::GridInfo| g.value == "float";
    let density = grids.iter().find(|g| g.name == "density" && float(g)).or_else(|| grids.iter().find(float));
    let Some(density) = density else {
        return Err(Error::file(
            asset,
            format!("expected a float grid to draw as density: {}", crate::vdb::list(&grids)),
        ));
    };
    let color = grids.iter().find(|g| g.name == "Cd" && g.value == "vec3s").map(|g| g.name.clone());
    let request = crate::vdb::Request { density: density.name.clone(), color: color.clone(), band: 1.0 };
    let grid = crate::vdb::load(asset, &request)?;
    let corners = grid.world_corners(&DMat4::IDENTITY);
    let (lo, hi) = corners.iter().fold((corners[0], corners[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let fov: f64 = 40.0;
    let distance = 1.15 * radius / (0.5 * fov.to_radians()).sin();
    let eye = centre + DVec3::new(0.55, -1.0, 0.6).normalize() * distance;
    // The file's densities as extinction per world unit when they make a visible volume (an
    // optical depth between 1/2 and 50 across 16 voxels at the densest voxel), else scaled so
    // that it is 4.
    let across = grid.max_density as f64 * 16.0 * crate::vdb::voxel_size(&grid.index_to_world);
    let (scale, why) = if (0.5..=50.0).contains(&across) {
        (1.0, "the file's densities as they are".to_string())
    } else {
        let why =
            format!("the file's densities would give an optical depth of {} across 16 voxels", num(across));
        (4.0 / across.max(1e-30), why)
    };
    let v = |p: DVec3| format!("({}, {}, {})", num(p.x), num(p.y), num(p.z));
    let names: Vec<String> = grids
        .iter()
        .map(|g| {
            format!(
                "{} ({}{})",
                g.name,
                g.value,
                if g.class.is_empty() { String::new() } else { format!(", {}", g.class) }
            )
        })
        .collect();
    let name = asset.file_stem().and_then(|s| s.to_str()).unwrap_or("volume").replace('"', "'");
    let color_line = match &color {
        Some(c) => format!("color: {},", ron_string(c)),
        None => "// color: \"Cd\", (a vec3s grid of the file; white without one)".into(),
    };
    let band = if density.is_level_set() {
        "\n            band: 1.0, // a level set: density 1 inside, 0 outside, over 1 voxel"
    } else {
        ""
    };
    Ok(format!(
        r#"// Written by `voltex import` around {file}: grids {grids}.
// Edit freely: the grid "{grid}" is a volume object, ray-marched; density x density_scale is the
// extinction per world unit, the light it scatters albedo x color (docs: volumes.md).
#![enable(implicit_some)]
Scene(
    output: (width: 512, height: 512),
    regress: (size: (128, 128)),
    // Framing the density's bounds {lo} to {hi}.
    camera: (eye: {eye}, target: {centre}, up: (0.0, 0.0, 1.0), fov_y: {fov:.1}),
    background: (0.05, 0.05, 0.07),
    ambient: 0.25,
    lights: [Directional(direction: (-0.4, 0.55, -0.75), intensity: 1.0)],
    volumes: {{
        "{name}": (
            file: {path},
            grid: {grid_string},
            {color_line}
            density_scale: {scale}, // {why}
            albedo: (0.9, 0.9, 0.9),{band}
        ),
    }},
    nodes: [
        (name: "{name}", volume: "{name}", method: {method}),
    ],
)
"#,
        file = asset.file_name().and_then(|s| s.to_str()).unwrap_or("the file"),
        grids = names.join(", "),
        grid = density.name,
        grid_string = ron_string(&density.name),
        method = crate::scene::Method::imported(true),
        lo = v(lo),
        hi = v(hi),
        eye = v(eye),
        centre = v(centre),
        path = ron_string(vdb_path),
        scale = num(scale),
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

/// The path by which a scene written to `scene` names `asset`: relative to the scene's folder
/// (with `..` where the asset lies outside it), so that the pair moves together; absolute only
/// when the two share no root (another drive).
pub fn mesh_path(asset: &Path, scene: &Path) -> PathBuf {
    use std::path::Component;
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    // A bare file name's folder is the current one (`Path::parent` gives "", which has no
    // absolute form: the asset's absolute path was written).
    let folder = scene.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let (asset, dir) = (absolute(asset), absolute(folder));
    fn parts(p: &Path) -> Vec<std::path::Component<'_>> {
        p.components().filter(|c| *c != std::path::Component::CurDir).collect()
    }
    let (a, d) = (parts(&asset), parts(&dir));
    let shared = a.iter().zip(&d).take_while(|(x, y)| x == y).count();
    if shared == 0 {
        return asset;
    }
    let up = std::iter::repeat_n(Component::ParentDir, d.len() - shared);
    up.chain(a[shared..].iter().copied()).collect()
}
