//! The panel's list edits: duplicate an item of any list of the scene file (objects,
//! lights, noises, implicit shapes, metaballs, ...), as edits of the text. What the result means
//! is the scene parser's to judge: an edit it refuses (a list that may not be empty, say) is
//! refused as a typed value is. (Removing is `scene_text::remove_item`.)

use crate::error::{Error, Result};

use super::scene_text::{self as st, Step};

/// The edit inserting a copy of item `index` of the list at `list` after it. A named item (an
/// object) gets a name the list's other items do not have: `name_2`, `name_3`, ...
pub(crate) fn duplicate(src: &str, list: &[Step], index: usize) -> Result<st::Edit> {
    let root = st::tree(src)?;
    let items = root.at(list, src).map(|l| l.items()).unwrap_or_default();
    let item =
        items.get(index).ok_or_else(|| Error::Invalid(format!("no item {index} in `{}`", st::show(list))))?;
    let mut text = item.text(src).to_string();
    let name_of =
        |v: &st::Value| v.child(&Step::Field("name".into()), src).and_then(|n| st::unquote(n.text(src)));
    if let Some(name) = name_of(item) {
        let taken: Vec<String> = items.iter().filter_map(|i| name_of(i)).collect();
        let stem =
            name.rsplit_once('_').filter(|(_, n)| n.parse::<u32>().is_ok()).map_or(name.as_str(), |s| s.0);
        let new = (2..).map(|k| format!("{stem}_{k}")).find(|n| !taken.contains(n)).expect("a free name");
        let at = item.child(&Step::Field("name".into()), src).expect("named").span.clone();
        let (start, end) = (at.start - item.span.start, at.end - item.span.start);
        text.replace_range(start..end, &format!("\"{new}\""));
    }
    st::insert_item(src, list, index + 1, &text)
}

/// What an empty list named `field` gets from the panel's "add" (a list with items gets copies
/// of them instead): its first item as a new scene would have it.
pub(crate) fn first_item(field: &str) -> Option<&'static str> {
    match field {
        "lights" => Some("Directional(direction: (-0.5, 0.6, -0.7))"),
        "noises" => Some("(shape: Curve([(0.0, 0.0, 0.0), (0.5, 1.0, 0.0), (1.0, 0.0, 0.0)]), amplitude: 0.2, frequency: 3.0)"),
        _ => None,
    }
}

/// The edit adding [`first_item`] to the empty list at `list` (its last step names it).
pub(crate) fn add_first(src: &str, list: &[Step]) -> Result<st::Edit> {
    let item = match list.last() {
        Some(Step::Field(f)) => first_item(f),
        _ => None,
    };
    let item = item.ok_or_else(|| Error::Invalid(format!("`{}`: no item to add", st::show(list))))?;
    st::insert_item(src, list, 0, item)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"Scene(
    lights: [Directional(direction: (0.0, 0.0, -1.0)), Point(position: (1.0, 2.0, 3.0))],
    nodes: [
        (
            name: "ball", // the first
            texel: "t",
        ),
        (
            name: "ball_2",
            texel: "t",
        ),
    ],
)"#;

    fn path(s: &str) -> Vec<Step> {
        vec![Step::Field(s.into())]
    }

    #[test]
    fn a_copy_follows_its_item_and_a_named_one_gets_a_free_name() {
        let text = duplicate(SCENE, &path("nodes"), 0).unwrap().apply(SCENE).unwrap();
        // ball_2 is taken: the copy is ball_3, right after the first, comment and all.
        assert!(text.contains("name: \"ball\", // the first"), "{text}");
        let order: Vec<usize> =
            ["\"ball\"", "\"ball_3\"", "\"ball_2\""].iter().map(|n| text.find(n).unwrap()).collect();
        assert!(order.windows(2).all(|w| w[0] < w[1]), "{text}");
        let lights = duplicate(SCENE, &path("lights"), 1).unwrap().apply(SCENE).unwrap();
        assert_eq!(lights.matches("Point(position: (1.0, 2.0, 3.0))").count(), 2, "{lights}");
    }

    #[test]
    fn an_empty_list_of_lights_or_noises_gets_a_first_item_that_parses() {
        let src = "Scene(\n    lights: [],\n)";
        let text = add_first(src, &path("lights")).unwrap().apply(src).unwrap();
        assert!(text.contains("lights: [Directional(direction: (-0.5, 0.6, -0.7))],"), "{text}");
        // The noise as a hypertexture's: the scene parser takes it.
        let scene = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hypertextures/fig4_holes.ron"),
        )
        .unwrap();
        let root = st::parse(&scene).unwrap();
        let noises = root.at(&[Step::Field("hypertextures".into())], &scene).unwrap();
        let st::Kind::Map(entries) = &noises.kind else { panic!() };
        let key = st::unquote(entries[0].0.text(&scene)).unwrap();
        let list = vec![Step::Field("hypertextures".into()), Step::Key(key), Step::Field("noises".into())];
        let emptied = st::set(&scene, &list, "[]").unwrap().apply(&scene).unwrap();
        let text = add_first(&emptied, &list).unwrap().apply(&emptied).unwrap();
        let at = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hypertextures/x.ron");
        crate::scene::parse(&text, &at).unwrap();
        assert!(add_first(src, &path("nodes")).is_err());
    }

    #[test]
    fn an_item_is_removed_with_its_separator() {
        let text = st::remove_item(SCENE, &path("lights"), 0).unwrap().apply(SCENE).unwrap();
        assert!(text.contains("lights: [Point(position: (1.0, 2.0, 3.0))],"), "{text}");
        let edit = st::remove_item(SCENE, &path("nodes"), 1).unwrap();
        let text = edit.apply(SCENE).unwrap();
        assert!(!text.contains("ball_2") && text.contains("\"ball\""), "{text}");
        assert_eq!(edit.inverse().apply(&text).unwrap(), SCENE);
        assert!(st::remove_item(SCENE, &path("lights"), 5).is_err());
    }
}
