//! The panel's looks: a preset of `voltex import --preset` (moss, fur, ...) put on the selected
//! object, and a node's texel picked from the scene's, as edits of the scene text (one undo step
//! each, the rest of the file byte for byte).

use crate::error::{Error, Result};
use crate::scene::import;

use super::scene_text::{self as st, Step};

/// The presets' names, for the panel's menu.
pub(crate) fn presets() -> Vec<&'static str> {
    import::presets()
}

/// The edit that puts preset `name` on the node at `node`: the preset's texels join the scene's
/// (those whose names it already has stay as they are: the user's edits of them are kept), and
/// the node takes the preset's texel, method and base colour. Its height and uv tiles stay: they
/// fit its mesh (the preset's are for a unit sphere).
pub(crate) fn put_preset(src: &str, node: &[Step], name: &str) -> Result<st::Edit> {
    let look = import::look(name)?;
    let root = st::tree(src)?;
    let texels_path = [Step::Field("texels".into())];
    let texels =
        root.at(&texels_path, src).ok_or_else(|| Error::Invalid("the scene has no `texels`".into()))?;
    let st::Kind::Map(entries) = &texels.kind else {
        return Err(Error::Invalid("the scene's `texels` is not a map".into()));
    };
    let have: Vec<String> = entries.iter().filter_map(|(k, _)| st::unquote(k.text(src))).collect();
    // The preset's entries as its file writes them (comments kept), those the scene lacks.
    let preset = st::tree(&format!("{{\n{}\n}}", look.texels))?;
    let st::Kind::Map(theirs) = &preset.kind else { unreachable!("parsed as a map") };
    let block = format!("{{\n{}\n}}", look.texels);
    let mut add = String::new();
    for (k, v) in theirs {
        if st::unquote(k.text(&block)).is_some_and(|key| !have.contains(&key)) {
            // From the line of the key to the end of the value, with its comma.
            let start = block[..k.span.start].rfind('\n').map_or(0, |i| i + 1);
            let end = v.span.end + block[v.span.end..].find(',').map_or(0, |i| i + 1);
            add.push_str(&block[start..end]);
            add.push('\n');
        }
    }
    let mut text = src.to_string();
    if !add.is_empty() {
        let span = texels.span.clone();
        let inner = src[span.start + 1..span.end - 1].trim_end();
        let comma = if inner.trim().is_empty() || inner.ends_with(',') { "" } else { "," };
        let map = format!("{{{inner}{comma}\n{add}    }}");
        text = st::set(&text, &texels_path, &map)?.apply(&text)?;
    }
    for (field, value) in
        [("texel", format!("\"{}\"", look.texel)), ("method", look.method), ("base_color", look.base_color)]
    {
        text = st::set_field(&text, node, field, &value)?.apply(&text)?;
    }
    whole(src, &text)
}

/// The edit setting the node's texel to `name` (one of the scene's texels).
pub(crate) fn pick_texel(src: &str, node: &[Step], name: &str) -> Result<st::Edit> {
    st::set_field(src, node, "texel", &format!("\"{name}\""))
}

/// One edit of the root value from `src` to `text` (several changes, one undo step).
fn whole(src: &str, text: &str) -> Result<st::Edit> {
    st::set(src, &[], st::tree(text)?.text(text))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene as `voltex import` writes it around a mesh (the default look, grain).
    fn imported() -> String {
        let mesh =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/view_slices/meshes/dome.glb");
        import::scene_text(&mesh, "dome.glb", None).unwrap()
    }

    /// Parsed as a scene beside the mesh.
    fn parse(text: &str) -> Result<crate::scene::Scene> {
        let at = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/view_slices/meshes/dome.ron");
        crate::scene::parse(text, &at)
    }

    fn node() -> Vec<Step> {
        vec![Step::Field("nodes".into()), Step::Index(0)]
    }

    #[test]
    fn a_preset_joins_the_scene_and_the_node_takes_it_in_one_edit() {
        let src = imported();
        let edit = put_preset(&src, &node(), "moss").unwrap();
        let text = edit.apply(&src).unwrap();
        let scene = parse(&text).unwrap();
        assert!(scene.texels.contains_key("grain") && scene.texels.contains_key("moss"), "{text}");
        assert_eq!(scene.nodes[0].texel.as_ref().map(|t| t.to_string()).as_deref(), Some("moss"));
        // The rest of the file is as it was: its comments, the node's height and mesh.
        for line in src.lines().filter(|l| l.trim_start().starts_with("//") || l.contains("height:")) {
            assert!(text.contains(line), "{line:?} lost:\n{text}");
        }
        // Undone in one step; put again, the moss (maybe edited since) is not added twice.
        assert_eq!(edit.inverse().apply(&text).unwrap(), src);
        let again = put_preset(&text, &node(), "moss").unwrap().apply(&text).unwrap();
        assert_eq!(again.matches("\"moss\": (").count(), 1, "{again}");
        parse(&again).unwrap();
    }

    #[test]
    fn every_preset_can_be_put_on_an_imported_mesh() {
        let src = imported();
        for name in presets() {
            let text = put_preset(&src, &node(), name).unwrap().apply(&src).unwrap();
            let scene = parse(&text).unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
            assert!(
                scene.nodes[0].texel.as_ref().is_some_and(|t| scene.texels.contains_key(t.as_str())),
                "{name}"
            );
        }
        assert!(put_preset(&src, &node(), "no-such-look").is_err());
    }

    #[test]
    fn a_texel_is_picked_from_the_scenes() {
        let src = put_preset(&imported(), &node(), "moss").unwrap().apply(&imported()).unwrap();
        let text = pick_texel(&src, &node(), "grain").unwrap().apply(&src).unwrap();
        let scene = parse(&text).unwrap();
        assert_eq!(scene.nodes[0].texel.as_ref().map(|t| t.to_string()).as_deref(), Some("grain"));
    }
}
