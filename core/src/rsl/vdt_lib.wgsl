// steradian: visibility distance table query (`vdt::VdtView::query`), shared by the VDT-query
// and shade kernels (`wgsl.rs` concatenates it into both). A kernel that includes it defines
// `fn vdt_table(at: u32) -> f32`, the table word `at` as f32; a w×h table's samples
// D(i, j) are row-major from word `base`.

// sqrt(2) rounded to f32, as `core::f32::consts::SQRT_2`.
const SQRT_2: f32 = 1.4142135623730951;
// `vdt::R_MIN`, `vdt::R_MAX`, `grid::Q_MIN`.
const R_MIN: f32 = 1e-12;
const R_MAX: f32 = 1.2089258196146292e24;
const Q_MIN: f32 = 1e-20;

// Cell index (exact integer as f32) and fraction along one axis of `len` centres.
fn vdt_axis(x: f32, len: u32) -> vec2<f32> {
    let c = x - 0.5;
    var hi_index = 0.0;
    var hi_frac = 0.0;
    if (len >= 2u) {
        hi_index = f32(len - 2u);
        hi_frac = 1.0;
    }
    let i0 = clamp(floor(c), 0.0, hi_index);
    let f = clamp(c - i0, 0.0, hi_frac);
    return vec2<f32>(i0, f);
}

fn vdt_lerp(a: f32, b: f32, t: f32) -> f32 {
    return (1.0 - t) * a + t * b;
}

// The bilinear cell of the point (u, v) (texel units): its four samples and the fractions.
struct VdtCell {
    d00: f32,
    d10: f32,
    d01: f32,
    d11: f32,
    fx: f32,
    fy: f32,
}

fn vdt_cell(base: u32, w: u32, h: u32, u: f32, v: f32) -> VdtCell {
    let ax = vdt_axis(u, w);
    let ay = vdt_axis(v, h);
    let i0 = u32(ax.x);
    let j0 = u32(ay.x);
    let i1 = min(i0 + 1u, w - 1u);
    let j1 = min(j0 + 1u, h - 1u);
    return VdtCell(
        vdt_table(base + j0 * w + i0),
        vdt_table(base + j0 * w + i1),
        vdt_table(base + j1 * w + i0),
        vdt_table(base + j1 * w + i1),
        ax.y,
        ay.y,
    );
}

// The bilinear distance D at the point.
fn vdt_distance(c: VdtCell) -> f32 {
    return vdt_lerp(vdt_lerp(c.d00, c.d10, c.fx), vdt_lerp(c.d01, c.d11, c.fx), c.fy);
}

// The in-cell gradient (gx, gy) of D.
fn vdt_gradient(c: VdtCell) -> vec2<f32> {
    return vec2<f32>(
        vdt_lerp(c.d10 - c.d00, c.d11 - c.d01, c.fy),
        vdt_lerp(c.d01 - c.d00, c.d11 - c.d10, c.fx),
    );
}

// Eq. 9: the visible fraction 1/2 + d/(sqrt(2) r) of the square of half-diagonal r cut by
// a straight edge at distance d parallel to a side (`rsl::vdt::eq9_from`).
fn vdt_eq9(d: f32, r: f32) -> f32 {
    let k = SQRT_2 * clamp(r, R_MIN, R_MAX);
    return clamp((0.5 * k + d) / k, 0.0, 1.0);
}

// Straight-edge fraction of the square cut by the line at D with normal along the gradient.
fn vdt_edge(d: f32, grad: vec2<f32>, r: f32) -> f32 {
    let rr = clamp(r, R_MIN, R_MAX);
    let agx = abs(grad.x);
    let agy = abs(grad.y);
    let m = max(agx, agy);
    var q = 0.0;
    if (m > 0.0) {
        q = min(agx, agy) / m;
    }
    let t = d * SQRT_2 / rr;
    let len = sqrt(1.0 + q * q);
    let hi = 1.0 + q;
    let tt = clamp(t * len, -hi, hi);
    let den = 8.0 * max(q, Q_MIN);
    var g = (tt + 1.0) * 0.5;
    if (tt <= q - 1.0) {
        let e = tt + hi;
        g = e * e / den;
    } else if (tt >= 1.0 - q) {
        let e = hi - tt;
        g = 1.0 - e * e / den;
    }
    return g;
}
