//! glTF 2.0 reader for base surfaces and pattern meshes (`.gltf` with its buffers, or `.glb`):
//! every triangle primitive of every node of the default scene (or of all scenes), with the
//! node transforms flattened; positions, `TEXCOORD_0` (v flipped to the OBJ convention, origin
//! bottom left) and `COLOR_0`. Vertices are welded by position, as OBJ vertices are by index, so
//! that a uv or normal seam does not crack the shell; normals are recomputed from the welded
//! surface for the same reason. Byte ranges are checked before any accessor is read.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat3, DMat4, DVec2, DVec3};
use gltf::mesh::Mode;

use super::{area_weighted_normals, Mesh};
use crate::error::{Error, Result};

/// Reads and parses a `.gltf` or `.glb` file; external buffers are read beside it.
pub(crate) fn load(path: &Path) -> Result<Mesh> {
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "a glTF file")?;
    parse(&bytes, path)
}

/// Parses glTF or GLB bytes; `path` names the file in errors and locates external buffers.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let fail = |msg: String| Error::file(path, msg);
    check_position_accessors(bytes).map_err(fail)?;
    // The loader's validation has panicked on input it should reject (see above): a panic is
    // still this file's error, not voltex's.
    let file = crate::error::quietly(|| gltf::Gltf::from_slice(bytes))
        .map_err(|_| fail("not a valid glTF 2.0 file: the glTF loader failed on it".into()))?
        .map_err(|e| fail(format!("not a valid glTF 2.0 file: {e}")))?;
    let buffers = file
        .buffers()
        .map(|b| buffer_data(&b, file.blob.as_deref(), path))
        .collect::<Result<Vec<Vec<u8>>>>()?;
    let mut out = Welded::default();
    let roots: Vec<gltf::Node> = match file.default_scene() {
        Some(scene) => scene.nodes().collect(),
        None => file.scenes().flat_map(|s| s.nodes()).collect(),
    };
    for node in roots {
        visit(&node, DMat4::IDENTITY, &buffers, &mut out, path, 0)?;
    }
    if out.triangles.is_empty() {
        return Err(fail("expected at least one triangle primitive in the scene's nodes".into()));
    }
    Ok(out.finish())
}

/// gltf-json 1.4 validates a primitive's `POSITION` accessor by indexing the accessor list
/// unchecked, and panics when the index is out of range: check that first (found by fuzzing).
fn check_position_accessors(bytes: &[u8]) -> std::result::Result<(), String> {
    let json = match bytes.get(..4) {
        Some(b"glTF") => {
            let len = bytes.get(12..16).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
            bytes.get(20..20usize.saturating_add(len)).unwrap_or_default()
        }
        _ => bytes,
    };
    // Not JSON, or not as expected: the loader says what is wrong.
    let Ok(doc) = serde_json::from_slice::<serde_json::Value>(json) else { return Ok(()) };
    let accessors = doc["accessors"].as_array().map_or(0, Vec::len) as u64;
    for (m, mesh) in doc["meshes"].as_array().into_iter().flatten().enumerate() {
        for (p, prim) in mesh["primitives"].as_array().into_iter().flatten().enumerate() {
            if let Some(i) = prim["attributes"]["POSITION"].as_u64().filter(|&i| i >= accessors) {
                return Err(format!(
                    "mesh {m} primitive {p}: POSITION accessor {i} out of range: {accessors} accessors"
                ));
            }
        }
    }
    Ok(())
}

/// The bytes of a buffer: the GLB's binary chunk, a base64 `data:` URI, or a file beside `path`.
fn buffer_data(b: &gltf::Buffer, blob: Option<&[u8]>, path: &Path) -> Result<Vec<u8>> {
    let what = format!("buffer {}", b.index());
    let data = match b.source() {
        gltf::buffer::Source::Bin => blob
            .ok_or_else(|| Error::file(path, format!("{what} refers to a GLB binary chunk the file lacks")))?
            .to_vec(),
        gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
            let (_, payload) = uri
                .split_once(";base64,")
                .ok_or_else(|| Error::file(path, format!("{what}: expected a base64 `data:` URI")))?;
            base64(payload)
                .ok_or_else(|| Error::file(path, format!("{what}: the data URI is not valid base64")))?
        }
        gltf::buffer::Source::Uri(uri) => {
            if uri.contains("://") {
                return Err(Error::file(path, format!("{what}: `{uri}` is not a file beside the glTF")));
            }
            let file = path.parent().unwrap_or(Path::new(".")).join(uri.replace("%20", " "));
            crate::input::read(&file, crate::input::Kind::Asset, "a glTF buffer")
                .map_err(|e| Error::file(path, format!("{what}: {e}")))?
        }
    };
    if (data.len() as u64) < b.length() as u64 {
        return Err(Error::file(path, format!("{what} holds {} bytes, expected {}", data.len(), b.length())));
    }
    Ok(data)
}

/// Decodes standard base64 (padding optional); `None` on any other character.
fn base64(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' => Some(62),
        b'/' => Some(63),
        _ => None,
    };
    let digits = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0);
    for &c in digits {
        acc = (acc << 6) | value(c)? as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    Some(out)
}

/// Most nested nodes followed: a deeper tree is a cycle or not a real asset.
const MAX_DEPTH: usize = 256;

fn visit(
    node: &gltf::Node,
    parent: DMat4,
    buffers: &[Vec<u8>],
    out: &mut Welded,
    path: &Path,
    depth: usize,
) -> Result<()> {
    let name =
        || node.name().map_or(format!("node {}", node.index()), |n| format!("node {} \"{n}\"", node.index()));
    if depth > MAX_DEPTH {
        return Err(Error::file(path, format!("{}: nodes nested deeper than {MAX_DEPTH}", name())));
    }
    let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(|v| v as f64)));
    let world = parent * local;
    if let Some(mesh) = node.mesh() {
        let det = DMat3::from_mat4(world).determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return Err(Error::file(
                path,
                format!("{}: its transform has zero scale or is not finite", name()),
            ));
        }
        for p in mesh.primitives() {
            let what = format!("{}, mesh {} primitive {}", name(), mesh.index(), p.index());
            primitive(&p, &world, det < 0.0, buffers, out)
                .map_err(|e| Error::file(path, format!("{what}: {e}")))?;
        }
    }
    for child in node.children() {
        visit(&child, world, buffers, out, path, depth + 1)?;
    }
    Ok(())
}

/// Checks that an accessor's elements lie inside its view and the view inside its buffer.
fn check_range(a: &gltf::Accessor, buffers: &[Vec<u8>]) -> std::result::Result<(), String> {
    let what = format!("accessor {}", a.index());
    if a.sparse().is_some() {
        return Err(format!("{what} is sparse: not supported"));
    }
    let view = a.view().ok_or_else(|| format!("{what} has no buffer view"))?;
    let data = &buffers[view.buffer().index()];
    let view_end = view.offset() as u64 + view.length() as u64;
    if view_end > data.len() as u64 {
        return Err(format!(
            "buffer view {} ends at byte {view_end}, past its buffer's {}",
            view.index(),
            data.len()
        ));
    }
    let stride = view.stride().unwrap_or(a.size()) as u64;
    let end = match a.count() {
        0 => 0,
        n => a.offset() as u64 + stride * (n as u64 - 1) + a.size() as u64,
    };
    if end > view.length() as u64 {
        return Err(format!(
            "{what} reads {end} bytes of buffer view {}, which holds {}",
            view.index(),
            view.length()
        ));
    }
    Ok(())
}

/// The component types and dimensions glTF allows for the attributes read here (the loader's
/// readers assume them and panic otherwise).
fn check_type(semantic: &gltf::Semantic, a: &gltf::Accessor) -> std::result::Result<(), String> {
    use gltf::accessor::{DataType::*, Dimensions::*};
    use gltf::Semantic::*;
    let ok = match (semantic, a.data_type(), a.dimensions()) {
        (Positions, F32, Vec3) => true,
        (Positions, ..) => false,
        (TexCoords(_), F32 | U8 | U16, Vec2) => true,
        (TexCoords(_), ..) => false,
        (Colors(_), F32 | U8 | U16, Vec3 | Vec4) => true,
        (Colors(_), ..) => false,
        _ => true,
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{semantic:?} accessor {}: {:?} {:?} is not a type glTF allows for it",
            a.index(),
            a.data_type(),
            a.dimensions()
        ))
    }
}

fn primitive(
    p: &gltf::Primitive,
    world: &DMat4,
    mirrored: bool,
    buffers: &[Vec<u8>],
    out: &mut Welded,
) -> std::result::Result<(), String> {
    if p.mode() != Mode::Triangles {
        return Err(format!("mode {:?}: expected triangles", p.mode()));
    }
    for (semantic, a) in p.attributes() {
        check_range(&a, buffers)?;
        check_type(&semantic, &a)?;
    }
    if let Some(a) = p.indices() {
        check_range(&a, buffers)?;
        use gltf::accessor::{DataType::*, Dimensions::Scalar};
        if !matches!((a.data_type(), a.dimensions()), (U8 | U16 | U32, Scalar)) {
            return Err(format!("indices accessor {}: expected unsigned integer scalars", a.index()));
        }
    }
    let reader = p.reader(|b| buffers.get(b.index()).map(|d| d.as_slice()));
    let positions: Vec<DVec3> = reader
        .read_positions()
        .ok_or("no POSITION attribute")?
        .map(|v| world.transform_point3(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)))
        .collect();
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("position {i} is not finite"));
    }
    let uvs: Option<Vec<DVec2>> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().map(|[u, v]| DVec2::new(u as f64, 1.0 - v as f64)).collect());
    let colors: Option<Vec<[f64; 3]>> =
        reader.read_colors(0).map(|c| c.into_rgb_f32().map(|c| c.map(|v| v as f64)).collect());
    for (what, n) in [("TEXCOORD_0", uvs.as_ref().map(Vec::len)), ("COLOR_0", colors.as_ref().map(Vec::len))]
    {
        if n.is_some_and(|n| n != positions.len()) {
            return Err(format!("{what} has {} elements, POSITION {}", n.unwrap_or(0), positions.len()));
        }
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(format!("{} indices: expected a multiple of 3", indices.len()));
    }
    if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(format!("index {i} out of range: {} vertices", positions.len()));
    }
    out.uvs_missing |= uvs.is_none();
    for t in indices.chunks_exact(3) {
        let t = if mirrored { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
        let corners = t.map(|i| out.vertex(positions[i as usize], colors.as_ref().map(|c| c[i as usize])));
        out.triangles.push(corners);
        out.corner_uvs.push(t.map(|i| uvs.as_ref().map(|u| u[i as usize])));
    }
    Ok(())
}

/// Vertices welded by position, with what the first corner at each brought.
#[derive(Default)]
struct Welded {
    index: HashMap<[u64; 3], u32>,
    positions: Vec<DVec3>,
    colors: Vec<Option<[f64; 3]>>,
    triangles: Vec<[u32; 3]>,
    corner_uvs: Vec<[Option<DVec2>; 3]>,
    uvs_missing: bool,
}

impl Welded {
    fn vertex(&mut self, p: DVec3, color: Option<[f64; 3]>) -> u32 {
        // +0.0 and -0.0 are one position.
        let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            self.colors.push(color);
            self.positions.len() as u32 - 1
        })
    }

    fn finish(self) -> Mesh {
        // Corners without TEXCOORD_0 take planar uvs from the x, y bounds, as OBJ corners without `vt`.
        let (lo, hi) = self
            .positions
            .iter()
            .fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(p.truncate()), hi.max(p.truncate()))
            });
        let extent = (hi - lo).max(DVec2::splat(1e-300));
        let corner_uvs = self
            .triangles
            .iter()
            .zip(&self.corner_uvs)
            .map(|(t, uvs)| {
                [0, 1, 2].map(|k| uvs[k].unwrap_or((self.positions[t[k] as usize].truncate() - lo) / extent))
            })
            .collect();
        let (attribute, colors) = if self.colors.iter().any(Option::is_some) {
            let attribute = self.colors.iter().map(|c| c.map_or(0.0, |c| c[0])).collect();
            (Some(attribute), Some(self.colors.iter().map(|c| c.unwrap_or([1.0; 3])).collect()))
        } else {
            (None, None)
        };
        let mut m = Mesh {
            normals: area_weighted_normals(&self.positions, &self.triangles),
            positions: self.positions,
            triangles: self.triangles,
            corner_uvs,
            vertex_uvs: vec![],
            attribute,
            colors,
            face_lines: vec![],
            uvs_missing: self.uvs_missing,
        };
        m.vertex_uvs = m.vertex_uvs_from_corners();
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b64(bytes: &[u8]) -> String {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        bytes
            .chunks(3)
            .flat_map(|c| {
                let n = c.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
                (0..=c.len()).map(move |i| A[(n >> (18 - 6 * i) & 63) as usize] as char)
            })
            .collect()
    }

    /// A unit square of two triangles (4 vertices, uvs), placed twice: at the origin, and by a
    /// child node translated by (2, 0, 0) and mirrored in x.
    fn square(uvs: bool) -> String {
        let pos: [f32; 12] = [0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
        let uv: [f32; 8] = [0., 1., 1., 1., 1., 0., 0., 0.];
        let idx: [u16; 6] = [0, 1, 2, 0, 2, 3];
        let mut bin: Vec<u8> = bytemuck::cast_slice(&pos).to_vec();
        bin.extend(bytemuck::cast_slice(&uv));
        bin.extend(bytemuck::cast_slice(&idx));
        let tex = if uvs { r#", "TEXCOORD_0": 1"# } else { "" };
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
            "nodes": [{{"mesh": 0, "children": [1]}}, {{"mesh": 0, "translation": [2, 0, 0], "scale": [-1, 1, 1]}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0{tex}}}, "indices": 2}}]}}],
            "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
            "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                            {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
                            {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                            "min": [0, 0, 0], "max": [1, 1, 0]}},
                          {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
                          {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}]}}"#,
            bin.len(),
            b64(&bin)
        )
    }

    #[test]
    fn reads_nodes_with_their_transforms_welded_and_facing_out() {
        let m = parse(square(true).as_bytes(), Path::new("sq.gltf")).unwrap();
        assert_eq!(m.triangles.len(), 4);
        // The two squares share the edge x = 1: 4 + 4 - 2 vertices.
        assert_eq!(m.positions.len(), 6);
        assert!(m.positions.contains(&DVec3::new(2.0, 1.0, 0.0)));
        // Mirrored in x, the copy's winding is flipped so that both face +z.
        assert!(m.normals.iter().all(|n| (*n - DVec3::Z).length() < 1e-12), "{:?}", m.normals);
        // v flipped to the OBJ convention: the corner at (0, 0, 0) has uv (0, 0).
        assert_eq!(m.corner_uvs[0][0], DVec2::ZERO);
        assert_eq!(m.corner_uvs[0][2], DVec2::ONE);
        assert!(!m.uvs_missing);
        assert!(parse(square(false).as_bytes(), Path::new("sq.gltf")).unwrap().uvs_missing);
    }

    #[test]
    fn reads_glb_alike() {
        let json = square(true);
        let mut glb = b"glTF".to_vec();
        let padded = json.len().div_ceil(4) * 4;
        glb.extend(2u32.to_le_bytes());
        glb.extend(((12 + 8 + padded) as u32).to_le_bytes());
        glb.extend((padded as u32).to_le_bytes());
        glb.extend(b"JSON");
        glb.extend(json.as_bytes());
        glb.resize(12 + 8 + padded, b' ');
        let a = parse(&glb, Path::new("sq.glb")).unwrap();
        let b = parse(json.as_bytes(), Path::new("sq.gltf")).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn bad_files_name_what_is_wrong() {
        let err = |text: String| parse(text.as_bytes(), Path::new("bad.gltf")).unwrap_err().to_string();
        let e = err("{\"asset\": ".into());
        assert!(e.starts_with("bad.gltf") && e.contains("not a valid glTF"), "{e}");
        // An accessor reading past its view.
        let e = err(square(true).replace(r#""count": 6"#, r#""count": 600"#));
        assert!(e.contains("accessor 2 reads 1200 bytes of buffer view 2, which holds 12"), "{e}");
        let e = err(square(true).replace(r#""scale": [-1, 1, 1]"#, r#""scale": [0, 1, 1]"#));
        assert!(e.contains("node 1: its transform has zero scale"), "{e}");
        let e = err(square(true).replace(r#""indices": 2"#, r#""indices": 2, "mode": 1"#));
        assert!(e.contains("mesh 0 primitive 0: mode Lines: expected triangles"), "{e}");
        let e = err(square(true).replace(";base64,", ";base64,*"));
        assert!(e.contains("buffer 0: the data URI is not valid base64"), "{e}");
        let e = err(square(true).replace("data:application/octet-stream;base64,", "missing.bin#"));
        assert!(e.contains("buffer 0") && e.contains("missing.bin"), "{e}");
    }
}
