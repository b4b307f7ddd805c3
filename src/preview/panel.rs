//! The preview's panel (egui): what the overlay said (scene, view, GPU time, adapter, status,
//! errors), the object list, and the selected object's method, knobs, hypertexture (noises,
//! vector field, transfer functions as curves) and texel, drawn from the scene file's text.
//!
//! Widgets come from the text itself (`scene_text`): a number is a drag value, a unit variant a
//! choice among its siblings, a tuple of numbers a row, `Curve`, `Ramp`, `Grid` and `Image`
//! shape and colour functions their editors. A field the file leaves out shows its default from
//! [`KNOBS`] and is added when edited, so a new scene field shows as soon as a file has it, and a
//! default is one line here. The panel returns [`Action`]s; the window makes them.

use egui::{Color32, RichText};

use super::present::Mode;
use super::scene_text::{self as st, format_number, Kind, Step, Value};
use crate::methods::plugin::panel_knobs;
use crate::scene::Scene;

/// Width of the panel in points.
pub(crate) const WIDTH: f32 = 340.0;

/// What the user asked for in the panel.
#[derive(Debug, Clone)]
pub(crate) enum Action {
    /// An edit of the scene text (`live`: a step of a drag).
    Edit {
        edit: st::Edit,
        live: bool,
    },
    /// A drag ended.
    EndGesture,
    Select(usize),
    Mode(Mode),
    Undo,
    Redo,
    /// A message for the status line.
    Note(String),
}

/// An object of the list: its name, the path of its node in the text, its method's name.
#[derive(Debug, Clone)]
pub(crate) struct Object {
    pub(crate) name: String,
    pub(crate) node: Vec<Step>,
}

/// What the panel shows.
pub(crate) struct PanelView<'a> {
    pub(crate) src: &'a str,
    pub(crate) tree: Option<&'a Value>,
    pub(crate) scene: Option<&'a Scene>,
    pub(crate) objects: &'a [Object],
    pub(crate) selected: usize,
    pub(crate) mode: Mode,
    /// Scene, GPU time, adapter, status.
    pub(crate) lines: &'a [String],
    pub(crate) error: Option<&'a str>,
    /// The difference view shows FLIP's heat map: draw its colour scale.
    pub(crate) heat_scale: bool,
    pub(crate) note: Option<&'a str>,
    pub(crate) refused: Option<&'a (Vec<Step>, String)>,
    pub(crate) read_only: bool,
    pub(crate) can_undo: bool,
    pub(crate) can_redo: bool,
}

/// Drawing context: the text, the refused field, and the actions and editor rectangles made.
pub(crate) struct Cx<'a> {
    pub(crate) src: &'a str,
    pub(crate) scene: Option<&'a Scene>,
    refused: Option<&'a (Vec<Step>, String)>,
    pub(crate) actions: Vec<Action>,
    /// Screen rectangles of the curve editors and number fields by path (window tests drive them).
    pub(crate) rects: Vec<(String, egui::Rect)>,
    /// The type of the struct whose fields are being shown (for the fields' tooltips).
    owner: Option<String>,
}

/// Defaults of fields a file may leave out, by the struct's variant name (unnamed structs: the
/// name [`type_key`] gives them). Shown greyed; editing one writes it into the file. Methods'
/// knobs come from their plug-ins ([`defaults_of`]).
const KNOBS: &[(&str, &[(&str, &str)])] = &[
    ("DepthPeeling", &[("passes", "4"), ("splat_grid", "32")]),
    ("Splatting", &[("slabs", "16"), ("splat_grid", "32")]),
    ("Noise", &[("shift", "0.0"), ("operator", "Sum"), ("seed", "0"), ("speed", "0.0")]),
    ("Hypertexture", &[("field", "ClosestSurface"), ("opacity_length", "0.05")]),
    ("Swirl", &[("axis", "(0.0, 0.0, 1.0)"), ("center", "(0.0, 0.0, 0.0)"), ("twist", "1.0")]),
    ("Perturbed", &[("amount", "0.5"), ("magnitude", "0.0"), ("seed", "0")]),
    ("Directional", &[("color", "(1.0, 1.0, 1.0)"), ("intensity", "1.0")]),
    ("Camera", &[("up", "(0.0, 0.0, 1.0)"), ("fov_y", "45.0")]),
];

/// Variants that replace one another, as written when chosen (all fields given or defaulted).
const CHOICES: &[&[&str]] = &[
    &["None", "Phong", "PhongShadows", "HenyeyGreenstein(g: 0.5, shadows: true)"],
    &["Rays", "LightVolume(resolution: 64)"],
    &["IE", "HQ"],
    &["Baked", "PerPixel"],
    &["Sum", "Blend", "Mix"],
    &["Three", "Horizontal"],
    &["Binary", "Blended"],
    &["Texels", "Slices"],
    &["Bounds", "DepthPeeling()", "Splatting()"],
    &[
        "ClosestSurface",
        "FromCentre(center: (0.0, 0.0, 0.0))",
        "Constant(direction: (0.0, 0.0, 1.0))",
        "Swirl()",
        "Perturbed(field: ClosestSurface, frequency: 4.0)",
    ],
];

/// The defaults shown for the struct `key`: a method's from its plug-in, else [`KNOBS`]'.
pub(crate) fn defaults_of(key: &str) -> Option<Vec<(&'static str, &'static str)>> {
    if let Some(m) = panel_knobs().iter().find(|m| m.name == key) {
        return Some(m.defaults.clone());
    }
    KNOBS.iter().find(|(n, _)| *n == key).map(|(_, d)| d.to_vec())
}

/// The methods an object may be switched between, as written when chosen.
fn method_choices() -> &'static [&'static str] {
    static CHOSEN: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    CHOSEN.get_or_init(|| panel_knobs().iter().filter_map(|m| m.chosen).collect())
}

fn variant(choice: &str) -> &str {
    choice.split('(').next().unwrap_or(choice)
}

/// The struct's name for [`KNOBS`]: its variant name, else from where it sits.
fn type_key<'a>(v: &'a Value, path: &[Step], src: &'a str) -> Option<&'a str> {
    if let Some(n) = v.name(src) {
        return Some(n);
    }
    match path {
        [.., Step::Field(f), Step::Index(_)] if f == "noises" => Some("Noise"),
        [Step::Field(f), Step::Key(_)] if f == "hypertextures" => Some("Hypertexture"),
        [Step::Field(f)] if f == "camera" => Some("Camera"),
        _ => None,
    }
}

/// Draws the panel; returns what the user did.
pub(crate) fn show(root: &mut egui::Ui, view: &PanelView) -> (Vec<Action>, Vec<(String, egui::Rect)>) {
    let mut cx = Cx {
        src: view.src,
        scene: view.scene,
        refused: view.refused,
        actions: Vec::new(),
        rects: Vec::new(),
        owner: None,
    };
    egui::Panel::right("voltex-panel").exact_size(WIDTH).resizable(false).show(root, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| contents(ui, &mut cx, view));
    });
    (cx.actions, cx.rects)
}

fn contents(ui: &mut egui::Ui, cx: &mut Cx, view: &PanelView) {
    for (i, line) in view.lines.iter().enumerate() {
        if i == 0 {
            ui.label(RichText::new(line).strong());
        } else {
            ui.label(line);
        }
    }
    ui.horizontal(|ui| {
        for (mode, label) in
            [(Mode::Image, "1 image"), (Mode::Truth, "2 reference"), (Mode::Difference, "3 difference")]
        {
            if ui.selectable_label(view.mode == mode, label).clicked() {
                cx.actions.push(Action::Mode(mode));
            }
        }
    });
    if view.heat_scale {
        heat_scale(ui);
    }
    ui.horizontal(|ui| {
        if ui.add_enabled(view.can_undo, egui::Button::new("undo")).clicked() {
            cx.actions.push(Action::Undo);
        }
        if ui.add_enabled(view.can_redo, egui::Button::new("redo")).clicked() {
            cx.actions.push(Action::Redo);
        }
        if view.read_only {
            ui.colored_label(Color32::from_rgb(240, 180, 60), "read-only: edits unsaved");
        }
    });
    for msg in [view.note, view.error].into_iter().flatten() {
        ui.colored_label(Color32::from_rgb(255, 110, 90), msg);
    }
    ui.separator();
    let Some(tree) = view.tree else {
        ui.label("the scene text does not parse: edit it in a text editor");
        return;
    };
    ui.label(RichText::new("objects").strong());
    for (i, o) in view.objects.iter().enumerate() {
        if ui.selectable_label(i == view.selected, &o.name).clicked() {
            cx.actions.push(Action::Select(i));
        }
    }
    if let Some(o) = view.objects.get(view.selected) {
        if let Some((Step::Index(i), list)) = o.node.split_last() {
            item_buttons(ui, cx, list, *i, " object");
        }
        if let Some(node) = tree.at(&o.node, cx.src) {
            object(ui, cx, tree, node, &o.node);
        }
    }
    ui.separator();
    egui::CollapsingHeader::new("scene: camera, lights, background").id_salt("scene").show(ui, |ui| {
        for f in ["camera", "lights", "background", "ambient", "time"] {
            let path = vec![Step::Field(f.into())];
            if let Some(v) = tree.at(&path, cx.src) {
                field(ui, cx, f, v, &path);
            }
        }
    });
    ui.separator();
    ui.small(
        "drag: orbit | right/shift drag: pan | wheel: zoom | R: reset camera | C: save camera | \
         Tab: next object | M: method | +/-: quality | 1 2 3: view | S: screenshot | \
         Ctrl+Z / Ctrl+Shift+Z: undo / redo | H: hide panel",
    );
}

/// The selected object: its method, then its hypertexture or texel, then the rest of its node.
fn object(ui: &mut egui::Ui, cx: &mut Cx, tree: &Value, node: &Value, path: &[Step]) {
    let src = cx.src;
    ui.separator();
    let method_path = [path, &[Step::Field("method".into())]].concat();
    match node.child(&Step::Field("method".into()), src) {
        Some(m) => field(ui, cx, "method", m, &method_path),
        None => {
            ui.label("method: the default");
        }
    }
    if node.child(&Step::Field("hypertexture".into()), src).is_none() {
        looks(ui, cx, tree, node, path);
    }
    for (key, map) in [("hypertexture", "hypertextures"), ("texel", "texels")] {
        let Some(name) = node.child(&Step::Field(key.into()), src).and_then(|n| st::unquote(n.text(src)))
        else {
            continue;
        };
        let entry = vec![Step::Field(map.into()), Step::Key(name.clone())];
        if let Some(v) = tree.at(&entry, src) {
            egui::CollapsingHeader::new(RichText::new(format!("{key} \"{name}\"")).strong())
                .id_salt(st::show(&entry))
                .default_open(true)
                .show(ui, |ui| structure(ui, cx, v, &entry));
        }
    }
    egui::CollapsingHeader::new("node").id_salt(st::show(path)).show(ui, |ui| {
        if let Kind::Paren { fields, .. } = &node.kind {
            for f in fields {
                let Some(name) = &f.name else { continue };
                if matches!(name.as_str(), "method" | "children" | "name" | "texel" | "hypertexture") {
                    continue;
                }
                let p = [path, &[Step::Field(name.clone())]].concat();
                field(ui, cx, name, &f.value, &p);
            }
        }
    });
}

fn refused_here(cx: &Cx, path: &[Step]) -> Option<String> {
    cx.refused.filter(|(p, _)| p == path).map(|(_, m)| m.clone())
}

fn push_edit(cx: &mut Cx, edit: crate::Result<st::Edit>, live: bool) {
    match edit {
        Ok(edit) => cx.actions.push(Action::Edit { edit, live }),
        Err(e) => cx.actions.push(Action::Note(e.to_string())),
    }
}

/// One named field: a row for atoms and small tuples, a section for the rest.
fn field(ui: &mut egui::Ui, cx: &mut Cx, name: &str, v: &Value, path: &[Step]) {
    let src = cx.src;
    let small_tuple = matches!(&v.kind, Kind::Paren { name: None, .. })
        && !v.items().is_empty()
        && v.items().len() <= 4
        && v.items().iter().all(|i| i.number(src).is_some());
    // What the scene-file reference says of the field, on hover.
    let tip = super::tooltips::tooltip(name, cx.owner.as_deref());
    let with_tip = |r: egui::Response| match &tip {
        Some(t) => r.on_hover_text(t),
        None => r,
    };
    if small_tuple || matches!(v.kind, Kind::Atom) {
        ui.horizontal(|ui| {
            with_tip(ui.label(name));
            value(ui, cx, name, v, path);
        });
        if let Some(msg) = refused_here(cx, path) {
            ui.colored_label(Color32::from_rgb(255, 110, 90), msg);
        }
    } else {
        let shown =
            egui::CollapsingHeader::new(name).id_salt(st::show(path)).default_open(true).show(ui, |ui| {
                value(ui, cx, name, v, path);
                if let Some(msg) = refused_here(cx, path) {
                    ui.colored_label(Color32::from_rgb(255, 110, 90), msg);
                }
            });
        with_tip(shown.header_response);
    }
}

/// A value's widgets.
fn value(ui: &mut egui::Ui, cx: &mut Cx, name: &str, v: &Value, path: &[Step]) {
    let src = cx.src;
    let refused = refused_here(cx, path).is_some();
    match &v.kind {
        Kind::Atom if group(v.text(src)).is_some() => choice(ui, cx, v, path),
        Kind::Atom => {
            let (new, stopped) = atom(ui, &mut cx.rects, v.text(src), refused, path);
            if let Some((text, live)) = new {
                push_edit(cx, st::set(src, path, &text), live);
            }
            if stopped {
                cx.actions.push(Action::EndGesture);
            }
        }
        Kind::Paren { name: None, .. }
            if v.items().iter().all(|i| i.number(src).is_some()) && !v.items().is_empty() =>
        {
            numbers_row(ui, cx, name, v, path);
        }
        Kind::Paren { name: Some(n), .. } if n == "Curve" => {
            super::curves::shape_curve(ui, cx, v, path);
        }
        Kind::Paren { name: Some(n), .. } if n == "Ramp" => {
            super::curves::color_ramp(ui, cx, v, path);
        }
        Kind::Paren { name: Some(n), .. } if n == "Grid" || n == "Image" => {
            choice(ui, cx, v, path);
            let rows = grid_rows(cx, v, path);
            // A `Grid` is painted in the panel; an `Image` is its file's.
            super::curves::grid_image(ui, cx, &rows, path, n == "Grid");
        }
        Kind::Paren { .. } => structure(ui, cx, v, path),
        Kind::List(items) => {
            let list_name = match path.last() {
                Some(Step::Field(f)) => f.as_str(),
                _ => "",
            };
            if items.is_empty() && super::items::first_item(list_name).is_some() {
                let add = ui.small_button("add");
                cx.rects.push((format!("{} add", st::show(path)), add.rect));
                if add.clicked() {
                    push_edit(cx, super::items::add_first(src, path), false);
                }
            }
            for (i, item) in items.iter().enumerate() {
                let p = [path, &[Step::Index(i)]].concat();
                let label = match (path.last(), item.name(src)) {
                    (Some(Step::Field(f)), _) if f == "noises" => format!("noise {i}"),
                    (_, Some(n)) => format!("{i}: {n}"),
                    _ => format!("{i}"),
                };
                if matches!(item.kind, Kind::Atom) {
                    field(ui, cx, &label, item, &p);
                } else {
                    egui::CollapsingHeader::new(label).id_salt(st::show(&p)).default_open(true).show(
                        ui,
                        |ui| {
                            item_buttons(ui, cx, path, i, "");
                            value(ui, cx, name, item, &p)
                        },
                    );
                }
            }
        }
        Kind::Map(entries) => {
            for (k, item) in entries {
                let key = st::unquote(k.text(src)).unwrap_or_else(|| k.text(src).to_string());
                let p = [path, &[Step::Key(key.clone())]].concat();
                field(ui, cx, &key, item, &p);
            }
        }
    }
}

/// The rows of a `Grid` (from the text) or an `Image` (as the scene loaded it).
fn grid_rows(cx: &Cx, v: &Value, path: &[Step]) -> Vec<Vec<f64>> {
    let src = cx.src;
    if v.name(src) == Some("Grid") {
        return v
            .items()
            .first()
            .map(|rows| {
                rows.items()
                    .iter()
                    .map(|r| r.items().iter().map(|x| x.number(src).unwrap_or(0.0)).collect())
                    .collect()
            })
            .unwrap_or_default();
    }
    // hypertextures["h"].noises[i].shape
    if let ([Step::Field(_), Step::Key(h), Step::Field(_), Step::Index(i), ..], Some(scene)) =
        (path, cx.scene)
    {
        if let Some(rows) =
            scene.hypertextures.get(h).and_then(|h| h.noises.get(*i)).and_then(|n| n.shape.rows())
        {
            return rows.to_vec();
        }
    }
    Vec::new()
}

/// A struct or tuple: a choice of variant where it has siblings, then its fields (those left
/// out with their defaults), and a noise's on/off switch.
fn structure(ui: &mut egui::Ui, cx: &mut Cx, v: &Value, path: &[Step]) {
    let src = cx.src;
    choice(ui, cx, v, path);
    let Kind::Paren { fields, .. } = &v.kind else { return };
    let key = type_key(v, path, src);
    if key == Some("Noise") {
        let enabled =
            v.child(&Step::Field("enabled".into()), src).map(|e| e.text(src) != "false").unwrap_or(true);
        let mut on = enabled;
        if ui.checkbox(&mut on, "on").changed() {
            push_edit(cx, st::set_field(src, path, "enabled", if on { "true" } else { "false" }), false);
        }
        if let Some(msg) = refused_here(cx, &[path, &[Step::Field("enabled".into())]].concat()) {
            ui.colored_label(Color32::from_rgb(255, 110, 90), msg);
        }
    }
    let outer = std::mem::replace(&mut cx.owner, key.map(str::to_string));
    for (i, f) in fields.iter().enumerate() {
        match &f.name {
            Some(n) if n == "enabled" && key == Some("Noise") => {}
            Some(n) => field(ui, cx, n, &f.value, &[path, &[Step::Field(n.clone())]].concat()),
            None => field(ui, cx, &format!("{i}"), &f.value, &[path, &[Step::Index(i)]].concat()),
        }
    }
    cx.owner = outer;
    let Some(defaults) = key.and_then(defaults_of) else { return };
    for (name, default) in defaults {
        if fields.iter().any(|f| f.name.as_deref() == Some(name)) {
            continue;
        }
        let p = [path, &[Step::Field(name.to_string())]].concat();
        ui.horizontal(|ui| {
            ui.label(RichText::new(name).weak());
            let refused = refused_here(cx, &p).is_some();
            if let Some(new) = default_widget(ui, &mut cx.rects, default, refused, &p) {
                push_edit(cx, st::add_field(src, path, name, &new), false);
            }
        });
        if let Some(msg) = refused_here(cx, &p) {
            ui.colored_label(Color32::from_rgb(255, 110, 90), msg);
        }
    }
}

/// A field left out: its default as a widget; the text to add when it is edited (the first step
/// of a drag adds the field, which then moves among the file's fields).
fn default_widget(
    ui: &mut egui::Ui,
    rects: &mut Vec<(String, egui::Rect)>,
    default: &str,
    refused: bool,
    path: &[Step],
) -> Option<String> {
    if let Some(g) = group(default) {
        return combo(ui, g, default, path).map(str::to_string);
    }
    match st::parse(default).ok()?.kind {
        Kind::Atom => atom(ui, rects, default, refused, path).0.map(|(text, _)| text),
        _ => ui.button(RichText::new(format!("add {default}")).weak()).clicked().then(|| default.to_string()),
    }
}

/// The variants that can replace `name`'s.
fn group(name: &str) -> Option<&'static [&'static str]> {
    let methods = std::iter::once(method_choices());
    methods.chain(CHOICES.iter().copied()).find(|g| g.iter().any(|c| variant(c) == variant(name)))
}

/// A combo box of `group` showing `current`: the choice picked, if another.
fn combo(ui: &mut egui::Ui, group: &[&'static str], current: &str, path: &[Step]) -> Option<&'static str> {
    let current = variant(current);
    let mut picked = None;
    egui::ComboBox::from_id_salt(st::show(path)).selected_text(current).show_ui(ui, |ui| {
        for c in group.iter() {
            if ui.selectable_label(variant(c) == current, variant(c)).clicked() && variant(c) != current {
                picked = Some(*c);
            }
        }
    });
    picked
}

/// A variant choice for `v` when it has siblings in [`CHOICES`].
fn choice(ui: &mut egui::Ui, cx: &mut Cx, v: &Value, path: &[Step]) {
    let src = cx.src;
    let Some(current) = v.name(src) else { return };
    let Some(group) = group(current) else { return };
    if let Some(c) = combo(ui, group, current, path) {
        // Keep the lighting when switching between textured methods that have it.
        let lighting = v.child(&Step::Field("lighting".into()), src).map(|l| l.text(src).to_string());
        let lit = defaults_of(variant(c)).is_some_and(|d| d.iter().any(|(n, _)| *n == "lighting"));
        let text = match (lighting, c.find('(')) {
            (Some(l), Some(open)) if lit => {
                let inner = &c[open + 1..c.len() - 1];
                let sep = if inner.is_empty() { "" } else { ", " };
                format!("{}({inner}{sep}lighting: {l})", variant(c))
            }
            _ => c.to_string(),
        };
        push_edit(cx, st::set(src, path, &text), false);
    }
}

/// A row of numbers (a vector, a colour with its picker).
fn numbers_row(ui: &mut egui::Ui, cx: &mut Cx, name: &str, v: &Value, path: &[Step]) {
    let src = cx.src;
    let items = v.items();
    let refused = refused_here(cx, path).is_some();
    let mut out: Vec<String> = items.iter().map(|i| i.text(src).to_string()).collect();
    let mut changed = None;
    ui.horizontal(|ui| {
        if name.contains("color") && items.len() == 3 {
            let mut rgb = [0f32; 3];
            for (k, i) in items.iter().enumerate() {
                rgb[k] = i.number(src).unwrap_or(0.0) as f32;
            }
            let r = ui.color_edit_button_rgb(&mut rgb);
            if r.changed() {
                for k in 0..3 {
                    out[k] = format_number((rgb[k] as f64 * 1000.0).round() / 1000.0, "0.0");
                }
                changed = Some((false, false));
            }
        }
        for (k, i) in items.iter().enumerate() {
            let p = [path, &[Step::Index(k)]].concat();
            let (new, stopped) = atom(ui, &mut cx.rects, i.text(src), refused, &p);
            if let Some((text, live)) = new {
                out[k] = text;
                changed = Some((live, false));
            }
            if stopped {
                changed = Some((false, true));
            }
        }
    });
    match changed {
        Some((_, true)) => cx.actions.push(Action::EndGesture),
        Some((live, false)) => push_edit(cx, st::set(src, path, &format!("({})", out.join(", "))), live),
        None => {}
    }
}

/// A number (drag value) or a bool (check box): the new text and whether it is a step of a drag;
/// and whether a drag just ended.
fn atom(
    ui: &mut egui::Ui,
    rects: &mut Vec<(String, egui::Rect)>,
    text: &str,
    refused: bool,
    path: &[Step],
) -> (Option<(String, bool)>, bool) {
    if let Some(x) = st::parse_number(text) {
        let mut y = x;
        let integer = !text.contains(['.', 'e', 'E']);
        let speed = (x.abs() * 0.01).max(if integer { 0.2 } else { 0.001 });
        let mut drag = egui::DragValue::new(&mut y).speed(speed);
        drag = if integer { drag.fixed_decimals(0) } else { drag.max_decimals(6) };
        let r = ui.add(drag);
        rects.push((st::show(path), r.rect));
        if refused {
            ui.painter().rect_stroke(
                r.rect.expand(2.0),
                2.0,
                egui::Stroke::new(2.0, Color32::RED),
                egui::StrokeKind::Outside,
            );
        }
        let r = r.on_hover_text(st::show(path));
        let y = if integer { y.round() } else { y };
        let new = (r.changed() && y != x).then(|| (format_number(y, text), r.dragged()));
        return (new, r.drag_stopped());
    }
    if text == "true" || text == "false" {
        let mut b = text == "true";
        return (ui.checkbox(&mut b, "").changed().then(|| (b.to_string(), false)), false);
    }
    ui.label(RichText::new(text).monospace());
    (None, false)
}

/// The difference view's colour scale: FLIP 0 to 1 in the heat map's colours, with ticks.
fn heat_scale(ui: &mut egui::Ui) {
    const STEPS: usize = 64;
    let (rect, _) = ui.allocate_exact_size(egui::vec2(WIDTH - 40.0, 12.0), egui::Sense::hover());
    let w = rect.width() / STEPS as f32;
    for i in 0..STEPS {
        let [r, g, b, _] = super::difference::colour(i as f32 / (STEPS - 1) as f32);
        let x = rect.left() + i as f32 * w;
        let cell =
            egui::Rect::from_min_max(egui::pos2(x, rect.top()), egui::pos2(x + w + 0.5, rect.bottom()));
        ui.painter().rect_filled(cell, 0.0, egui::Color32::from_rgb(r, g, b));
    }
    // Ticks under the bar, each centred on its value.
    let (labels, _) = ui.allocate_exact_size(egui::vec2(rect.width(), 14.0), egui::Sense::hover());
    let colour = ui.visuals().text_color();
    for (v, text) in [(0.0, "0"), (0.25, "0.25"), (0.5, "0.5"), (0.75, "0.75"), (1.0, "1 FLIP")] {
        let x = rect.left() + v * rect.width();
        let align = if v == 0.0 {
            egui::Align2::LEFT_TOP
        } else if v == 1.0 {
            egui::Align2::RIGHT_TOP
        } else {
            egui::Align2::CENTER_TOP
        };
        ui.painter().text(egui::pos2(x, labels.top()), align, text, egui::FontId::proportional(11.0), colour);
    }
}

/// The node's texel, picked from the scene's, and a preset's look to put on it.
fn looks(ui: &mut egui::Ui, cx: &mut Cx, tree: &Value, node: &Value, path: &[Step]) {
    let src = cx.src;
    let current = node.child(&Step::Field("texel".into()), src).and_then(|n| st::unquote(n.text(src)));
    let names: Vec<String> = match tree.at(&[Step::Field("texels".into())], src).map(|t| &t.kind) {
        Some(Kind::Map(entries)) => entries.iter().filter_map(|(k, _)| st::unquote(k.text(src))).collect(),
        _ => Vec::new(),
    };
    ui.horizontal(|ui| {
        ui.label("texel");
        let id = format!("{} texel", st::show(path));
        let shown = current.clone().unwrap_or_else(|| "(none)".into());
        egui::ComboBox::from_id_salt(id).selected_text(shown).show_ui(ui, |ui| {
            for name in &names {
                if ui.selectable_label(current.as_ref() == Some(name), name).clicked()
                    && current.as_ref() != Some(name)
                {
                    push_edit(cx, super::looks::pick_texel(src, path, name), false);
                }
            }
        });
        let id = format!("{} look", st::show(path));
        egui::ComboBox::from_id_salt(id).selected_text("put a preset").show_ui(ui, |ui| {
            for preset in super::looks::presets() {
                if ui.selectable_label(false, preset).clicked() {
                    push_edit(cx, super::looks::put_preset(src, path, preset), false);
                }
            }
        });
    });
}

/// Buttons that duplicate or remove item `index` of the list at `list` (`what` names it).
fn item_buttons(ui: &mut egui::Ui, cx: &mut Cx, list: &[Step], index: usize, what: &str) {
    let src = cx.src;
    let item = st::show(&[list, &[Step::Index(index)]].concat());
    ui.horizontal(|ui| {
        let duplicate = ui.small_button(format!("duplicate{what}"));
        let remove = ui.small_button(format!("remove{what}"));
        // Where they are, for the window tests (`--record`'s editors).
        cx.rects.push((format!("{item} duplicate"), duplicate.rect));
        cx.rects.push((format!("{item} remove"), remove.rect));
        if duplicate.clicked() {
            push_edit(cx, super::items::duplicate(src, list, index), false);
        }
        if remove.clicked() {
            push_edit(cx, st::remove_item(src, list, index), false);
        }
    });
}
