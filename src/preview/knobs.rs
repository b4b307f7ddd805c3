//! The preview's method keys as edits of the scene file: `M` switches the selected object's method
//! (a hypertexture's shading), `+` and `-` step its quality knob. Each is one edit of the node's
//! text (undone at once), made from the method the renderer draws with; what each key does to a
//! method is its plug-in's answer (`methods::plugin`).

use super::scene_text::{self as st, format_number, Edit, Step};
use crate::error::{Error, Result};
use crate::scene::Method;

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

/// The node's `method` path, with the method written first as `written` when the file has none.
fn method_path(src: &str, node: &[Step], written: &str) -> Result<(String, Vec<Step>)> {
    let mut m = node.to_vec();
    m.push(Step::Field("method".into()));
    let has = st::parse(src).ok().is_some_and(|t| t.at(&m, src).is_some());
    let text = if has { src.to_string() } else { st::add_field(src, node, "method", written)?.apply(src)? };
    Ok((text, m))
}

/// The settings of the methods `M` switched away from, per node and method, so that cycling
/// back finds them again (`ViewSlices(planes: 800, lighting: PerPixel)` stays so).
pub(crate) type LeftMethods = std::collections::BTreeMap<(String, String), Method>;

/// `M`: the method's plug-in says what comes next: ViewSlices, AxisSlices, Reference in turn
/// (lighting kept where both have it, or the settings the node had in that method when `M` last
/// left it, from `left`); a hypertexture's RayMarch cycles its shading.
pub(crate) fn next_method(src: &str, node: &[Step], m: &Method, left: &mut LeftMethods) -> Result<Edit> {
    let written = format!("{}()", m.kind());
    compound(src, node, |text| match m.plugin().next_mode() {
        Some((path, value)) => {
            let (text, mp) = method_path(&text, node, &written)?;
            set_knob(&text, &mp, path, &value)
        }
        None => {
            let key = |m: &Method| (st::show(node), m.kind().to_string());
            left.insert(key(m), m.clone());
            let next = crate::methods::plugin::next_method(m);
            let next = left.get(&key(&next)).cloned().unwrap_or(next);
            let next = crate::methods::plugin::short_text(&next);
            let (text, mp) = method_path(&text, node, &next)?;
            st::set(&text, &mp, &next)?.apply(&text)
        }
    })
}

/// Writes the knob at `path` under the method at `mp` (the last field added when the file
/// leaves it out; the ones above it must be written).
fn set_knob(src: &str, mp: &[Step], path: &[&str], value: &str) -> Result<String> {
    let (last, above) = path.split_last().expect("a knob's path names a field");
    let mut at = mp.to_vec();
    at.extend(above.iter().map(|f| Step::Field((*f).into())));
    st::set_field(src, &at, last, value)?.apply(src)
}

/// `+` (finer) and `-`: the knobs the method's plug-in steps (ViewSlices' planes, a ray step
/// with an adaptive stride's `max_step`, AxisSlices' slice depth). `None` where the method has
/// no knob to step (Reference at its default step).
pub(crate) fn step_quality(src: &str, node: &[Step], m: &Method, finer: bool) -> Result<Option<Edit>> {
    let edits = m.plugin().quality_step(finer);
    if edits.is_empty() {
        return Ok(None);
    }
    compound(src, node, |text| {
        let (mut text, mp) = method_path(&text, node, &format!("{}()", m.kind()))?;
        for e in &edits {
            let value = format_number(e.value, if e.integer { "0" } else { "0.0" });
            text = set_knob(&text, &mp, e.path, &value)?;
        }
        Ok(text)
    })
    .map(Some)
}

/// The method `d` times coarser, for a frame drawn while a drag goes on (its plug-in's
/// `coarser`: fewer planes, longer steps, looser criteria).
pub(crate) fn coarser(m: &Method, d: f64) -> Method {
    m.plugin().coarser(d)
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
        let mut left = LeftMethods::new();
        let e = next_method(SRC, &node(0), &v, &mut left).unwrap();
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
        let e = next_method(SRC, &node(1), &h, &mut left).unwrap();
        assert!(e.apply(SRC).unwrap().contains("adaptive: (max_step: 0.04), shading: Phong)"));
        // A node without a method in the file gets one.
        let e = step_quality(SRC, &node(2), &v, false).unwrap().unwrap();
        assert!(e.apply(SRC).unwrap().contains("(name: \"d\", method: ViewSlices(planes: 12)),"));
    }

    /// `M` around the cycle comes back to the settings it left (issue 32: they were thrown away).
    #[test]
    fn m_around_the_cycle_keeps_each_methods_settings() {
        let src = "Scene(\n    nodes: [\n        (name: \"a\", method: ViewSlices(planes: 800, lighting: PerPixel)),\n    ],\n)\n";
        let parse = |text: &str| -> Method {
            let at = text.find("method: ").unwrap() + "method: ".len();
            let end = text[at..].find("),\n").unwrap() + at;
            ron::from_str(&format!("#![enable(implicit_some, unwrap_variant_newtypes)] {}", &text[at..end]))
                .unwrap()
        };
        let mut left = LeftMethods::new();
        let mut text = src.to_string();
        let mut seen = Vec::new();
        let cycle = crate::methods::plugin::MethodKind::all().filter(|k| k.switchable()).count();
        for _ in 0..cycle {
            let m = parse(&text);
            text = next_method(&text, &node(0), &m, &mut left).unwrap().apply(&text).unwrap();
            seen.push(crate::methods::plugin::short_text(&parse(&text)));
        }
        assert_eq!(text, src, "after {seen:?}");
        assert_ne!(seen[0], seen[1]);
    }
}
