//! Wavefront OBJ reader for base surfaces: `v` (optionally `v x y z r g b`), `vt`, `vn` (ignored),
//! `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn`, negative (relative) indices; polygons are
//! fan-triangulated. Vertices are welded by their `v` index; uvs live per corner. Without `vt`
//! the uv is planar from the x, y bounds. Other statements (o, g, s, usemtl, mtllib, ...) are ignored.

use super::{area_weighted_normals, Mesh};
use crate::error::{Error, FileLoc, Result};
use glam::{DVec2, DVec3};
use std::path::Path;

/// Reads and parses an OBJ file; every problem is reported at its `file:line:col`.
pub fn load(path: &Path) -> Result<Mesh> {
    let text = crate::input::read_asset_text(path, "an OBJ file")?;
    parse(&text, path)
}

/// Whitespace-separated words of a line with their 1-based column. Columns are counted on from
/// the previous word, so a long line costs linear time.
fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    let (mut bytes, mut chars) = (0, 0);
    line.split_ascii_whitespace().map(move |w| {
        let byte = w.as_ptr() as usize - line.as_ptr() as usize;
        chars += line[bytes..byte].chars().count();
        bytes = byte;
        (chars + 1, w)
    })
}

/// Parses OBJ text; `path` is only used for error positions.
pub fn parse(text: &str, path: &Path) -> Result<Mesh> {
    let at = |line: usize, col: usize, msg: String| Error::at(FileLoc::new(path, line, col), msg);
    let mut positions: Vec<DVec3> = Vec::new();
    let mut colors: Vec<Option<[f64; 3]>> = Vec::new();
    let mut uvs: Vec<DVec2> = Vec::new();
    let mut normal_count = 0usize;
    // Faces as corners (v index, optional vt index) with the line of the face for late checks.
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut tri_vts: Vec<[Option<u32>; 3]> = Vec::new();
    let mut face_lines: Vec<u32> = Vec::new();

    for (ln, raw) in text.lines().enumerate() {
        let line_no = ln + 1;
        let line = raw.split('#').next().unwrap_or("");
        let mut it = words(line);
        let Some((_, key)) = it.next() else { continue };
        let args: Vec<(usize, &str)> = it.collect();
        let end_col = line.trim_end().chars().count() + 1;
        let number = |&(col, w): &(usize, &str)| -> Result<f64> {
            match w.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(at(line_no, col, format!("expected a finite number, found `{w}`"))),
            }
        };
        match key {
            "v" => {
                if args.len() < 3 {
                    return Err(at(line_no, end_col, "expected `v x y z` (3 numbers)".into()));
                }
                let v: Vec<f64> = args.iter().map(number).collect::<Result<_>>()?;
                positions.push(DVec3::new(v[0], v[1], v[2]));
                // `v x y z w` (4 numbers) is a homogeneous weight, not a colour.
                colors.push(if v.len() >= 6 { Some([v[3], v[4], v[5]]) } else { None });
            }
            "vt" => {
                if args.is_empty() {
                    return Err(at(line_no, end_col, "expected `vt u [v]`".into()));
                }
                let u = number(&args[0])?;
                let v = args.get(1).map(number).transpose()?.unwrap_or(0.0);
                uvs.push(DVec2::new(u, v));
            }
            "vn" => normal_count += 1,
            "f" => {
                if args.len() < 3 {
                    return Err(at(line_no, end_col, "expected a face with at least 3 corners".into()));
                }
                let mut corners = Vec::with_capacity(args.len());
                for &(col, w) in &args {
                    let mut parts = w.split('/');
                    let index = |part: Option<&str>, count: usize, what: &str, offset: usize| {
                        let col = col + offset;
                        match part {
                            None | Some("") => Ok(None),
                            Some(s) => {
                                let i: i64 = s.parse().map_err(|_| {
                                    at(line_no, col, format!("expected a {what} index, found `{s}`"))
                                })?;
                                // OBJ indices are 1-based; negative ones count back from the end.
                                let resolved = if i > 0 { i - 1 } else { count as i64 + i };
                                if i == 0 || resolved < 0 || resolved >= count as i64 {
                                    Err(at(
                                        line_no,
                                        col,
                                        format!(
                                            "{what} index {i} out of range: expected 1..={count} or -{count}..=-1"
                                        ),
                                    ))
                                } else {
                                    Ok(Some(resolved as u32))
                                }
                            }
                        }
                    };
                    let v_str = parts.next();
                    let vt_str = parts.next();
                    let vn_str = parts.next();
                    let v = index(v_str, positions.len(), "vertex", 0)?
                        .ok_or_else(|| at(line_no, col, "expected a vertex index".into()))?;
                    let vt_off = v_str.map_or(0, |s| s.len() + 1);
                    let vt = index(vt_str, uvs.len(), "texture coordinate", vt_off)?;
                    let vn_off = vt_off + vt_str.map_or(0, |s| s.len() + 1);
                    index(vn_str, normal_count, "normal", vn_off)?;
                    corners.push((v, vt));
                }
                for k in 1..corners.len() - 1 {
                    let c = [corners[0], corners[k], corners[k + 1]];
                    triangles.push(c.map(|c| c.0));
                    tri_vts.push(c.map(|c| c.1));
                    face_lines.push(line_no as u32);
                }
            }
            _ => {}
        }
    }
    if triangles.is_empty() {
        return Err(Error::file(path, "expected at least one face (`f` line)"));
    }

    // Planar uv from the x, y bounds for corners without `vt`.
    let (lo, hi) = positions
        .iter()
        .fold((DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(p.truncate()), hi.max(p.truncate()))
        });
    let extent = (hi - lo).max(DVec2::splat(1e-300));
    let corner_uvs = triangles
        .iter()
        .zip(&tri_vts)
        .map(|(t, vts)| {
            [0, 1, 2].map(|k| match vts[k] {
                Some(i) => uvs[i as usize],
                None => (positions[t[k] as usize].truncate() - lo) / extent,
            })
        })
        .collect();
    let (attribute, colors) = if colors.iter().any(Option::is_some) {
        let attribute = colors.iter().map(|c| c.map_or(0.0, |c| c[0])).collect();
        (Some(attribute), Some(colors.iter().map(|c| c.unwrap_or([1.0; 3])).collect()))
    } else {
        (None, None)
    };
    let mut m = Mesh {
        normals: area_weighted_normals(&positions, &triangles),
        positions,
        triangles,
        corner_uvs,
        vertex_uvs: vec![],
        attribute,
        colors,
        face_lines,
        uvs_missing: false,
    };
    m.vertex_uvs = m.vertex_uvs_from_corners();
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text, Path::new("m.obj")).unwrap_err().to_string()
    }

    #[test]
    fn parses_all_face_forms_and_fans() {
        let text = "# quad\nv 0 0 0 1 0 0\nv 1 0 0 0.5 0 0\nv 1 1 0 0 0 0\nv 0 1 0 0.25 0 0\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
                    f 1/1/1 2/2/1 3/3/1 4/4/1\nf -4 -2 -1\nf 1//1 2//1 3//1\nf 1/1 2/2 3/3\n";
        let m = parse(text, Path::new("m.obj")).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3], [0, 1, 2], [0, 1, 2]]);
        assert_eq!(m.corner_uvs[1], [DVec2::ZERO, DVec2::ONE, DVec2::Y]);
        // No vt: planar uv from the x, y bounds.
        assert_eq!(m.corner_uvs[3], [DVec2::ZERO, DVec2::X, DVec2::ONE]);
        assert_eq!(m.attribute, Some(vec![1.0, 0.5, 0.0, 0.25]));
        assert!(m.normals.iter().all(|n| (*n - DVec3::Z).length() < 1e-12));
    }

    #[test]
    fn errors_have_positions() {
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
        assert!(e.starts_with("m.obj:4:7: vertex index 4 out of range"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n");
        assert!(e.starts_with("m.obj:4:7: vertex index -4"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n");
        assert!(e.starts_with("m.obj:5:9: texture coordinate index 2 out of range"), "{e}");
        let e = err("v 0 0 0\nv 1 x 0\n");
        assert!(e.starts_with("m.obj:2:5: expected a finite number, found `x`"), "{e}");
        let e = err("v 0 0 nan\n");
        assert!(e.starts_with("m.obj:1:7: expected a finite number"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
        assert!(e.starts_with("m.obj:4:6: expected a face"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n");
        assert!(e.contains("m.obj:4:7"), "{e}");
        let e = err("v 0 0 0\n");
        assert!(e.contains("expected at least one face"), "{e}");
    }
}
