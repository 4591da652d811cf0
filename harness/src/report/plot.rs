//! A small SVG chart for the report sections: named series of points on linear or log
//! axes, optionally joined by a line, each point optionally with a vertical bar up to a
//! second value (e.g. mean to max) and a tooltip.

use std::fmt::Write as _;

/// How an axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear from 0.
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

/// A named series, drawn in one colour.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend entry.
    pub label: String,
    /// Its points (non-finite ones are skipped).
    pub points: Vec<Pt>,
    /// Join the points with a line.
    pub line: bool,
}

const COLORS: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// An axis: value → `[0, 1]` of the plot area, and its tick values with labels.
struct Axis {
    scale: Scale,
    lo: f64,
    hi: f64,
}

impl Axis {
    fn new(scale: Scale, values: impl Iterator<Item = f64>) -> Axis {
        let t = |v: f64| match scale {
            Scale::Linear => v,
            Scale::Log => v.max(FLOOR).log10(),
        };
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && (scale == Scale::Linear || *v > 0.0)) {
            lo = lo.min(t(v));
            hi = hi.max(t(v));
        }
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        match scale {
            Scale::Linear => Axis {
                scale,
                lo: lo.min(0.0),
                hi: if hi > lo.min(0.0) {
                    hi
                } else {
                    lo.min(0.0) + 1.0
                },
            },
            Scale::Log => Axis {
                scale,
                lo: lo.floor(),
                hi: hi.ceil().max(lo.floor() + 1.0),
            },
        }
    }

    fn frac(&self, v: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => v,
            Scale::Log => v.max(FLOOR).log10(),
        };
        (t - self.lo) / (self.hi - self.lo)
    }

    fn ticks(&self) -> Vec<(f64, String)> {
        match self.scale {
            Scale::Log => {
                let mut d = self.lo;
                let mut out = Vec::new();
                while d <= self.hi + 1e-9 {
                    out.push((10f64.powf(d), format!("1e{d}")));
                    d += 1.0;
                }
                out
            }
            Scale::Linear => (0..=4)
                .map(|k| {
                    let v = self.lo + (self.hi - self.lo) * k as f64 / 4.0;
                    let digits = if self.hi - self.lo >= 10.0 { 0 } else { 3 };
                    (v, format!("{v:.digits$}"))
                })
                .collect(),
        }
    }
}

/// A complete SVG document: the axes with ticks, one colour per series, a legend.
pub fn chart(
    title: &str,
    (x_label, x_scale): (&str, Scale),
    (y_label, y_scale): (&str, Scale),
    series: &[Series],
) -> String {
    let (w, h) = (800.0, 420.0);
    let (left, right, top, bottom) = (80.0, 330.0, 40.0, 60.0);
    let all = || series.iter().flat_map(|s| s.points.iter());
    let xa = Axis::new(x_scale, all().map(|p| p.x));
    let ya = Axis::new(y_scale, all().flat_map(|p| [Some(p.y), p.y_hi]).flatten());
    let px = |x: f64| left + xa.frac(x) * (w - left - right);
    let py = |y: f64| h - bottom - ya.frac(y) * (h - top - bottom);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<rect width="{w}" height="{h}" fill="white"/>
<text x="{}" y="22" font-size="14" text-anchor="middle">{}</text>
"#,
        (w - right + left) / 2.0,
        esc(title)
    );
    let _ = writeln!(
        s,
        r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="#444"/>"##,
        w - left - right,
        h - top - bottom
    );
    for (v, label) in xa.ticks() {
        let x = px(v);
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{}" x2="{x}" y2="{top}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">{label}</text>"##,
            h - bottom,
            h - bottom + 16.0
        );
    }
    for (v, label) in ya.ticks() {
        let y = py(v);
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">{label}</text>"##,
            w - right,
            left - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (w - right + left) / 2.0,
        h - 18.0,
        esc(x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
        (h - bottom + top) / 2.0,
        (h - bottom + top) / 2.0,
        esc(y_label)
    );
    let ok = |v: f64, scale: Scale| v.is_finite() && (scale == Scale::Linear || v > 0.0);
    for (i, ser) in series.iter().enumerate() {
        let c = COLORS[i % COLORS.len()];
        let pts: Vec<&Pt> = ser
            .points
            .iter()
            .filter(|p| ok(p.x, x_scale) && p.y.is_finite())
            .collect();
        if ser.line && pts.len() > 1 {
            let line: Vec<String> = pts
                .iter()
                .map(|p| format!("{:.1},{:.1}", px(p.x), py(p.y)))
                .collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="{}"/>"#,
                line.join(" "),
                // The first series is drawn wide, so that series on top of it stay visible.
                if i == 0 { 5.0 } else { 1.5 }
            );
        }
        for p in pts {
            let (x, y) = (px(p.x), py(p.y));
            if let Some(hi) = p.y_hi.filter(|v| v.is_finite()) {
                let _ = writeln!(
                    s,
                    r#"<line x1="{x}" y1="{y}" x2="{x}" y2="{}" stroke="{c}" stroke-width="2"/>"#,
                    py(hi)
                );
            }
            let tip = p
                .note
                .as_deref()
                .map_or(String::new(), |n| format!("<title>{}</title>", esc(n)));
            let _ = writeln!(
                s,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="{}" fill="{c}">{tip}</circle>"#,
                if i == 0 { 6.0 } else { 3.5 }
            );
        }
        let ly = top + 16.0 + 18.0 * i as f64;
        let _ = writeln!(
            s,
            r#"<circle cx="{}" cy="{}" r="5" fill="{c}"/><text x="{}" y="{}">{}</text>"#,
            w - right + 16.0,
            ly - 4.0,
            w - right + 26.0,
            ly,
            esc(&ser.label)
        );
    }
    s += "</svg>\n";
    s
}
