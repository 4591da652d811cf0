//! A small log-log scatter plot in SVG for the report sections: one labelled point per
//! configuration, with an optional bar up to a second value (e.g. mean to max).

use std::fmt::Write as _;

/// One point of a [`log_log`] plot.
#[derive(Clone, Debug)]
pub struct Point {
    /// Label drawn beside the point.
    pub label: String,
    /// x (> 0).
    pub x: f64,
    /// y (> 0; smaller values are drawn on the floor).
    pub y: f64,
    /// Optional upper end of a vertical bar from `y`.
    pub y_hi: Option<f64>,
}

const COLORS: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
];

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A complete SVG document: log axes with decade ticks, one colour per point, a legend.
pub fn log_log(title: &str, x_label: &str, y_label: &str, points: &[Point]) -> String {
    const FLOOR: f64 = 1e-12;
    let (w, h) = (720.0, 420.0);
    let (left, right, top, bottom) = (80.0, 250.0, 40.0, 60.0);
    let finite = |v: f64| v.is_finite() && v > 0.0;
    let xs: Vec<f64> = points.iter().map(|p| p.x).filter(|&v| finite(v)).collect();
    let ys: Vec<f64> = points
        .iter()
        .flat_map(|p| [Some(p.y), p.y_hi])
        .flatten()
        .map(|v| v.max(FLOOR))
        .filter(|&v| finite(v))
        .collect();
    let span = |v: &[f64]| {
        let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi.is_finite() {
            (
                (lo.log10()).floor(),
                (hi.log10()).ceil().max(lo.log10().floor() + 1.0),
            )
        } else {
            (0.0, 1.0)
        }
    };
    let (x0, x1) = span(&xs);
    let (y0, y1) = span(&ys);
    let px = |x: f64| left + (x.log10() - x0) / (x1 - x0) * (w - left - right);
    let py = |y: f64| h - bottom - (y.max(FLOOR).log10() - y0) / (y1 - y0) * (h - top - bottom);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<rect width="{w}" height="{h}" fill="white"/>
<text x="{}" y="22" font-size="14" text-anchor="middle">{}</text>
"#,
        (w - right + left) / 2.0,
        esc(title)
    );
    // Axes and decade ticks.
    let _ = writeln!(
        s,
        r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="#444"/>"##,
        w - left - right,
        h - top - bottom
    );
    let mut d = x0;
    while d <= x1 + 1e-9 {
        let x = px(10f64.powf(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x}" y1="{}" x2="{x}" y2="{top}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">1e{d}</text>"##,
            h - bottom,
            h - bottom + 16.0
        );
        d += 1.0;
    }
    let mut d = y0;
    while d <= y1 + 1e-9 {
        let y = py(10f64.powf(d));
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">1e{d}</text>"##,
            w - right,
            left - 6.0,
            y + 4.0
        );
        d += 1.0;
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
    for (i, p) in points.iter().enumerate() {
        if !finite(p.x) {
            continue;
        }
        let c = COLORS[i % COLORS.len()];
        let (x, y) = (px(p.x), py(p.y));
        if let Some(hi) = p.y_hi {
            let _ = writeln!(
                s,
                r#"<line x1="{x}" y1="{y}" x2="{x}" y2="{}" stroke="{c}" stroke-width="2"/>"#,
                py(hi)
            );
        }
        let _ = writeln!(s, r#"<circle cx="{x}" cy="{y}" r="5" fill="{c}"/>"#);
        let ly = top + 16.0 + 18.0 * i as f64;
        let _ = writeln!(
            s,
            r#"<circle cx="{}" cy="{}" r="5" fill="{c}"/><text x="{}" y="{}">{}</text>"#,
            w - right + 16.0,
            ly - 4.0,
            w - right + 26.0,
            ly,
            esc(&p.label)
        );
    }
    s += "</svg>\n";
    s
}
