//! The preview's method keys as edits of the scene file: `M` switches the selected object's method
//! (a hypertexture's shading), `+` and `-` step its quality knob. Each is one edit of the node's
//! text (undone at once), made from the method the renderer draws with.

use super::scene_text::{self as st, format_number, Edit, Step};
use crate::error::{Error, Result};
use crate::render::SWITCHED_PLANES;
use crate::scene::{Method, Shading, MAX_PLANES};

/// The edit of `path` made by `change`, a sequence of edits on the whole text inside `path`.
fn compound(src: &str, path: &[Step], change: impl FnOnce(String) -> Result<String>) -> Result<Edit> {
    let before = st::parse(src).ok().and_then(|t| t.at(path, src).map(|v| v.text(src).to_string()));
    let before =
        before.ok_or_else(|| Error::Invalid(format!("no `{}` in the scene text", st::show(path))))?;
    let out = change(src.to_string())?;
    let after = st::parse(&out).ok().and_then(|t| t.at(path, &out).map(|v| v.text(&out).to_string()));
    let after = after.ok_or_else(|| Error::Invalid(format!("no `{}` after the edit", st::show(path))))?;
    Ok(Edit { path: path.to_vec(), before, after })
}

/// Sets `field` of the struct at `path` to `text`, adding it when the file leaves it out.
fn set_field(src: &str, path: &[Step], field: &str, text: &str) -> Result<String> {
    let mut p = path.to_vec();
    p.push(Step::Field(field.into()));
    let has = st::parse(src).ok().is_some_and(|t| t.at(&p, src).is_some());
    let edit = if has { st::set(src, &p, text)? } else { st::add_field(src, path, field, text)? };
    edit.apply(src)
}

/// The node's `method` path, with the method written first as `written` when the file has none.
fn method_path(src: &str, node: &[Step], written: &str) -> Result<(String, Vec<Step>)> {
    let mut m = node.to_vec();
    m.push(Step::Field("method".into()));
    let has = st::parse(src).ok().is_some_and(|t| t.at(&m, src).is_some());
    let text = if has { src.to_string() } else { st::add_field(src, node, "method", written)?.apply(src)? };
    Ok((text, m))
}

fn variant(m: &Method) -> &'static str {
    match m {
        Method::ViewSlices(_) => "ViewSlices",
        Method::AxisSlices(_) => "AxisSlices",
        Method::Reference(_) => "Reference",
        Method::RayMarch(_) => "RayMarch",
        #[allow(unreachable_patterns)]
        _ => "",
    }
}

/// `M`: ViewSlices, AxisSlices, Reference in turn (lighting kept where both have it); a
/// hypertexture's RayMarch cycles its shading: None, Phong, PhongShadows, HenyeyGreenstein.
pub(crate) fn next_method(src: &str, node: &[Step], m: &Method) -> Result<Edit> {
    compound(src, node, |text| {
        let lighting = |l: crate::scene::Lighting| format!("{l:?}");
        let next = match m {
            Method::RayMarch(h) => {
                let shading = match h.shading {
                    Shading::None => "Phong",
                    Shading::Phong => "PhongShadows",
                    Shading::PhongShadows => "HenyeyGreenstein(g: 0.5, shadows: true)",
                    Shading::HenyeyGreenstein { .. } => "None",
                };
                let (text, mp) = method_path(&text, node, "RayMarch()")?;
                return set_field(&text, &mp, "shading", shading);
            }
            Method::ViewSlices(_) => "AxisSlices()".to_string(),
            Method::AxisSlices(_) => "Reference()".to_string(),
            Method::Reference(r) => {
                format!("ViewSlices(planes: {SWITCHED_PLANES}, lighting: {})", lighting(r.lighting))
            }
            #[allow(unreachable_patterns)]
            other => return Err(Error::Invalid(format!("no key switches {other:?}"))),
        };
        let (text, mp) = method_path(&text, node, &next)?;
        st::set(&text, &mp, &next)?.apply(&text)
    })
}

/// `+` (finer) and `-`: ViewSlices planes x2 or /2, a ray step /2 or x2 (an adaptive stride's
/// `max_step` with it), AxisSlices' slice depth /2 or x2. `None` where the method has no knob
/// to step (Reference at its default step).
pub(crate) fn step_quality(src: &str, node: &[Step], m: &Method, finer: bool) -> Result<Option<Edit>> {
    let scale = if finer { 0.5 } else { 2.0 };
    let (field, value) = match m {
        Method::ViewSlices(v) => {
            let planes = if finer { (v.planes * 2).min(MAX_PLANES) } else { (v.planes / 2).max(1) };
            ("planes", planes.to_string())
        }
        Method::Reference(r) => match r.step {
            Some(s) => ("step", format_number(s * scale, "0.0")),
            None => return Ok(None),
        },
        // Finer: see less deep inside contours (more slices).
        Method::AxisSlices(a) => ("depth", format_number((a.depth * scale).clamp(1.0 / 64.0, 1024.0), "0.0")),
        Method::RayMarch(h) => ("step", format_number(h.step() * scale, "0.0")),
        #[allow(unreachable_patterns)]
        _ => return Ok(None),
    };
    compound(src, node, |text| {
        let (text, mp) = method_path(&text, node, &format!("{}()", variant(m)))?;
        let text = set_field(&text, &mp, field, &value)?;
        // The adaptive stride's longest step scales with the step, so the stride stays on.
        match m {
            Method::RayMarch(h) => match h.adaptive {
                Some(a) => {
                    let mut ap = mp.clone();
                    ap.push(Step::Field("adaptive".into()));
                    set_field(&text, &ap, "max_step", &format_number(a.max_step * scale, "0.0"))
                }
                None => Ok(text),
            },
            _ => Ok(text),
        }
    })
    .map(Some)
}

/// The method `d` times coarser, for a frame drawn while a drag goes on: a `d`-th of the planes,
/// a ray step (and shadow step, adaptive stride) `d` times longer, AxisSlices criteria `d` times
/// looser. Reference at its default step stays as it is.
pub(crate) fn coarser(m: &Method, d: f64) -> Method {
    let mut m = m.clone();
    match &mut m {
        Method::ViewSlices(v) => v.planes = ((v.planes as f64 / d).round() as u32).max(1),
        Method::RayMarch(h) => {
            h.step = Some(h.step() * d);
            h.shadow_step = h.shadow_step.map(|s| s * d);
            if let Some(a) = &mut h.adaptive {
                a.max_step *= d;
            }
        }
        Method::AxisSlices(a) => {
            a.depth = (a.depth * d).min(1024.0);
            a.pixels *= d;
        }
        Method::Reference(r) => r.step = r.step.map(|s| s * d),
        #[allow(unreachable_patterns)]
        _ => {}
    }
    m
}

/// Names and paths of the nodes of the text (`nodes[i]`, `nodes[i].children[j]`, ...).
pub(crate) fn node_paths(v: &st::Value, src: &str, at: Vec<Step>, out: &mut Vec<(String, Vec<Step>)>) {
    let key = if at.is_empty() { "nodes" } else { "children" };
    let Some(list) = v.child(&Step::Field(key.into()), src) else { return };
    for (i, n) in list.items().into_iter().enumerate() {
        let mut p = at.clone();
        p.extend([Step::Field(key.into()), Step::Index(i)]);
        if let Some(name) = n.child(&Step::Field("name".into()), src).and_then(|v| st::unquote(v.text(src))) {
            out.push((name, p.clone()));
        }
        node_paths(n, src, p, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Adaptive, RayMarch, ViewSlices};

    const SRC: &str = "Scene(\n    nodes: [\n        (name: \"a\", method: ViewSlices(planes: 24)), // a\n        (name: \"h\", hypertexture: \"h\", method: RayMarch(step: 0.01, adaptive: (max_step: 0.04))),\n        (name: \"d\"),\n    ],\n)\n";

    fn node(i: usize) -> Vec<Step> {
        vec![Step::Field("nodes".into()), Step::Index(i)]
    }

    #[test]
    fn keys_edit_the_method_in_place() {
        let v = Method::ViewSlices(ViewSlices {
            planes: 24,
            trivial_reject: true,
            lighting: Default::default(),
            compositor: Default::default(),
            lod: Default::default(),
        });
        let e = step_quality(SRC, &node(0), &v, true).unwrap().unwrap();
        assert_eq!(e.apply(SRC).unwrap(), SRC.replace("planes: 24", "planes: 48"));
        let e = next_method(SRC, &node(0), &v).unwrap();
        assert_eq!(e.apply(SRC).unwrap(), SRC.replace("ViewSlices(planes: 24)", "AxisSlices()"));
        let h = Method::RayMarch(RayMarch {
            step: Some(0.01),
            adaptive: Some(Adaptive { max_step: 0.04 }),
            ..Default::default()
        });
        let e = step_quality(SRC, &node(1), &h, false).unwrap().unwrap();
        assert_eq!(
            e.apply(SRC).unwrap(),
            SRC.replace("step: 0.01, adaptive: (max_step: 0.04)", "step: 0.02, adaptive: (max_step: 0.08)")
        );
        let e = next_method(SRC, &node(1), &h).unwrap();
        assert!(e.apply(SRC).unwrap().contains("adaptive: (max_step: 0.04), shading: Phong)"));
        // A node without a method in the file gets one.
        let e = step_quality(SRC, &node(2), &v, false).unwrap().unwrap();
        assert!(e.apply(SRC).unwrap().contains("(name: \"d\", method: ViewSlices(planes: 12)),"));
    }
}
