//! The preview panel's write-back (`voltex::preview::scene_text`) on every example scene: an
//! edited value changes its span only (every comment, the order and the layout stay byte for
//! byte), and the edited text parses as a scene holding the new value.

use std::path::{Path, PathBuf};

use voltex::preview::scene_text::{self as st, Step};
use voltex::scene::{self, Method, Node};

fn scenes() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in std::fs::read_dir(crate::common::root().join("scenes")).unwrap() {
        let dir = dir.unwrap().path();
        for f in std::fs::read_dir(&dir).into_iter().flatten() {
            let f = f.unwrap().path();
            if f.extension().is_some_and(|e| e == "ron") {
                out.push(f);
            }
        }
    }
    out.sort();
    assert!(out.len() > 40, "found only {} example scenes", out.len());
    out
}

/// Applies `edit` and checks that the text outside its span is the original's, byte for byte.
#[track_caller]
fn apply(path: &Path, src: &str, edit: &st::Edit) -> String {
    let out = edit.apply(src).unwrap();
    let root = st::parse(src).unwrap();
    let span = root.at(&edit.path, src).unwrap().span.clone();
    let tail = src.len() - span.end;
    assert_eq!(&out[..span.start], &src[..span.start], "{}: text before the edit changed", path.display());
    assert_eq!(&out[out.len() - tail..], &src[span.end..], "{}: text after the edit changed", path.display());
    assert_eq!(&out[span.start..out.len() - tail], edit.after);
    out
}

#[track_caller]
fn parsed(path: &Path, text: &str) -> scene::Scene {
    scene::parse(text, path)
        .unwrap_or_else(|e| panic!("{}: the edited scene does not parse: {e}", path.display()))
}

/// The node at a path of the text (`nodes[i].children[j]...`).
fn node<'a>(nodes: &'a [Node], path: &[Step]) -> &'a Node {
    match path {
        [Step::Field(_), Step::Index(i)] => &nodes[*i],
        [Step::Field(_), Step::Index(i), rest @ ..] => node(&nodes[*i].children, rest),
        _ => panic!("not a node path: {path:?}"),
    }
}

/// Paths of every node with a method, depth first.
fn node_paths(v: &st::Value, src: &str, at: Vec<Step>, out: &mut Vec<Vec<Step>>) {
    let key = if at.is_empty() { "nodes" } else { "children" };
    let Some(list) = v.child(&Step::Field(key.into()), src) else { return };
    for (i, n) in list.items().into_iter().enumerate() {
        let mut p = at.clone();
        p.extend([Step::Field(key.into()), Step::Index(i)]);
        if n.child(&Step::Field("method".into()), src).is_some() {
            out.push(p.clone());
        }
        node_paths(n, src, p, out);
    }
}

#[test]
fn write_back_keeps_every_comment_of_every_example_scene() {
    let mut edits = 0;
    for path in scenes() {
        let src = std::fs::read_to_string(&path).unwrap();
        let root = st::parse(&src).unwrap_or_else(|e| panic!("{}: {e}", path.display()));

        // The camera's field of view.
        let fov = vec![Step::Field("camera".into()), Step::Field("fov_y".into())];
        let edit = match root.at(&fov, &src) {
            Some(_) => st::set(&src, &fov, "33.5").unwrap(),
            None => st::add_field(&src, &fov[..1], "fov_y", "33.5").unwrap(),
        };
        assert_eq!(parsed(&path, &apply(&path, &src, &edit)).camera.fov_y, 33.5, "{}", path.display());
        edits += 1;

        // Each node's quality knob: planes doubled, a ray step set or halved, a slice depth.
        let mut nodes = Vec::new();
        node_paths(&root, &src, Vec::new(), &mut nodes);
        for at in nodes {
            let mut method = at.clone();
            method.push(Step::Field("method".into()));
            let m = root.at(&method, &src).unwrap();
            let (field, value) = match m.name(&src) {
                Some("ViewSlices") => ("planes", "300"),
                Some("RayMarch") | Some("Reference") => ("step", "0.0125"),
                Some("AxisSlices") => ("depth", "0.5"),
                Some("ShellMarch") => ("step", "0.5"),
                other => panic!("{}: method {other:?}", path.display()),
            };
            let mut knob = method.clone();
            knob.push(Step::Field(field.into()));
            let edit = match root.at(&knob, &src) {
                Some(_) => st::set(&src, &knob, value).unwrap(),
                None => st::add_field(&src, &method, field, value).unwrap(),
            };
            let out = apply(&path, &src, &edit);
            let scene = parsed(&path, &out);
            let got = node(&scene.nodes, &at).method.as_ref().map(|m| m.value.clone());
            let ok = match got {
                Some(Method::ViewSlices(v)) => v.planes == 300,
                Some(Method::RayMarch(r)) => r.step == Some(0.0125),
                Some(Method::Reference(r)) => r.step == Some(0.0125),
                Some(Method::AxisSlices(a)) => a.depth == 0.5,
                Some(Method::ShellMarch(s)) => s.step == 0.5,
                _ => false,
            };
            assert!(ok, "{}: {} = {value} not read back: {got:?}", path.display(), st::show(&knob));
            edits += 1;
        }

        // Curve control points: one added between the first two, one removed, and each undone.
        for (name, h) in st_hypertextures(&root, &src) {
            let noises = h.child(&Step::Field("noises".into()), &src).unwrap();
            for (i, noise) in noises.items().into_iter().enumerate() {
                let Some(shape) = noise.child(&Step::Field("shape".into()), &src) else { continue };
                if shape.name(&src) != Some("Curve") {
                    continue;
                }
                let list = vec![
                    Step::Field("hypertextures".into()),
                    Step::Key(name.clone()),
                    Step::Field("noises".into()),
                    Step::Index(i),
                    Step::Field("shape".into()),
                    Step::Index(0),
                ];
                let points = root.at(&list, &src).unwrap().items();
                let (x0, x1) =
                    (points[0].items()[0].number(&src).unwrap(), points[1].items()[0].number(&src).unwrap());
                let x = st::format_number(0.5 * (x0 + x1), "0.0");
                let add = st::insert_item(&src, &list, 1, &format!("({x}, 0.5, 0.0)")).unwrap();
                let out = apply(&path, &src, &add);
                let scene = parsed(&path, &out);
                let hs = &scene.hypertextures[&name];
                let voltex::scene::hypertexture::ShapeTransfer::Curve(c) = &hs.noises[i].shape else {
                    panic!()
                };
                assert_eq!(c.len(), points.len() + 1);
                assert_eq!(c[1].1, 0.5);
                assert_eq!(add.inverse().apply(&out).unwrap(), src, "{}: undo", path.display());
                if points.len() > 2 {
                    let del = st::remove_item(&src, &list, points.len() - 1).unwrap();
                    let out = apply(&path, &src, &del);
                    parsed(&path, &out);
                    assert_eq!(del.inverse().apply(&out).unwrap(), src);
                }
                edits += 1;
            }
        }
    }
    assert!(edits > 100, "only {edits} edits made");
}

fn st_hypertextures<'a>(root: &'a st::Value, src: &str) -> Vec<(String, &'a st::Value)> {
    match root.child(&Step::Field("hypertextures".into()), src).map(|m| &m.kind) {
        Some(st::Kind::Map(entries)) => {
            entries.iter().map(|(k, v)| (st::unquote(k.text(src)).unwrap(), v)).collect()
        }
        _ => Vec::new(),
    }
}
