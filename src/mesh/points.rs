//! Point sets (hypertexture `Points` objects, Gilet & Dischler 2009, section 5.1: a volumetric
//! object defined by point samples, each with a radial kernel): read from PLY (ASCII or binary
//! little-endian; `x`, `y`, `z` and an optional `radius` vertex property) or from the `v` lines
//! of an OBJ file, through `input` (bounded regular files). Every problem names the file and its
//! `line:col` (text) or byte offset (binary data).

use std::hash::{Hash, Hasher};
use std::path::Path;

use glam::DVec3;

use crate::error::{Error, FileLoc, Result};
use crate::mesh::shape::GridSpec;

/// Most points of one point set: its kernels (16 bytes each) and BVH (two 32-byte nodes per
/// point) stay under 96 MiB, checked from the PLY header's count before anything is read.
pub(crate) const MAX_POINTS: usize = 1 << 20;

/// Most kernels overlapping at the densest place ([`PointSet::overlap`]): the grid bake visits
/// each at every sample, within one invocation's loop budget.
pub(crate) const MAX_OVERLAP: f64 = 4096.0;

/// A point set in its node's frame: kernel centres and, when the file has a `radius` property,
/// per-point factors of the scene's kernel radius.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    /// The points (kernel centres).
    pub(crate) centres: Vec<DVec3>,
    /// Per point, the file's `radius` property (a factor of the scene's `radius`), if it has one.
    pub(crate) radii: Option<Vec<f64>>,
    /// Of centres and radii: the bake cache's key.
    pub(crate) hash: u64,
}

impl PointSet {
    /// A point set of `centres` with optional per-point radius factors.
    pub fn new(centres: Vec<DVec3>, radii: Option<Vec<f64>>) -> Self {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for p in &centres {
            p.to_array().map(f64::to_bits).hash(&mut h);
        }
        for r in radii.iter().flatten() {
            r.to_bits().hash(&mut h);
        }
        PointSet { centres, radii, hash: h.finish() }
    }

    /// The kernel radius of point `i` for the scene's `radius`.
    pub(crate) fn radius(&self, i: usize, radius: f64) -> f64 {
        self.radii.as_ref().map_or(radius, |r| r[i] * radius)
    }

    /// Where the kernels reach, (min, max), for the scene's `radius`.
    pub(crate) fn bounds(&self, radius: f64) -> (DVec3, DVec3) {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for (i, &p) in self.centres.iter().enumerate() {
            let r = DVec3::splat(self.radius(i, radius));
            (lo, hi) = (lo.min(p - r), hi.max(p + r));
        }
        (lo, hi)
    }

    /// The grid of `n` samples per axis over the kernels' bounds enlarged by the largest shift
    /// and two cells (as a mesh object's grid: the field is needed wherever a noise may shift a
    /// point from, and the outer samples stay outside every kernel).
    pub fn grid(&self, radius: f64, n: u32, max_shift: f64) -> GridSpec {
        let (lo, hi) = self.bounds(radius);
        let extent = (hi - lo).max_element() + 2.0 * max_shift;
        let pad = max_shift + 2.0 * extent / (n - 1) as f64;
        GridSpec { lo: lo - DVec3::splat(pad), hi: hi + DVec3::splat(pad), n: [n; 3], parity: false }
    }

    /// About how many kernels overlap at the densest place (points per cell of a 16^3 grid over
    /// the centres, times the largest kernel's volume over the cell's): the bake visits that
    /// many per sample.
    pub(crate) fn overlap(&self, radius: f64) -> f64 {
        const CELLS: usize = 16;
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for &p in &self.centres {
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        let r = (0..self.centres.len()).map(|i| self.radius(i, radius)).fold(0.0, f64::max);
        // Cells no smaller than a kernel, so a thin set is not counted as dense.
        let size = ((hi - lo) / CELLS as f64).max(DVec3::splat(r));
        let mut counts = vec![0u32; CELLS * CELLS * CELLS];
        for &p in &self.centres {
            let c = ((p - lo) / size).as_uvec3().min(glam::UVec3::splat(CELLS as u32 - 1));
            counts[c.x as usize + CELLS * (c.y as usize + CELLS * c.z as usize)] += 1;
        }
        let densest = *counts.iter().max().unwrap_or(&0) as f64;
        densest / (size.x * size.y * size.z) * (4.0 / 3.0 * std::f64::consts::PI * r * r * r)
    }
}

/// Reads a point set: `.ply` as PLY, anything else as OBJ (its `v` lines).
pub(crate) fn load(path: &Path) -> Result<PointSet> {
    let bytes = crate::input::read(path, crate::input::Kind::Asset, "a point set (.ply or .obj)")?;
    let set = match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("ply") => ply(path, &bytes)?,
        _ => obj(path, &crate::input::utf8(path, bytes)?)?,
    };
    if set.centres.is_empty() {
        return Err(Error::file(path, "expected at least one point, found none"));
    }
    Ok(set)
}

fn too_many(loc: FileLoc, n: u64) -> Error {
    Error::at(loc, format!("{n} points: at most {MAX_POINTS} are allowed in a point set"))
}

/// The `v x y z` lines of an OBJ file (faces and everything else ignored).
fn obj(path: &Path, text: &str) -> Result<PointSet> {
    let mut centres = Vec::new();
    for (ln, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("");
        let mut words = line.split_ascii_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let loc = |w: Option<&str>| {
            let col = w.map_or(line.trim_end().len(), |w| w.as_ptr() as usize - line.as_ptr() as usize);
            FileLoc::new(path, ln + 1, line[..col].chars().count() + 1)
        };
        if centres.len() == MAX_POINTS {
            return Err(too_many(loc(None), MAX_POINTS as u64 + 1));
        }
        let mut p = [0.0; 3];
        for c in &mut p {
            let w = words.next();
            *c = number(w).ok_or_else(|| {
                Error::at(
                    loc(w),
                    format!("expected `v x y z` with finite numbers, found `{}`", w.unwrap_or("")),
                )
            })?;
        }
        centres.push(DVec3::from_array(p));
    }
    Ok(PointSet::new(centres, None))
}

fn number(w: Option<&str>) -> Option<f64> {
    w?.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// A scalar PLY property type: its size in bytes.
fn scalar_size(t: &str) -> Option<usize> {
    Some(match t {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => return None,
    })
}

/// Reads a little-endian scalar of type `t` (checked by `scalar_size`) from `b`.
fn scalar(t: &str, b: &[u8]) -> f64 {
    match t {
        "char" | "int8" => b[0] as i8 as f64,
        "uchar" | "uint8" => b[0] as f64,
        "short" | "int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
        "ushort" | "uint16" => u16::from_le_bytes([b[0], b[1]]) as f64,
        "int" | "int32" => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        "uint" | "uint32" => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        "float" | "float32" => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        _ => f64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
    }
}

/// A property of a PLY element: its name and type, or for a list its count and item types.
struct Property {
    name: String,
    kind: String,
    list_count: Option<String>,
}

struct Element {
    name: String,
    count: u64,
    line: usize,
    properties: Vec<Property>,
}

fn ply(path: &Path, bytes: &[u8]) -> Result<PointSet> {
    let at = |line: usize, col: usize, msg: String| Error::at(FileLoc::new(path, line, col), msg);
    // The header is ASCII lines up to `end_header`.
    let end = bytes.windows(11).position(|w| w == b"end_header\n" || w == b"end_header\r");
    let Some(end) = end else {
        return Err(Error::file(path, "expected a PLY header ending with `end_header`"));
    };
    let body_start = end + 10 + if bytes.get(end + 10..end + 12) == Some(b"\r\n") { 2 } else { 1 };
    let header = std::str::from_utf8(&bytes[..end])
        .map_err(|_| Error::file(path, "expected an ASCII PLY header, found bytes that are not text"))?;
    let mut lines = header.lines().enumerate().map(|(i, l)| (i + 1, l));
    if lines.next().map(|(_, l)| l.trim()) != Some("ply") {
        return Err(at(1, 1, "expected `ply` on the first line".into()));
    }
    let mut binary = None;
    let mut elements: Vec<Element> = Vec::new();
    for (ln, line) in lines {
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let col = |i: usize| {
            words.get(i).map_or(line.len() + 1, |w| w.as_ptr() as usize - line.as_ptr() as usize + 1)
        };
        match words.as_slice() {
            ["format", "ascii", _] => binary = Some(false),
            ["format", "binary_little_endian", _] => binary = Some(true),
            ["format", other, ..] => {
                return Err(at(
                    ln,
                    col(1),
                    format!("expected format `ascii` or `binary_little_endian`, found `{other}`"),
                ))
            }
            ["comment" | "obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count
                    .parse::<u64>()
                    .map_err(|_| at(ln, col(2), format!("expected an element count, found `{count}`")))?;
                if *name == "vertex" && count > MAX_POINTS as u64 {
                    return Err(too_many(FileLoc::new(path, ln, col(2)), count));
                }
                elements.push(Element { name: name.to_string(), count, line: ln, properties: Vec::new() });
            }
            ["property", "list", count, item, name] => {
                let Some(e) = elements.last_mut() else {
                    return Err(at(ln, 1, "expected `element` before `property`".into()));
                };
                for (i, t) in [(2, count), (3, item)] {
                    if scalar_size(t).is_none() {
                        return Err(at(ln, col(i), format!("expected a PLY scalar type, found `{t}`")));
                    }
                }
                let p = Property {
                    name: name.to_string(),
                    kind: item.to_string(),
                    list_count: Some(count.to_string()),
                };
                e.properties.push(p);
            }
            ["property", kind, name] => {
                let Some(e) = elements.last_mut() else {
                    return Err(at(ln, 1, "expected `element` before `property`".into()));
                };
                if scalar_size(kind).is_none() {
                    return Err(at(ln, col(1), format!("expected a PLY scalar type, found `{kind}`")));
                }
                e.properties.push(Property {
                    name: name.to_string(),
                    kind: kind.to_string(),
                    list_count: None,
                });
            }
            _ => return Err(at(ln, 1, format!("expected a PLY header line, found `{}`", line.trim()))),
        }
    }
    let Some(binary) = binary else {
        return Err(Error::file(
            path,
            "expected a `format ascii 1.0` or `format binary_little_endian 1.0` line",
        ));
    };
    let Some(vi) = elements.iter().position(|e| e.name == "vertex") else {
        return Err(Error::file(path, "expected an `element vertex` in the PLY header"));
    };
    let v = &elements[vi];
    let index = |name: &str| v.properties.iter().position(|p| p.name == name && p.list_count.is_none());
    let (Some(x), Some(y), Some(z)) = (index("x"), index("y"), index("z")) else {
        return Err(at(v.line, 1, "expected `property float x`, `y` and `z` in element vertex".into()));
    };
    let wanted = [Some(x), Some(y), Some(z), index("radius")];
    // Lines before `end_header`, then it: the body's first line.
    let header_lines = header.lines().count() + 2;
    let values = if binary {
        binary_vertices(path, bytes, body_start, &elements[..=vi], &wanted)?
    } else {
        let body = std::str::from_utf8(&bytes[body_start..]).map_err(|_| {
            Error::file(path, "expected ASCII PLY data after `end_header`, found bytes that are not text")
        })?;
        ascii_vertices(path, body, header_lines, &elements[..=vi], &wanted)?
    };
    let centres = values.iter().map(|v| DVec3::new(v[0], v[1], v[2])).collect();
    let radii = wanted[3].map(|_| values.iter().map(|v| v[3]).collect());
    Ok(PointSet::new(centres, radii))
}

/// Checks a vertex's values: finite coordinates, a positive finite radius.
fn check_vertex(v: &[f64; 4], has_radius: bool) -> std::result::Result<(), String> {
    if let Some(c) = v[..3].iter().position(|c| !c.is_finite()) {
        return Err(format!("expected a finite {}, found {}", ["x", "y", "z"][c], v[c]));
    }
    if has_radius && !(v[3].is_finite() && v[3] > 0.0) {
        return Err(format!("expected a positive finite radius, found {}", v[3]));
    }
    Ok(())
}

/// Vertex values of an ASCII body: one line per element instance, elements in header order
/// (`elements` ends with the vertex element; earlier ones are skipped line by line).
fn ascii_vertices(
    path: &Path,
    body: &str,
    first_line: usize,
    elements: &[Element],
    wanted: &[Option<usize>; 4],
) -> Result<Vec<[f64; 4]>> {
    let skip: u64 = elements[..elements.len() - 1].iter().map(|e| e.count).sum();
    let v = elements.last().expect("the vertex element");
    let mut lines = body.lines().enumerate().map(|(i, l)| (first_line + i, l)).skip(skip as usize);
    let mut out = Vec::with_capacity(v.count as usize);
    for k in 0..v.count {
        let Some((ln, line)) = lines.next() else {
            return Err(Error::file(path, format!("expected {} vertices, found {k}", v.count)));
        };
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let col = |i: usize| {
            words.get(i).map_or(line.len() + 1, |w| w.as_ptr() as usize - line.as_ptr() as usize + 1)
        };
        let mut vals = [0.0, 0.0, 0.0, 1.0];
        for (slot, want) in wanted.iter().enumerate() {
            let Some(i) = *want else { continue };
            let Some(w) = words.get(i) else {
                return Err(Error::at(
                    FileLoc::new(path, ln, col(i)),
                    format!("expected {} values in vertex {k}, found {}", v.properties.len(), words.len()),
                ));
            };
            vals[slot] = w.parse::<f64>().map_err(|_| {
                Error::at(FileLoc::new(path, ln, col(i)), format!("expected a number, found `{w}`"))
            })?;
            if let Err(msg) = check_vertex(&vals, slot == 3) {
                return Err(Error::at(FileLoc::new(path, ln, col(i)), format!("vertex {k}: {msg}")));
            }
        }
        out.push(vals);
    }
    Ok(out)
}

/// Vertex values of a binary little-endian body (`elements` ends with the vertex element;
/// earlier ones are skipped, their lists read for their lengths).
fn binary_vertices(
    path: &Path,
    bytes: &[u8],
    start: usize,
    elements: &[Element],
    wanted: &[Option<usize>; 4],
) -> Result<Vec<[f64; 4]>> {
    let short = |at: usize, what: &str| {
        Error::file(path, format!("byte {at}: the file ends inside {what}: expected more binary PLY data"))
    };
    let mut at = start;
    for e in elements[..elements.len() - 1].iter().filter(|e| !e.properties.is_empty()) {
        for _ in 0..e.count {
            if at > bytes.len() {
                return Err(short(bytes.len(), &e.name));
            }
            for p in &e.properties {
                let size = scalar_size(&p.kind).expect("checked");
                let n = match &p.list_count {
                    Some(t) => {
                        let s = scalar_size(t).expect("checked");
                        let b = bytes.get(at..at + s).ok_or_else(|| short(at, &e.name))?;
                        at += s;
                        scalar(t, b) as usize
                    }
                    None => 1,
                };
                at += n * size;
            }
        }
    }
    let v = elements.last().expect("the vertex element");
    if v.properties.iter().any(|p| p.list_count.is_some()) {
        return Err(Error::file(path, "expected only scalar properties in element vertex"));
    }
    let offsets: Vec<usize> = v
        .properties
        .iter()
        .scan(0, |o, p| {
            let here = *o;
            *o += scalar_size(&p.kind).expect("checked");
            Some(here)
        })
        .collect();
    let stride: usize = v.properties.iter().map(|p| scalar_size(&p.kind).expect("checked")).sum();
    let need = at as u64 + v.count * stride as u64;
    if need > bytes.len() as u64 {
        let found = (bytes.len().saturating_sub(at)) / stride.max(1);
        return Err(Error::file(
            path,
            format!("byte {}: expected {} vertices of {stride} bytes, found {found}", bytes.len(), v.count),
        ));
    }
    let mut out = Vec::with_capacity(v.count as usize);
    for k in 0..v.count as usize {
        let base = at + k * stride;
        let mut vals = [0.0, 0.0, 0.0, 1.0];
        for (slot, want) in wanted.iter().enumerate() {
            let Some(i) = *want else { continue };
            let o = base + offsets[i];
            vals[slot] = scalar(&v.properties[i].kind, &bytes[o..]);
            if let Err(msg) = check_vertex(&vals, slot == 3) {
                return Err(Error::file(path, format!("byte {o}: vertex {k}: {msg}")));
            }
        }
        out.push(vals);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load_text(name: &str, text: &[u8]) -> Result<PointSet> {
        // A file of its own per call: the tests run in parallel and reuse names.
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("voltex-points-{}-{call}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let r = load(&path);
        std::fs::remove_dir_all(&dir).unwrap();
        r
    }

    /// ASCII and binary PLY and OBJ give the same points; a `radius` property is read; other
    /// elements and properties are skipped.
    #[test]
    fn reads_ply_and_obj() {
        let ascii = b"ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 2\nproperty float x\n\
            property float y\nproperty float z\nproperty uchar red\nproperty float radius\n\
            element face 0\nproperty list uchar int vertex_indices\nend_header\n1 2 3 255 0.5\n-1 0 0.25 0 2\n";
        let a = load_text("a.ply", ascii).unwrap();
        assert_eq!(a.centres, [DVec3::new(1.0, 2.0, 3.0), DVec3::new(-1.0, 0.0, 0.25)]);
        assert_eq!(a.radii, Some(vec![0.5, 2.0]));
        let mut bin = b"ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty list uchar int k\n\
            element vertex 2\nproperty double x\nproperty float y\nproperty float z\nend_header\n"
            .to_vec();
        bin.extend([2u8]);
        bin.extend([7i32, 8].iter().flat_map(|v| v.to_le_bytes()));
        for p in &a.centres {
            bin.extend(p.x.to_le_bytes());
            bin.extend((p.y as f32).to_le_bytes());
            bin.extend((p.z as f32).to_le_bytes());
        }
        let b = load_text("b.ply", &bin).unwrap();
        assert_eq!((b.centres.clone(), b.radii.clone()), (a.centres.clone(), None));
        let o = load_text("c.obj", b"# points\nv 1 2 3\nvn 0 0 1\nv -1 0 0.25\nf 1 2 1\n").unwrap();
        assert_eq!(o.centres, a.centres);
        assert_eq!(b.hash, o.hash);
    }

    /// Malformed input is reported at its line:col or byte.
    #[test]
    fn positions_bad_input() {
        let msg = |name: &str, text: &[u8]| load_text(name, text).unwrap_err().to_string();
        let head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        let m = msg("a.ply", format!("{head}0 0 0\n1 nan 2\n").as_bytes());
        assert!(m.ends_with("a.ply:9:3: vertex 1: expected a finite y, found NaN"), "{m}");
        let m = msg("a.ply", format!("{head}0 0 0\n1 x 2\n").as_bytes());
        assert!(m.ends_with("a.ply:9:3: expected a number, found `x`"), "{m}");
        let m = msg("a.ply", format!("{head}0 0 0\n").as_bytes());
        assert!(m.ends_with("a.ply: expected 2 vertices, found 1"), "{m}");
        let m =
            msg("a.ply", b"ply\nformat ascii 1.0\nelement vertex 99999999\nproperty float x\nend_header\n");
        assert!(
            m.ends_with("a.ply:3:16: 99999999 points: at most 1048576 are allowed in a point set"),
            "{m}"
        );
        let m = msg("a.ply", b"ply\nformat binary_big_endian 1.0\nend_header\n");
        assert!(m.contains("a.ply:2:8: expected format"), "{m}");
        let m = msg("a.ply", b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
        assert!(m.ends_with("a.ply: expected at least one point, found none"), "{m}");
        let mut bin = head.replace("ascii", "binary_little_endian").into_bytes();
        let start = bin.len();
        bin.extend([0.0f32, 0.0, 0.0, 1.0, f32::INFINITY].iter().flat_map(|v| v.to_le_bytes()));
        let m = msg("b.ply", &bin);
        assert!(
            m.ends_with(&format!("b.ply: byte {}: expected 2 vertices of 12 bytes, found 1", start + 20)),
            "{m}"
        );
        bin.extend(0f32.to_le_bytes());
        let m = msg("b.ply", &bin);
        assert!(
            m.ends_with(&format!("b.ply: byte {}: vertex 1: expected a finite y, found inf", start + 16)),
            "{m}"
        );
        let m = msg("c.obj", b"v 0 0 0\nv 1 inf 0\n");
        assert!(m.ends_with("c.obj:2:5: expected `v x y z` with finite numbers, found `inf`"), "{m}");
        let m = msg("c.obj", b"v 0 0\n");
        assert!(m.ends_with("c.obj:1:6: expected `v x y z` with finite numbers, found ``"), "{m}");
        let m = msg("c.obj", b"vn 0 0 1\n");
        assert!(m.ends_with("c.obj: expected at least one point, found none"), "{m}");
    }
}
