//! The report's only SVG writer. [`Chart`]: named series of points on linear or log axes,
//! optionally joined by a line, each point optionally with a vertical bar up to a second
//! value (e.g. mean to max) and a tooltip, dashed reference lines and a legend; [`grid`]:
//! several charts in one figure sharing one legend; [`picture`]: an image-like figure of
//! filled cells with marked points. A leaf module.

use std::fmt::Write as _;

/// How an axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear (automatic ranges start at 0).
    Linear,
    /// Decades; values at or below [`FLOOR`] are drawn on the floor.
    Log,
}

/// Values at or below this are drawn on a log axis's floor (an exact result).
pub const FLOOR: f64 = 1e-12;

/// One point of a [`Series`].
#[derive(Clone, Debug)]
pub struct Pt {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// Optional upper end of a vertical bar from `y`.
    pub y_hi: Option<f64>,
    /// Optional tooltip.
    pub note: Option<String>,
}

impl Pt {
    /// A plain point.
    pub fn new(x: f64, y: f64) -> Self {
        Pt {
            x,
            y,
            y_hi: None,
            note: None,
        }
    }
}

/// A named series, drawn in one colour (the palette's `i`-th for the chart's `i`-th series).
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend entry.
    pub label: String,
    /// Its points (non-finite ones are skipped).
    pub points: Vec<Pt>,
    /// Join the points with a line.
    pub line: bool,
    /// Draw it wide (thick line, big dots), so that series on top of it stay visible.
    pub wide: bool,
}

impl Series {
    /// Points, not joined.
    pub fn dots(label: impl Into<String>, points: Vec<Pt>) -> Self {
        Series {
            label: label.into(),
            points,
            line: false,
            wide: false,
        }
    }

    /// Points joined by a line.
    pub fn line(label: impl Into<String>, points: Vec<Pt>) -> Self {
        Series {
            line: true,
            ..Series::dots(label, points)
        }
    }

    /// The same series, drawn wide.
    pub fn wide(self) -> Self {
        Series { wide: true, ..self }
    }
}

/// An axis of a [`Chart`]: label and scale, and optionally a fixed range and fixed ticks
/// (otherwise both follow the data: whole decades on a log axis, from 0 on a linear one).
#[derive(Clone, Debug)]
pub struct Axis {
    /// Label.
    pub label: String,
    /// Scale.
    pub scale: Scale,
    /// Fixed `(low, high)`, in data units.
    pub range: Option<(f64, f64)>,
    /// Fixed ticks: (value, label).
    pub ticks: Option<Vec<(f64, String)>>,
}

impl Axis {
    /// An axis whose range and ticks follow the data.
    pub fn new(label: impl Into<String>, scale: Scale) -> Self {
        Axis {
            label: label.into(),
            scale,
            range: None,
            ticks: None,
        }
    }

    /// The same axis over `[lo, hi]`.
    pub fn range(self, lo: f64, hi: f64) -> Self {
        Axis {
            range: Some((lo, hi)),
            ..self
        }
    }

    /// The same axis with these ticks (value, label).
    pub fn ticks(self, ticks: Vec<(f64, String)>) -> Self {
        Axis {
            ticks: Some(ticks),
            ..self
        }
    }
}

/// A chart: title, axes, series and horizontal reference lines.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Title.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Series, in legend order.
    pub series: Vec<Series>,
    /// Dashed horizontal lines: (y, label), e.g. a documented bound.
    pub rules: Vec<(f64, String)>,
}

impl Chart {
    /// A chart without reference lines.
    pub fn new(title: impl Into<String>, x: Axis, y: Axis, series: Vec<Series>) -> Self {
        Chart {
            title: title.into(),
            x,
            y,
            series,
            rules: Vec::new(),
        }
    }

    /// The same chart with a dashed horizontal line at `y`, labelled.
    pub fn rule(mut self, y: f64, label: impl Into<String>) -> Self {
        self.rules.push((y, label.into()));
        self
    }

    /// A complete SVG document (800 × 420): the chart with its legend on the right.
    pub fn svg(&self) -> String {
        let (w, h) = (800.0, 420.0);
        let mut s = open(w, h, 12);
        let frame = Frame {
            ox: 0.0,
            oy: 0.0,
            w,
            h,
            left: 80.0,
            right: 330.0,
            top: 40.0,
            bottom: 60.0,
        };
        draw(&mut s, self, &frame, true);
        let labels: Vec<&str> = self.series.iter().map(|x| x.label.as_str()).collect();
        legend(&mut s, &labels, |i| {
            (w - frame.right + 16.0, frame.top + 16.0 + 18.0 * i as f64)
        });
        s + "</svg>\n"
    }
}

/// One SVG document of `charts` in `cols` columns of `panel = (width, height)` each, with one
/// legend below them: the series labels of the first chart (the charts should list the same
/// series in the same order, so that each label names one colour in every panel).
pub fn grid(charts: &[Chart], cols: usize, panel: (f64, f64)) -> String {
    let cols = cols.max(1);
    let rows = charts.len().div_ceil(cols).max(1);
    let (pw, ph) = panel;
    let (w, h) = (pw * cols as f64, ph * rows as f64 + 40.0);
    let mut s = open(w, h, 11);
    for (i, c) in charts.iter().enumerate() {
        let frame = Frame {
            ox: (i % cols) as f64 * pw,
            oy: (i / cols) as f64 * ph,
            w: pw,
            h: ph,
            left: 62.0,
            right: 20.0,
            top: 30.0,
            bottom: 45.0,
        };
        draw(&mut s, c, &frame, false);
    }
    if let Some(first) = charts.first() {
        let labels: Vec<&str> = first.series.iter().map(|x| x.label.as_str()).collect();
        legend(&mut s, &labels, |i| (10.0 + 150.0 * i as f64, h - 15.0));
    }
    s + "</svg>\n"
}

/// A filled rectangle of a [`picture`], in pixels from the top left.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Left edge.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Width.
    pub w: f64,
    /// Height.
    pub h: f64,
    /// Fill colour (`#rrggbb`).
    pub fill: String,
}

/// An image-like SVG document of `width × height` pixels: the `background` colour, the
/// `cells` in order, and a white dot with a black outline at each of `marks`.
pub fn picture(
    (width, height): (f64, f64),
    background: &str,
    cells: &[Cell],
    marks: &[(f64, f64)],
) -> String {
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\">\n\
         <rect width=\"{width}\" height=\"{height}\" fill=\"{background}\"/>\n"
    );
    for c in cells {
        let _ = writeln!(
            s,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>",
            c.x, c.y, c.w, c.h, c.fill
        );
    }
    for (x, y) in marks {
        let _ = writeln!(
            s,
            "<circle cx=\"{x}\" cy=\"{y}\" r=\"3\" fill=\"#fff\" stroke=\"#000\"/>"
        );
    }
    s + "</svg>\n"
}

const COLORS: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
];

fn color(i: usize) -> &'static str {
    COLORS[i % COLORS.len()]
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The opening of an SVG document with a white background.
fn open(w: f64, h: f64, font_size: u32) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="{font_size}">
<rect width="{w}" height="{h}" fill="white"/>
"#
    )
}

/// A legend: a dot and a label per entry, the `i`-th at `at(i)`.
fn legend(s: &mut String, labels: &[&str], at: impl Fn(usize) -> (f64, f64)) {
    for (i, label) in labels.iter().enumerate() {
        let (x, y) = at(i);
        let _ = writeln!(
            s,
            r#"<circle cx="{x}" cy="{}" r="5" fill="{}"/><text x="{}" y="{y}">{}</text>"#,
            y - 4.0,
            color(i),
            x + 10.0,
            esc(label)
        );
    }
}

/// Where a chart is drawn: its box `(ox, oy, w, h)` in the document and the margins of the
/// plot area inside it.
struct Frame {
    ox: f64,
    oy: f64,
    w: f64,
    h: f64,
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
}

impl Frame {
    fn plot_w(&self) -> f64 {
        self.w - self.left - self.right
    }
    fn plot_h(&self) -> f64 {
        self.h - self.top - self.bottom
    }
}

/// An axis mapped: value → `[0, 1]` of the plot area (clamped), and its ticks.
struct Mapped {
    scale: Scale,
    lo: f64,
    hi: f64,
    ticks: Vec<(f64, String)>,
}

fn transform(scale: Scale, v: f64) -> f64 {
    match scale {
        Scale::Linear => v,
        Scale::Log => v.max(FLOOR).log10(),
    }
}

impl Mapped {
    /// `axis` over `values` (non-finite ones ignored), with about `max_ticks` automatic ticks.
    fn new(axis: &Axis, values: impl Iterator<Item = f64>, max_ticks: usize) -> Mapped {
        let scale = axis.scale;
        let (lo, hi) = match axis.range {
            Some((lo, hi)) => (transform(scale, lo), transform(scale, hi)),
            None => {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for v in values.filter(|v| v.is_finite()) {
                    lo = lo.min(transform(scale, v));
                    hi = hi.max(transform(scale, v));
                }
                if !lo.is_finite() {
                    (lo, hi) = (0.0, 1.0);
                }
                match scale {
                    Scale::Linear => {
                        let lo = lo.min(0.0);
                        (lo, if hi > lo { hi } else { lo + 1.0 })
                    }
                    Scale::Log => (lo.floor(), hi.ceil().max(lo.floor() + 1.0)),
                }
            }
        };
        let hi = if hi > lo { hi } else { lo + 1.0 };
        let ticks = axis
            .ticks
            .clone()
            .unwrap_or_else(|| auto_ticks(scale, lo, hi, max_ticks.max(2)));
        Mapped {
            scale,
            lo,
            hi,
            ticks,
        }
    }

    fn frac(&self, v: f64) -> f64 {
        ((transform(self.scale, v) - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0)
    }
}

/// Whole decades (every `k`-th, at most `max_ticks`) on a log axis over `[lo, hi]`
/// (exponents), five even steps on a linear one.
fn auto_ticks(scale: Scale, lo: f64, hi: f64, max_ticks: usize) -> Vec<(f64, String)> {
    match scale {
        Scale::Log => {
            let step = ((hi - lo) / max_ticks as f64).ceil().max(1.0);
            let mut d = lo.ceil();
            let mut out = Vec::new();
            while d <= hi + 1e-9 {
                out.push((10f64.powf(d), format!("1e{d}")));
                d += step;
            }
            out
        }
        Scale::Linear => (0..=4)
            .map(|k| {
                let v = lo + (hi - lo) * k as f64 / 4.0;
                let digits = if hi - lo >= 10.0 { 0 } else { 3 };
                (v, format!("{v:.digits$}"))
            })
            .collect(),
    }
}

/// Draws `c` into `f`: frame, grid lines, ticks, axis labels, title (centred when
/// `centred_title`, else bold at the left), reference lines, series.
fn draw(s: &mut String, c: &Chart, f: &Frame, centred_title: bool) {
    let all = || c.series.iter().flat_map(|x| x.points.iter());
    let xa = Mapped::new(
        &c.x,
        all().map(|p| p.x),
        (f.plot_w() / 45.0).floor() as usize,
    );
    let ya = Mapped::new(
        &c.y,
        all()
            .flat_map(|p| [Some(p.y), p.y_hi])
            .flatten()
            .chain(c.rules.iter().map(|r| r.0)),
        (f.plot_h() / 25.0).floor() as usize,
    );
    let (left, top) = (f.ox + f.left, f.oy + f.top);
    let (right, bottom) = (left + f.plot_w(), top + f.plot_h());
    let px = |x: f64| left + xa.frac(x) * f.plot_w();
    let py = |y: f64| bottom - ya.frac(y) * f.plot_h();
    if centred_title {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" font-size="14" text-anchor="middle">{}</text>"#,
            (left + right) / 2.0,
            top - 18.0,
            esc(&c.title)
        );
    } else {
        let _ = writeln!(
            s,
            r#"<text x="{left}" y="{}" font-weight="bold">{}</text>"#,
            top - 10.0,
            esc(&c.title)
        );
    }
    for (v, label) in &xa.ticks {
        let x = px(*v);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{bottom}" x2="{x:.1}" y2="{top}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
            bottom + 16.0,
            esc(label)
        );
    }
    for (v, label) in &ya.ticks {
        let y = py(*v);
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{y:.1}" x2="{right}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            left - 6.0,
            y + 4.0,
            esc(label)
        );
    }
    let _ = writeln!(
        s,
        r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="#444"/>"##,
        f.plot_w(),
        f.plot_h()
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (left + right) / 2.0,
        bottom + 36.0,
        esc(&c.x.label)
    );
    let (lx, ly) = (f.ox + 14.0, (top + bottom) / 2.0);
    let _ = writeln!(
        s,
        r#"<text x="{lx}" y="{ly}" text-anchor="middle" transform="rotate(-90 {lx} {ly})">{}</text>"#,
        esc(&c.y.label)
    );
    for (y, label) in &c.rules {
        let y = py(*y);
        // The label above the line, or below it where the line runs along the top.
        let label_y = if y - top < 14.0 { y + 13.0 } else { y - 3.0 };
        let _ = writeln!(
            s,
            r##"<line x1="{left}" x2="{right}" y1="{y:.1}" y2="{y:.1}" stroke="#b00" stroke-dasharray="4 3"/><text x="{}" y="{label_y:.1}" fill="#b00" text-anchor="end">{}</text>"##,
            right - 2.0,
            esc(label)
        );
    }
    let x_ok = |v: f64| v.is_finite() && (c.x.scale == Scale::Linear || v > 0.0);
    for (i, ser) in c.series.iter().enumerate() {
        let col = color(i);
        let (width, r) = if ser.wide { (5.0, 6.0) } else { (2.0, 3.5) };
        let pts: Vec<&Pt> = ser
            .points
            .iter()
            .filter(|p| x_ok(p.x) && p.y.is_finite())
            .collect();
        if ser.line && pts.len() > 1 {
            let line: Vec<String> = pts
                .iter()
                .map(|p| format!("{:.1},{:.1}", px(p.x), py(p.y)))
                .collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{col}" stroke-width="{width}"/>"#,
                line.join(" ")
            );
        }
        for p in pts {
            let (x, y) = (px(p.x), py(p.y));
            if let Some(hi) = p.y_hi.filter(|v| v.is_finite()) {
                let _ = writeln!(
                    s,
                    r#"<line x1="{x:.1}" y1="{y:.1}" x2="{x:.1}" y2="{:.1}" stroke="{col}" stroke-width="2"/>"#,
                    py(hi)
                );
            }
            let tip = p
                .note
                .as_deref()
                .map_or(String::new(), |n| format!("<title>{}</title>", esc(n)));
            let _ = writeln!(
                s,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r}" fill="{col}" fill-opacity="0.85">{tip}</circle>"#
            );
        }
    }
}
