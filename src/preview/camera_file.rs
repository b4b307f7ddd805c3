//! Writing the preview's camera back into the scene file: the `camera: (...)` value is replaced
//! in the text (comments and layout elsewhere stay as they are), atomically.

use std::path::Path;

use crate::error::{Error, Result};
use crate::scene::Camera;

/// `camera: (...)` with `cam`'s values, as written into scene files.
pub fn format_camera(cam: &Camera) -> String {
    let v = |p: glam::DVec3| format!("({:.4}, {:.4}, {:.4})", p.x, p.y, p.z);
    format!("(eye: {}, target: {}, up: {}, fov_y: {:.3})", v(cam.eye), v(cam.target), v(cam.up), cam.fov_y)
}

/// The byte range of the value of the top-level `camera:` field (a parenthesised tuple), skipping
/// comments and strings.
pub fn camera_span(text: &str) -> Option<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut i = 0;
    let mut depth = 0i32;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
                continue;
            }
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => depth -= 1,
            b'c' if depth == 1
                && text[i..].starts_with("camera")
                && !is_ident(bytes.get(i.wrapping_sub(1))) =>
            {
                let rest = text[i + 6..].trim_start();
                if let Some(after) = rest.strip_prefix(':') {
                    let start = text.len() - after.trim_start().len();
                    if text[start..].starts_with('(') {
                        return matching(text, start).map(|end| (start, end + 1));
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    None
}

fn is_ident(b: Option<&u8>) -> bool {
    b.is_some_and(|b| b.is_ascii_alphanumeric() || *b == b'_')
}

/// Index of the `)` closing the `(` at `open`.
fn matching(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (k, c) in text[open..].char_indices() {
        match c {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + k);
                }
            }
            _ => {}
        }
    }
    None
}

pub fn write_camera(path: &Path, cam: &Camera) -> Result<()> {
    if crate::scene::import::is_asset(path) {
        return Err(Error::file(
            path,
            "an asset (a mesh or a .vdb) opened directly has no scene file: `voltex import` writes one",
        ));
    }
    let text = crate::input::read_text(path, "a scene file")?;
    let (start, end) = camera_span(&text)
        .ok_or_else(|| Error::file(path, "no `camera: (...)` field to write the camera into"))?;
    let new = format!("{}{}{}", &text[..start], format_camera(cam), &text[end..]);
    crate::io::atomic::write_bytes(path, new.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn replaces_only_the_camera_value() {
        let text = "// camera: (not this)\nScene(\n    output: (width: 8, height: 8),\n    camera: (eye: (0, -1, 0), target: (0, 0, 0)), // the view\n    nodes: [],\n)\n";
        let (s, e) = camera_span(text).unwrap();
        assert_eq!(&text[s..e], "(eye: (0, -1, 0), target: (0, 0, 0))");
        let cam = Camera { eye: DVec3::new(1.0, 2.0, 3.0), target: DVec3::ZERO, up: DVec3::Z, fov_y: 30.0 };
        let new = format!("{}{}{}", &text[..s], format_camera(&cam), &text[e..]);
        let scene = crate::scene::parse(&new, Path::new("c.ron")).unwrap();
        assert_eq!(*scene.camera, cam);
        assert!(new.contains("// the view") && new.starts_with("// camera: (not this)"));
    }
}
