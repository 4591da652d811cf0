//! The speed-against-error plot: one panel per kernel, a point per backend, log axes.

use super::Report;

const BACKENDS: [(&str, &str); 4] = [
    ("cpu-scalar", "#1f77b4"),
    ("cpu-scalar-loop", "#ff7f0e"),
    ("cpu-simd", "#2ca02c"),
    ("wgpu", "#d62728"),
];

/// Errors below this are drawn on the floor of the plot (an exact kernel).
const FLOOR: f64 = 1e-12;

fn color(backend: &str) -> &'static str {
    BACKENDS
        .iter()
        .find(|(b, _)| *b == backend)
        .map_or("#555", |(_, c)| c)
}

/// An SVG with one panel per kernel: x = evaluations per second (log), y = max error (log).
pub fn speed_vs_error(r: &Report) -> String {
    let mut kernels: Vec<&str> = Vec::new();
    for row in &r.results {
        if !kernels.contains(&row.kernel) {
            kernels.push(row.kernel);
        }
    }
    let (pw, ph, cols) = (300.0, 220.0, 3usize);
    let rows = kernels.len().div_ceil(cols).max(1);
    let (w, h) = (pw * cols as f64, ph * rows as f64 + 40.0);
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="11">
<rect width="100%" height="100%" fill="white"/>
"#
    );
    for (i, (b, c)) in BACKENDS.iter().enumerate() {
        let x = 10.0 + i as f64 * 150.0;
        s += &format!(
            r#"<circle cx="{}" cy="{}" r="5" fill="{c}"/><text x="{}" y="{}">{b}</text>
"#,
            x + 5.0,
            h - 15.0,
            x + 14.0,
            h - 11.0
        );
    }
    for (ki, k) in kernels.iter().enumerate() {
        let ox = (ki % cols) as f64 * pw;
        let oy = (ki / cols) as f64 * ph;
        let pts: Vec<_> = r.results.iter().filter(|row| row.kernel == *k).collect();
        let xs: Vec<f64> = pts.iter().map(|p| p.evals_per_s.max(1.0).log10()).collect();
        let ys: Vec<f64> = pts
            .iter()
            .map(|p| {
                let e = if p.error.max.is_finite() {
                    p.error.max
                } else {
                    1.0
                };
                e.max(FLOOR).log10()
            })
            .chain(std::iter::once(
                pts.first().map_or(0.0, |p| p.bound.max(FLOOR).log10()),
            ))
            .collect();
        let (x0, x1) = (
            xs.iter().copied().fold(f64::INFINITY, f64::min).floor(),
            xs.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil(),
        );
        let (y0, y1) = (
            ys.iter().copied().fold(f64::INFINITY, f64::min).floor(),
            ys.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil() + 1.0,
        );
        let (x1, y1) = (x1.max(x0 + 1.0), y1.max(y0 + 1.0));
        let (l, t, pw2, ph2) = (ox + 50.0, oy + 25.0, pw - 70.0, ph - 65.0);
        let px = |x: f64| l + (x - x0) / (x1 - x0) * pw2;
        let py = |y: f64| t + (y1 - y) / (y1 - y0) * ph2;
        s += &format!(
            r##"<text x="{}" y="{}" font-weight="bold">{k}</text>
<rect x="{l}" y="{t}" width="{pw2}" height="{ph2}" fill="none" stroke="#999"/>
"##,
            l,
            oy + 16.0
        );
        let mut x = x0;
        while x <= x1 + 1e-9 {
            s += &format!(
                r##"<text x="{}" y="{}" text-anchor="middle" fill="#555">1e{}</text>
"##,
                px(x),
                t + ph2 + 13.0,
                x as i32
            );
            x += 1.0;
        }
        let step = ((y1 - y0) / 5.0).ceil().max(1.0);
        let mut y = y0;
        while y <= y1 + 1e-9 {
            s += &format!(
                r##"<text x="{}" y="{}" text-anchor="end" fill="#555">1e{}</text>
"##,
                l - 3.0,
                py(y) + 4.0,
                y as i32
            );
            y += step;
        }
        s += &format!(
            r##"<text x="{}" y="{}" text-anchor="middle" fill="#555">evals/s</text>
<text transform="translate({},{}) rotate(-90)" text-anchor="middle" fill="#555">max error</text>
"##,
            l + pw2 / 2.0,
            t + ph2 + 27.0,
            ox + 10.0,
            t + ph2 / 2.0
        );
        if let Some(p) = pts.first() {
            let by = py(p.bound.max(FLOOR).log10());
            s += &format!(
                r##"<line x1="{l}" x2="{}" y1="{by}" y2="{by}" stroke="#b00" stroke-dasharray="4 3"/><text x="{}" y="{}" fill="#b00" text-anchor="end">bound ({})</text>
"##,
                l + pw2,
                l + pw2 - 2.0,
                by - 3.0,
                p.error.metric
            );
        }
        for (p, (x, y)) in pts.iter().zip(xs.iter().zip(&ys)) {
            s += &format!(
                r#"<circle cx="{:.1}" cy="{:.1}" r="5" fill="{}" fill-opacity="0.8"><title>{} {}: {:.3e} evals/s, max error {:.3e}</title></circle>
"#,
                px(*x),
                py(*y),
                color(p.backend),
                p.kernel,
                p.backend,
                p.evals_per_s,
                p.error.max
            );
        }
    }
    s + "</svg>\n"
}
