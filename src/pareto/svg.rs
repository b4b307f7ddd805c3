//! A hand-written SVG chart of speed against error: time (x, log) against error (y, log), one
//! colour per series (method), each series' Pareto front as a step line, the overall front as a
//! dashed black step line with its points ringed, tick labels on both axes and a legend.

use std::fmt::Write;

use super::front;

/// One measured setting.
#[derive(Debug, Clone)]
pub(crate) struct Point {
    pub(crate) x: f64,
    pub(crate) y: f64,
    /// Tooltip text (method and knobs).
    pub(crate) label: String,
    /// A short name written beside the point when it is on its series' front (`64`, `8x`).
    pub(crate) tag: String,
}

/// The points of one method.
#[derive(Debug, Clone)]
pub(crate) struct Series {
    pub(crate) label: String,
    pub(crate) points: Vec<Point>,
}

pub(crate) struct Chart<'a> {
    pub(crate) title: &'a str,
    pub(crate) x_label: &'a str,
    pub(crate) y_label: &'a str,
    pub(crate) series: &'a [Series],
}

const COLOURS: [&str; 6] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
const WIDTH: f64 = 760.0;
const HEIGHT: f64 = 500.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 190.0;
const TOP: f64 = 44.0;
const BOTTOM: f64 = 60.0;

/// A log-scaled axis from `lo` to `hi` onto pixels `a` (at `lo`) to `b` (at `hi`).
struct Axis {
    lo: f64,
    hi: f64,
    a: f64,
    b: f64,
}

impl Axis {
    /// The range of the positive finite `values`, widened a little (and to a decade's fifth at
    /// least) so that no point sits on the frame.
    fn new(values: impl Iterator<Item = f64>, a: f64, b: f64) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && *v > 0.0) {
            lo = lo.min(v.log10());
            hi = hi.max(v.log10());
        }
        if !lo.is_finite() {
            (lo, hi) = (-1.0, 0.0);
        }
        let pad = ((hi - lo) * 0.06).max(0.1);
        Self { lo: lo - pad, hi: hi + pad, a, b }
    }

    /// Pixel of `v`; zero and negative values go to the axis' start.
    fn px(&self, v: f64) -> f64 {
        let l = if v > 0.0 { v.log10().max(self.lo) } else { self.lo };
        self.a + (l - self.lo) / (self.hi - self.lo) * (self.b - self.a)
    }

    /// Tick values: decades, else 1-2-5 or 1..9 per decade when the range is narrow (3 to 12 ticks).
    fn ticks(&self) -> Vec<f64> {
        let mut best = Vec::new();
        for mantissas in [&[1.0][..], &[1.0, 2.0, 5.0], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]] {
            let mut t = Vec::new();
            for k in self.lo.floor() as i32..=self.hi.ceil() as i32 {
                for m in mantissas {
                    let l = (m * 10f64.powi(k)).log10();
                    if l >= self.lo && l <= self.hi {
                        t.push(m * 10f64.powi(k));
                    }
                }
            }
            if t.len() > 12 {
                let step = t.len().div_ceil(8);
                t = t.into_iter().step_by(step).collect();
            }
            best = t;
            if best.len() >= 3 {
                break;
            }
        }
        best
    }
}

/// `m * 10^k` written plainly (0.002, 20, 1e-5 for the very small or large).
pub(crate) fn format_tick(v: f64) -> String {
    let k = v.abs().log10().floor() as i32;
    if !(-4..=5).contains(&k) {
        let m = v / 10f64.powi(k);
        return format!("{}e{k}", trim(format!("{m:.1}")));
    }
    trim(format!("{v:.*}", (-k).max(0) as usize + 1))
}

fn trim(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// XML text and attribute escaping.
pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A step line through `pts` (fastest first): across to the next point's time, then down to its error.
fn step_path(pts: &[(f64, f64)]) -> String {
    let mut d = String::new();
    for (i, &(x, y)) in pts.iter().enumerate() {
        if i == 0 {
            let _ = write!(d, "M{x:.1},{y:.1}");
        } else {
            let _ = write!(d, " H{x:.1} V{y:.1}");
        }
    }
    d
}

/// The chart as a standalone SVG document.
pub(crate) fn render(chart: &Chart) -> String {
    let all: Vec<&Point> = chart.series.iter().flat_map(|s| &s.points).collect();
    let x = Axis::new(all.iter().map(|p| p.x), LEFT, WIDTH - RIGHT);
    let y = Axis::new(all.iter().map(|p| p.y), HEIGHT - BOTTOM, TOP);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="14">{}</text>"#,
        (LEFT + WIDTH - RIGHT) / 2.0,
        escape(chart.title)
    );
    // Grid and tick labels.
    let (x0, x1, y0, y1) = (LEFT, WIDTH - RIGHT, HEIGHT - BOTTOM, TOP);
    for t in x.ticks() {
        let px = x.px(t);
        let _ = writeln!(s, r##"<line x1="{px:.1}" y1="{y1}" x2="{px:.1}" y2="{y0}" stroke="#ddd"/>"##);
        let _ = writeln!(
            s,
            r#"<text class="tick" x="{px:.1}" y="{}" text-anchor="middle">{}</text>"#,
            y0 + 16.0,
            format_tick(t)
        );
    }
    for t in y.ticks() {
        let py = y.px(t);
        let _ = writeln!(s, r##"<line x1="{x0}" y1="{py:.1}" x2="{x1}" y2="{py:.1}" stroke="#ddd"/>"##);
        let _ = writeln!(
            s,
            r#"<text class="tick" x="{}" y="{:.1}" text-anchor="end">{}</text>"#,
            x0 - 6.0,
            py + 4.0,
            format_tick(t)
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{x0}" y="{y1}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        x1 - x0,
        y0 - y1
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (x0 + x1) / 2.0,
        HEIGHT - 18.0,
        escape(chart.x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="20" y="{0}" text-anchor="middle" transform="rotate(-90 20 {0})">{1}</text>"#,
        (y0 + y1) / 2.0,
        escape(chart.y_label)
    );
    // Each series: its front as a step line, then its points.
    let at = |p: &Point| (x.px(p.x), y.px(p.y));
    let mut tags: Vec<(f64, f64, f64)> = Vec::new();
    let drawable = |p: &&Point| p.x.is_finite() && p.y.is_finite();
    for (i, series) in chart.series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let xy: Vec<(f64, f64)> = series.points.iter().map(|p| (p.x, p.y)).collect();
        let on_front = front::front_order(&xy);
        let line: Vec<(f64, f64)> = on_front.iter().map(|&j| at(&series.points[j])).collect();
        let _ = writeln!(s, r#"<g class="series" fill="{colour}" stroke="{colour}">"#);
        let _ =
            writeln!(s, r#"<path class="front" d="{}" fill="none" stroke-width="1.5"/>"#, step_path(&line));
        for (&j, &(px, py)) in on_front.iter().zip(&line) {
            // Left out where it would overlap a tag already written (the tooltip still names it).
            let tag = &series.points[j].tag;
            let rect = (px + 7.0, px + 7.0 + 5.8 * tag.chars().count() as f64, py - 7.0);
            if tags
                .iter()
                .any(|t: &(f64, f64, f64)| rect.0 < t.1 && t.0 < rect.1 && (rect.2 - t.2).abs() < 11.0)
            {
                continue;
            }
            tags.push(rect);
            let _ = writeln!(
                s,
                r#"<text class="tag" x="{:.1}" y="{:.1}" stroke="none" font-size="10">{}</text>"#,
                rect.0,
                rect.2,
                escape(tag)
            );
        }
        for p in series.points.iter().filter(drawable) {
            let (px, py) = at(p);
            let _ = writeln!(
                s,
                r#"<circle class="point" cx="{px:.1}" cy="{py:.1}" r="3.5" stroke="none"><title>{}</title></circle>"#,
                escape(&format!("{}: {} ms, error {}", p.label, sig(p.x), sig(p.y)))
            );
        }
        let _ = writeln!(s, "</g>");
    }
    // The overall front.
    let xy: Vec<(f64, f64)> = all.iter().map(|p| (p.x, p.y)).collect();
    let overall: Vec<(f64, f64)> = front::front_order(&xy).iter().map(|&j| at(all[j])).collect();
    let _ = writeln!(s, r#"<g class="overall" fill="none" stroke="black">"#);
    let _ =
        writeln!(s, r#"<path class="overall-front" d="{}" stroke-dasharray="5 3"/>"#, step_path(&overall));
    for (px, py) in &overall {
        let _ = writeln!(s, r#"<circle class="overall-point" cx="{px:.1}" cy="{py:.1}" r="6.5"/>"#);
    }
    let _ = writeln!(s, "</g>");
    // Legend.
    let lx = x1 + 16.0;
    for (i, series) in chart.series.iter().enumerate() {
        let (colour, ly) = (COLOURS[i % COLOURS.len()], y1 + 12.0 + 20.0 * i as f64);
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{colour}" stroke-width="1.5"/><circle cx="{}" cy="{ly}" r="3.5" fill="{colour}"/><text x="{}" y="{}">{}</text>"#,
            lx + 24.0,
            lx + 12.0,
            lx + 32.0,
            ly + 4.0,
            escape(&series.label)
        );
    }
    let ly = y1 + 12.0 + 20.0 * chart.series.len() as f64;
    let _ = writeln!(
        s,
        r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="black" stroke-dasharray="5 3"/><circle cx="{}" cy="{ly}" r="6.5" fill="none" stroke="black"/><text x="{}" y="{}">overall front</text>"#,
        lx + 24.0,
        lx + 12.0,
        lx + 32.0,
        ly + 4.0
    );
    s.push_str("</svg>\n");
    s
}

/// Three significant digits.
fn sig(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let k = v.abs().log10().floor() as i32;
    trim(format!("{v:.*}", (2 - k).max(0) as usize))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tags open and close in order, attributes are quoted, `&` starts an entity: enough of XML's
    /// well-formedness to catch what string building gets wrong.
    fn assert_well_formed(svg: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut rest = svg;
        while let Some(i) = rest.find('<') {
            let text = &rest[..i];
            assert!(!text.contains('>'), "stray '>' in {text:?}");
            for (j, _) in text.match_indices('&') {
                let e = &text[j..];
                assert!(
                    ["&amp;", "&lt;", "&gt;", "&quot;"].iter().any(|x| e.starts_with(x)),
                    "bare & in {text:?}"
                );
            }
            let end = rest[i..].find('>').expect("unclosed tag") + i;
            let tag = &rest[i + 1..end];
            assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
            assert!(!tag.contains('<'), "'<' inside <{tag}>");
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
            } else if !tag.ends_with('/') {
                stack.push(tag.split_whitespace().next().unwrap().to_string());
            }
            rest = &rest[end + 1..];
        }
        assert!(stack.is_empty(), "unclosed: {stack:?}");
    }

    fn series(label: &str, pts: &[(f64, f64)]) -> Series {
        Series {
            label: label.into(),
            points: pts
                .iter()
                .map(|&(x, y)| Point { x, y, label: format!("{label} <{x}> & co"), tag: format!("{x}") })
                .collect(),
        }
    }

    #[test]
    fn well_formed_with_every_point() {
        let s = [
            series("ViewSlices", &[(3.0, 0.08), (12.0, 0.02), (40.0, 0.005), (45.0, 0.005), (20.0, 0.03)]),
            series("Reference", &[(900.0, 0.001), (300.0, 0.004)]),
        ];
        let svg = render(&Chart { title: "a & b", x_label: "GPU ms", y_label: "FLIP", series: &s });
        assert_well_formed(&svg);
        assert_eq!(svg.matches(r#"class="point""#).count(), 7);
        assert_eq!(svg.matches(r#"class="front""#).count(), 2);
        // Tags on the method fronts: ViewSlices (3, 12, 40), Reference (300, 900).
        assert_eq!(svg.matches(r#"class="tag""#).count(), 5);
        // Overall front: (3, .08), (12, .02), (40, .005), (300, .004), (900, .001).
        assert_eq!(svg.matches(r#"class="overall-point""#).count(), 5);
        assert!(svg.contains(">ViewSlices</text>") && svg.contains(">Reference</text>"));
        assert!(svg.matches(r#"class="tick""#).count() >= 6, "{svg}");
    }

    #[test]
    fn overlapping_tags_are_left_out() {
        let s = [series("a", &[(10.0, 0.1), (10.5, 0.0999), (100.0, 0.01)])];
        let svg = render(&Chart { title: "t", x_label: "x", y_label: "y", series: &s });
        assert_well_formed(&svg);
        assert_eq!(svg.matches(r#"class="point""#).count(), 3);
        assert_eq!(svg.matches(r#"class="tag""#).count(), 2, "{svg}");
    }

    #[test]
    fn single_point_zero_and_nan() {
        let s = [series("one", &[(5.0, 0.0), (f64::NAN, 0.1)])];
        let svg = render(&Chart { title: "t", x_label: "x", y_label: "y", series: &s });
        assert_well_formed(&svg);
        assert_eq!(svg.matches(r#"class="point""#).count(), 1);
        assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
    }

    #[test]
    fn ticks_and_labels() {
        let a = Axis { lo: -3.2, hi: 0.1, a: 0.0, b: 1.0 };
        assert_eq!(a.ticks(), [0.001, 0.01, 0.1, 1.0]);
        let narrow = Axis { lo: 1.05, hi: 1.65, a: 0.0, b: 1.0 };
        assert_eq!(narrow.ticks(), [20.0, 30.0, 40.0]);
        assert_eq!(format_tick(0.002), "0.002");
        assert_eq!(format_tick(20.0), "20");
        assert_eq!(format_tick(1e-6), "1e-6");
        assert_eq!(format_tick(0.5), "0.5");
    }
}
