// steradian: visibility distance table query (`vdt::VdtView::query`), shared by the VDT-query
// and shade kernels (`wgsl/mod.rs` concatenates it into both). A kernel that includes it
// defines `fn vdt_table(at: u32) -> f32`, the table word `at` as f32; a w×h table's samples
// D(i, j) are row-major from word `base`. Eq. 9 reads the bilinear D (`vdt_cell`,
// `vdt_distance`, `vdt_eq9`); the straight-edge variant the zero-level-corrected
// least-squares plane through a 4×4 stencil (`vdt_line`, `vdt_edge`; `vdt_straight_edge`
// is both). Same operations in the same order as the scalar functions named at each
// (a driver may still reassociate or fuse them: `wgsl::VDT_QUERY_TOL`). Specified for
// finite inputs only.

// sqrt(2) rounded to f32, as `core::f32::consts::SQRT_2`.
const SQRT_2: f32 = 1.4142135623730951;
// `vdt::R_MIN`, `vdt::R_MAX`, `grid::Q_MIN`.
const R_MIN: f32 = 1e-12;
const R_MAX: f32 = 1.2089258196146292e24;
const Q_MIN: f32 = 1e-20;
// `vdt::FIT_WIDE_R`, `vdt::FIT_KAPPA`; 1/sqrt(2) rounded to f32 (`FRAC_1_SQRT_2`, named
// apart from shade_lib.wgsl's copy, which follows this file in the shade kernel).
const VDT_FIT_WIDE_R: f32 = 4.5;
const VDT_FIT_KAPPA: f32 = 1.6;
const VDT_FRAC_1_SQRT_2: f32 = 0.7071067811865476;

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

// (a.x + a.y) + (a.z + a.w) (`vdt::sum4`).
fn vdt_sum4(a: vec4<f32>) -> f32 {
    return (a.x + a.y) + (a.z + a.w);
}

// One axis of the straight-edge stencil (`vdt::stencil_axis`): the four centre indices
// (exact integers as f32, clamped to [0, len - 1]) at offsets -1, 0, +1, +2 from the cell
// index of `vdt_axis` (-3, -1, +2, +4 when `wide`), and their centres relative to x
// clamped to [0, len]. Clamped in float, so the indices convert to u32 exactly.
struct VdtStencilAxis {
    idx: vec4<f32>,
    pos: vec4<f32>,
}

fn vdt_stencil_axis(x: f32, len: u32, wide: bool) -> VdtStencilAxis {
    let xc = clamp(x, 0.0, f32(len));
    let i0 = vdt_axis(xc, len).x;
    let outer = select(1.0, 3.0, wide);
    let inner = select(0.0, 1.0, wide);
    let last = vec4<f32>(f32(len - 1u));
    let idx = clamp(
        vec4<f32>(i0 - outer, i0 - inner, i0 + 1.0 + inner, i0 + 1.0 + outer),
        vec4<f32>(0.0),
        last,
    );
    return VdtStencilAxis(idx, idx + 0.5 - xc);
}

// The sample positions of one stencil axis: mean, deviations from it, sum of squares
// (`vdt::fit_axis`).
struct VdtFitAxis {
    mean: f32,
    dev: vec4<f32>,
    ss: f32,
}

fn vdt_fit_axis(p: vec4<f32>) -> VdtFitAxis {
    let mean = vdt_sum4(p) * 0.25;
    let dev = p - mean;
    return VdtFitAxis(mean, dev, vdt_sum4(dev * dev));
}

// The 16 samples of a stencil, row b (along v) in `rb`, column a in component a.
struct VdtStencil {
    r0: vec4<f32>,
    r1: vec4<f32>,
    r2: vec4<f32>,
    r3: vec4<f32>,
}

// The least-squares plane through the stencil over the tensor grid ax × ay (`vdt::plane`):
// (value at the query point, slope along u, slope along v); a slope is 0 along an axis
// whose positions all coincide.
fn vdt_plane(s: VdtStencil, ax: VdtFitAxis, ay: VdtFitAxis) -> vec3<f32> {
    let col = ((s.r0 + s.r1) + (s.r2 + s.r3)) * 0.25;
    let row = vec4<f32>(vdt_sum4(s.r0), vdt_sum4(s.r1), vdt_sum4(s.r2), vdt_sum4(s.r3)) * 0.25;
    let mean = vdt_sum4(col) * 0.25;
    let sx = vdt_sum4(ax.dev * (col - mean));
    let sy = vdt_sum4(ay.dev * (row - mean));
    let gx = select(0.0, sx / ax.ss, ax.ss > 0.0);
    let gy = select(0.0, sy / ay.ss, ay.ss > 0.0);
    return vec3<f32>(mean - gx * ax.mean - gy * ay.mean, gx, gy);
}

// One stencil row with its zero level corrected (`vdt::zero_level_corrected`): D + sign(D)·c,
// c = k.x where |D| < 0.6, k.y where |D| < 1.1, k.z beyond.
fn vdt_zero_level_row(d: vec4<f32>, k: vec3<f32>) -> vec4<f32> {
    let a = abs(d);
    let c_mid = select(vec4<f32>(k.z), vec4<f32>(k.y), a < vec4<f32>(1.1));
    let c = select(c_mid, vec4<f32>(k.x), a < vec4<f32>(0.6));
    return select(d + c, d - c, d < vec4<f32>(0.0));
}

// The stencil with its zero level corrected for the staircase, for the gradient g of the
// plane through the raw samples (`vdt::zero_level_corrected`).
fn vdt_zero_level(s: VdtStencil, g: vec2<f32>) -> VdtStencil {
    let agx = abs(g.x);
    let agy = abs(g.y);
    let hi = max(agx, agy);
    let q = select(0.0, min(agx, agy) / hi, hi > 0.0);
    let m = 1.0 / sqrt(1.0 + q * q);
    let p = q * m;
    let k = vec3<f32>(
        0.5 * m - 0.5,
        m + 0.5 * p - VDT_FRAC_1_SQRT_2,
        VDT_FIT_KAPPA * p * (1.0 - p),
    );
    return VdtStencil(
        vdt_zero_level_row(s.r0, k),
        vdt_zero_level_row(s.r1, k),
        vdt_zero_level_row(s.r2, k),
        vdt_zero_level_row(s.r3, k),
    );
}

// One stencil row: the samples at row index j, column indices ix.
fn vdt_stencil_row(base: u32, w: u32, j: f32, ix: vec4<u32>) -> vec4<f32> {
    let at = base + u32(j) * w;
    return vec4<f32>(
        vdt_table(at + ix.x),
        vdt_table(at + ix.y),
        vdt_table(at + ix.z),
        vdt_table(at + ix.w),
    );
}

// The straight edge for the square at (u, v) of half-diagonal r, which picks the stencil
// (`vdt::VdtView::line`): the corrected plane's (value at (u, v), gx, gy).
fn vdt_line(base: u32, w: u32, h: u32, u: f32, v: f32, r: f32) -> vec3<f32> {
    let wide = r >= VDT_FIT_WIDE_R;
    let sx = vdt_stencil_axis(u, w, wide);
    let sy = vdt_stencil_axis(v, h, wide);
    let ix = vec4<u32>(sx.idx);
    let s = VdtStencil(
        vdt_stencil_row(base, w, sy.idx.x, ix),
        vdt_stencil_row(base, w, sy.idx.y, ix),
        vdt_stencil_row(base, w, sy.idx.z, ix),
        vdt_stencil_row(base, w, sy.idx.w, ix),
    );
    let ax = vdt_fit_axis(sx.pos);
    let ay = vdt_fit_axis(sy.pos);
    let raw = vdt_plane(s, ax, ay);
    return vdt_plane(vdt_zero_level(s, raw.yz), ax, ay);
}

// Eq. 9: the visible fraction 1/2 + d/(sqrt(2) r) of the square of half-diagonal r cut by
// a straight edge at distance d parallel to a side (`rsl::vdt::eq9_from`).
fn vdt_eq9(d: f32, r: f32) -> f32 {
    let k = SQRT_2 * clamp(r, R_MIN, R_MAX);
    return clamp((0.5 * k + d) / k, 0.0, 1.0);
}

// Straight-edge fraction of the square cut by the line at signed distance d with normal
// along grad (`vdt::gradient_from`, `grid::square_halfplane_fraction`).
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

// The straight-edge variant (`vdt::VdtView::gradient`): the fraction of the square on the
// visible side of `vdt_line`.
fn vdt_straight_edge(base: u32, w: u32, h: u32, u: f32, v: f32, r: f32) -> f32 {
    let line = vdt_line(base, w, h, u, v, r);
    return vdt_edge(line.x, line.yz, r);
}
