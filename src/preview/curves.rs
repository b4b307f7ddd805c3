//! The panel's transfer-function editors: a 1D shape function (`Curve([(x, y, slope), ..])`) and
//! an RGBA transfer function (`Ramp([(density, (r, g, b, a)), ..])`) as curves whose control
//! points are dragged (x kept between its neighbours), added (double click) and deleted (right
//! click); a 2D shape function (`Grid`, `Image`) shown as an image.

use egui::{pos2, Color32, Pos2, Rect, Sense, Stroke, StrokeKind, Vec2};

use super::panel::{Action, Cx};
use super::scene_text::{self as st, format_number, Step, Value};
use crate::cpu::bake_transfer::{transfer_curve, HERMITE, LINEAR};
use crate::types::{TransferFunction, TransferPoint};

/// Pixels within which a press picks a control point.
const PICK: f32 = 8.0;
/// Height of a curve editor.
const HEIGHT: f32 = 130.0;
/// Pixels from a point to its tangent's handle.
const HANDLE: f32 = 18.0;
/// The steepest slope a tangent's handle sets (curve units).
const MAX_SLOPE: f64 = 50.0;

/// One curve of an editor: its control points (x, y) and how the points read and write.
struct Curve {
    color: Color32,
    points: Vec<[f64; 3]>,
    kind: u32,
}

/// Where point `p`'s tangent handle is drawn: [`HANDLE`] pixels along its slope, rightwards.
fn tangent_handle(r: Rect, p: &[f64; 3]) -> Pos2 {
    let dir = Vec2::new(r.width(), -(p[2] as f32) * r.height()).normalized();
    to_screen(r, p[0], p[1]) + dir * HANDLE
}

fn to_screen(r: Rect, x: f64, y: f64) -> Pos2 {
    pos2(r.left() + x as f32 * r.width(), r.bottom() - y as f32 * r.height())
}

fn from_screen(r: Rect, p: Pos2) -> (f64, f64) {
    let x = ((p.x - r.left()) / r.width()).clamp(0.0, 1.0) as f64;
    let y = ((r.bottom() - p.y) / r.height()).clamp(0.0, 1.0) as f64;
    ((x * 1000.0).round() / 1000.0, (y * 1000.0).round() / 1000.0)
}

fn num(v: f64) -> String {
    format_number(v, "0.0")
}

fn sample(c: &Curve, x: f64) -> f64 {
    let points: Vec<TransferPoint> = c
        .points
        .iter()
        .map(|p| TransferPoint { x: p[0] as f32, y: p[1] as f32, slope: p[2] as f32, _pad: 0.0 })
        .collect();
    let f = TransferFunction { first: 0, count: points.len() as u32, kind: c.kind, _pad: 0 };
    transfer_curve(&f, &points, x)
}

/// The drawing area with its grid, and its response.
fn area(ui: &mut egui::Ui) -> (egui::Response, egui::Painter, Rect) {
    let size = Vec2::new(ui.available_width().max(120.0), HEIGHT);
    let (resp, painter) = ui.allocate_painter(size, Sense::click_and_drag());
    let r = resp.rect.shrink(6.0);
    painter.rect_filled(resp.rect, 2.0, Color32::from_gray(24));
    for k in 0..=4 {
        let t = k as f32 / 4.0;
        let stroke = Stroke::new(1.0, Color32::from_gray(if k % 4 == 0 { 90 } else { 50 }));
        painter.line_segment(
            [pos2(r.left() + t * r.width(), r.top()), pos2(r.left() + t * r.width(), r.bottom())],
            stroke,
        );
        painter.line_segment(
            [pos2(r.left(), r.top() + t * r.height()), pos2(r.right(), r.top() + t * r.height())],
            stroke,
        );
    }
    (resp, painter, r)
}

fn draw(painter: &egui::Painter, r: Rect, c: &Curve) {
    let line: Vec<Pos2> =
        (0..=128).map(|i| i as f64 / 128.0).map(|x| to_screen(r, x, sample(c, x))).collect();
    painter.line(line, Stroke::new(1.5, c.color));
    for p in &c.points {
        painter.circle_filled(to_screen(r, p[0], p[1]), 4.0, c.color);
    }
}

/// The (curve, point) nearest the pointer within [`PICK`] pixels.
fn pick(r: Rect, curves: &[Curve], at: Pos2) -> Option<(usize, usize)> {
    let mut best = None;
    let mut dist = PICK;
    for (ci, c) in curves.iter().enumerate() {
        for (pi, p) in c.points.iter().enumerate() {
            let d = to_screen(r, p[0], p[1]).distance(at);
            if d <= dist {
                dist = d;
                best = Some((ci, pi));
            }
        }
    }
    best
}

/// What the pointer did to a curve editor: move point `i` of curve `c` to (x, y), add a point at
/// (x, y), or delete point `i`.
enum Gesture {
    Move { c: usize, i: usize, x: f64, y: f64 },
    Add { x: f64, y: f64 },
    Delete { i: usize },
}

fn interact(
    ui: &egui::Ui,
    resp: &egui::Response,
    r: Rect,
    curves: &[Curve],
    id: egui::Id,
) -> Option<Gesture> {
    let at = resp.interact_pointer_pos().or(resp.hover_pos())?;
    // A drag's point and where it was grabbed from the point's centre: the point moves with the
    // pointer by as much as the pointer moves (a grab a few pixels off does not make it jump).
    type Grab = Option<(usize, usize, [f32; 2])>;
    if resp.drag_started() {
        // The point under the press, not under the pointer once it has moved enough to drag.
        let origin = ui.input(|i| i.pointer.press_origin()).unwrap_or(at);
        let grab: Grab = pick(r, curves, origin).map(|(c, i)| {
            let p = curves[c].points[i];
            let off = to_screen(r, p[0], p[1]) - origin;
            (c, i, [off.x, off.y])
        });
        ui.data_mut(|d| d.insert_temp(id, grab));
    }
    let dragging: Option<Grab> = ui.data(|d| d.get_temp(id));
    if resp.drag_stopped() {
        ui.data_mut(|d| d.remove::<Grab>(id));
    }
    // The frame a drag stops in may hold its last move.
    if resp.dragged() || resp.drag_stopped() {
        if let Some(Some((c, i, off))) = dragging {
            let (mut x, y) = from_screen(r, at + egui::vec2(off[0], off[1]));
            let pts = &curves[c].points;
            // x stays strictly between the neighbours' (the file's points are sorted by x).
            let lo = if i > 0 { pts[i - 1][0] + 0.001 } else { 0.0 };
            let hi = if i + 1 < pts.len() { pts[i + 1][0] - 0.001 } else { 1.0 };
            x = x.clamp(lo, hi.max(lo));
            return Some(Gesture::Move { c, i, x, y });
        }
    }
    if resp.double_clicked() && pick(r, curves, at).is_none() {
        let (x, y) = from_screen(r, at);
        return Some(Gesture::Add { x, y });
    }
    if resp.secondary_clicked() {
        if let Some((_, i)) = pick(r, curves, at) {
            return Some(Gesture::Delete { i });
        }
    }
    None
}

/// Turns a gesture on the point list at `list` into edits.
fn act(
    cx: &mut Cx,
    list: &[Step],
    g: Gesture,
    n: usize,
    text_of: impl Fn(usize, Option<(usize, f64, f64)>) -> String,
    insert_at: impl Fn(f64, f64) -> (usize, String),
    resp: &egui::Response,
) {
    let src = cx.src;
    let edit = match g {
        Gesture::Move { c, i, x, y } => {
            let mut path = list.to_vec();
            path.push(Step::Index(i));
            st::set(src, &path, &text_of(i, Some((c, x, y))))
        }
        Gesture::Add { x, y } => {
            let (at, text) = insert_at(x, y);
            st::insert_item(src, list, at, &text)
        }
        Gesture::Delete { i } if n > 2 => st::remove_item(src, list, i),
        Gesture::Delete { .. } => {
            cx.actions.push(Action::Note("a curve keeps at least 2 control points".into()));
            return;
        }
    };
    match edit {
        Ok(edit) => cx.actions.push(Action::Edit { edit, live: resp.dragged() }),
        Err(e) => cx.actions.push(Action::Note(e.to_string())),
    }
}

fn numbers(v: &Value, src: &str) -> Vec<f64> {
    v.items().iter().map(|i| i.number(src).unwrap_or(0.0)).collect()
}

/// `Curve([(x, y, slope), ..])` at `path` (the `Curve(..)` value).
pub(crate) fn shape_curve(ui: &mut egui::Ui, cx: &mut Cx, v: &Value, path: &[Step]) {
    let src = cx.src;
    let Some(list) = v.items().first().copied() else { return };
    let mut list_path = path.to_vec();
    list_path.push(Step::Index(0));
    let points: Vec<[f64; 3]> = list
        .items()
        .iter()
        .map(|p| {
            let n = numbers(p, src);
            [
                n.first().copied().unwrap_or(0.0),
                n.get(1).copied().unwrap_or(0.0),
                n.get(2).copied().unwrap_or(0.0),
            ]
        })
        .collect();
    let curves = [Curve { color: Color32::from_rgb(230, 200, 90), points: points.clone(), kind: HERMITE }];
    let (resp, painter, r) = area(ui);
    cx.rects.push((st::show(path), resp.rect));
    draw(&painter, r, &curves[0]);
    // Each point's tangent as a handle: dragged, it sets the point's slope.
    for p in &points {
        let (at, end) = (to_screen(r, p[0], p[1]), tangent_handle(r, p));
        painter.line_segment([at, end], Stroke::new(1.0, Color32::from_gray(160)));
        painter.circle_stroke(end, 3.0, Stroke::new(1.0, Color32::from_gray(200)));
    }
    let tangent_id = resp.id.with("tangent");
    if resp.drag_started() {
        let origin = ui.input(|i| i.pointer.press_origin()).unwrap_or(r.center());
        // A handle, unless a point is under the press (points win).
        let grabbed = (pick(r, &curves, origin).is_none())
            .then(|| points.iter().position(|p| tangent_handle(r, p).distance(origin) <= PICK))
            .flatten();
        ui.data_mut(|d| d.insert_temp(tangent_id, grabbed));
    }
    let tangent: Option<usize> = ui.data(|d| d.get_temp(tangent_id)).flatten();
    if resp.drag_stopped() {
        ui.data_mut(|d| d.remove::<Option<usize>>(tangent_id));
    }
    let id = resp.id.with("drag");
    if let (Some(i), Some(at)) = (tangent, resp.interact_pointer_pos()) {
        if resp.dragged() || resp.drag_stopped() {
            let p = points[i];
            let v = at - to_screen(r, p[0], p[1]);
            // In the curve's units; a handle pulled to or past the vertical is steep, not reversed.
            let (dx, dy) = ((v.x / r.width()).max(1e-3) as f64, (-v.y / r.height()) as f64);
            let slope = (dy / dx).clamp(-MAX_SLOPE, MAX_SLOPE);
            let text = format!("({}, {}, {})", num(p[0]), num(p[1]), num(slope));
            let point = [list_path.as_slice(), &[Step::Index(i)]].concat();
            match st::set(src, &point, &text) {
                Ok(edit) => cx.actions.push(Action::Edit { edit, live: resp.dragged() }),
                Err(e) => cx.actions.push(Action::Note(e.to_string())),
            }
        }
    } else if let Some(g) = interact(ui, &resp, r, &curves, id) {
        let slope_text =
            |i: usize| list.items()[i].items().get(2).map_or("0.0".to_string(), |s| s.text(src).to_string());
        act(
            cx,
            &list_path,
            g,
            points.len(),
            |i, m| {
                let (_, x, y) = m.unwrap_or((0, points[i][0], points[i][1]));
                format!("({}, {}, {})", num(x), num(y), slope_text(i))
            },
            |x, y| {
                let at = points.iter().position(|p| p[0] > x).unwrap_or(points.len());
                (at, format!("({}, {}, 0.0)", num(x), num(y)))
            },
            &resp,
        );
    }
    if resp.drag_stopped() {
        cx.actions.push(Action::EndGesture);
    }
    ui.small("drag a point or its tangent's handle; double click: add; right click: delete");
}

/// `Ramp([(density, (r, g, b, a)), ..])` at `path`: one curve per channel.
pub(crate) fn color_ramp(ui: &mut egui::Ui, cx: &mut Cx, v: &Value, path: &[Step]) {
    let src = cx.src;
    let Some(list) = v.items().first().copied() else { return };
    let mut list_path = path.to_vec();
    list_path.push(Step::Index(0));
    let points: Vec<(f64, [f64; 4])> = list
        .items()
        .iter()
        .map(|p| {
            let items = p.items();
            let d = items.first().and_then(|d| d.number(src)).unwrap_or(0.0);
            let c = items.get(1).map(|c| numbers(c, src)).unwrap_or_default();
            (d, std::array::from_fn(|k| c.get(k).copied().unwrap_or(0.0)))
        })
        .collect();
    let colors = [
        Color32::from_rgb(230, 70, 70),
        Color32::from_rgb(70, 200, 70),
        Color32::from_rgb(80, 120, 240),
        Color32::from_gray(220),
    ];
    let curves: Vec<Curve> = (0..4)
        .map(|k| Curve {
            color: colors[k],
            points: points.iter().map(|(d, c)| [*d, c[k], 0.0]).collect(),
            kind: LINEAR,
        })
        .collect();
    let (resp, painter, r) = area(ui);
    cx.rects.push((st::show(path), resp.rect));
    // The colour itself along the bottom.
    let strip = Rect::from_min_max(pos2(r.left(), r.bottom() - 8.0), r.right_bottom());
    for i in 0..64 {
        let x = i as f64 / 63.0;
        let rgb: Vec<u8> =
            (0..3).map(|k| (sample(&curves[k], x).clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0) as u8).collect();
        let cell = Rect::from_min_max(
            pos2(strip.left() + i as f32 / 64.0 * strip.width(), strip.top()),
            pos2(strip.left() + (i + 1) as f32 / 64.0 * strip.width(), strip.bottom()),
        );
        painter.rect_filled(cell, 0.0, Color32::from_rgb(rgb[0], rgb[1], rgb[2]));
    }
    for c in &curves {
        draw(&painter, r, c);
    }
    let id = resp.id.with("drag");
    if let Some(g) = interact(ui, &resp, r, &curves, id) {
        act(
            cx,
            &list_path,
            g,
            points.len(),
            |i, m| {
                let (mut d, mut c) = points[i];
                if let Some((k, x, y)) = m {
                    d = x;
                    c[k] = y;
                }
                format!("({}, ({}, {}, {}, {}))", num(d), num(c[0]), num(c[1]), num(c[2]), num(c[3]))
            },
            |x, _| {
                let at = points.iter().position(|p| p.0 > x).unwrap_or(points.len());
                let c: Vec<String> =
                    curves.iter().map(|c| num((sample(c, x) * 1000.0).round() / 1000.0)).collect();
                (at, format!("({}, ({}, {}, {}, {}))", num(x), c[0], c[1], c[2], c[3]))
            },
            &resp,
        );
    }
    if resp.drag_stopped() {
        cx.actions.push(Action::EndGesture);
    }
    ui.small("r g b a by density: drag a point; double click: add; right click: delete");
}

/// A 2D shape function (rows by density from 0 at the top, columns by noise value) as an image.
pub(crate) fn grid_image(ui: &mut egui::Ui, cx: &mut Cx, rows: &[Vec<f64>], path: &[Step], paint: bool) {
    let key = st::show(path);
    let (h, w) = (rows.len(), rows.first().map_or(0, Vec::len));
    if h == 0 || w == 0 {
        return;
    }
    let gray: Vec<u8> =
        rows.iter().flat_map(|r| r.iter().map(|v| (v.clamp(0.0, 1.0) * 255.0) as u8)).collect();
    let image = egui::ColorImage::from_gray([w, h], &gray);
    let hash = {
        use std::hash::{Hash, Hasher};
        let mut s = std::collections::hash_map::DefaultHasher::new();
        gray.hash(&mut s);
        (w, h).hash(&mut s);
        s.finish()
    };
    let id = ui.scope_id().with(("grid", &key));
    let cached: Option<(u64, egui::TextureHandle)> = ui.data(|d| d.get_temp(id));
    let tex = match cached {
        Some((k, t)) if k == hash => t,
        _ => {
            let t = ui.ctx().load_texture(&key, image, egui::TextureOptions::NEAREST);
            ui.data_mut(|d| d.insert_temp(id, (hash, t.clone())));
            t
        }
    };
    // The brush's density (a `Grid` is painted as the paper paints its 2D transfer functions).
    let brush_id = id.with("brush");
    let mut brush: f64 = ui.data(|d| d.get_temp(brush_id)).unwrap_or(1.0);
    if paint {
        ui.horizontal(|ui| {
            ui.label("brush");
            if ui.add(egui::Slider::new(&mut brush, 0.0..=1.0).max_decimals(2)).changed() {
                ui.data_mut(|d| d.insert_temp(brush_id, brush));
            }
        });
    }
    let width = ui.available_width().max(120.0);
    let size = Vec2::new(width, (width * h as f32 / w as f32).clamp(24.0, 160.0));
    let sense = if paint { Sense::click_and_drag() } else { Sense::hover() };
    let (resp, painter) = ui.allocate_painter(size, sense);
    painter.image(tex.id(), resp.rect, Rect::from_min_max(pos2(0.0, 0.0), pos2(1.0, 1.0)), Color32::WHITE);
    painter.rect_stroke(resp.rect, 0.0, Stroke::new(1.0, Color32::from_gray(90)), StrokeKind::Inside);
    cx.rects.push((key.clone(), resp.rect));
    ui.small(if paint {
        format!("{h} densities (top: 0) x {w} noise values (left: 0): paint with the brush, right button: 0")
    } else {
        format!("{h} densities (top: 0) x {w} noise values (left: 0)")
    });
    if !paint {
        return;
    }
    // The cell under the pointer takes the brush's value (0 with the right button); a stroke is
    // one undo step, as a curve drag is.
    let pressed = resp.dragged() || resp.clicked() || resp.secondary_clicked() || resp.drag_stopped();
    if let (true, Some(at)) = (pressed, resp.interact_pointer_pos()) {
        let r = resp.rect;
        let col = (((at.x - r.left()) / r.width()) * w as f32).floor().clamp(0.0, w as f32 - 1.0) as usize;
        let row = (((at.y - r.top()) / r.height()) * h as f32).floor().clamp(0.0, h as f32 - 1.0) as usize;
        let erase = resp.secondary_clicked() || ui.input(|i| i.pointer.secondary_down());
        let value = if erase { 0.0 } else { brush };
        if (rows[row][col] - value).abs() > 1e-9 {
            let cell = [path, &[Step::Index(0), Step::Index(row), Step::Index(col)]].concat();
            let text = st::format_number(value, "0.0");
            match st::set(cx.src, &cell, &text) {
                Ok(edit) => cx.actions.push(Action::Edit { edit, live: resp.dragged() }),
                Err(e) => cx.actions.push(Action::Note(e.to_string())),
            }
        }
    }
    if resp.drag_stopped() {
        cx.actions.push(Action::EndGesture);
    }
}
