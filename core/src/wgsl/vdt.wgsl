// steradian: visibility distance table query (mirrors `vdt::VdtView::query`): the visible
// fraction of the square with centre (u, v) and half-diagonal r (texel units), by eq. 9
// and by the straight-edge (gradient) variant, from one bilinear lookup of D.
// Input columns [u, v, r], output columns [eq9, gradient]; column c of n rows at c*n.
// Binding 3: the table [w, h, D(0, 0), D(1, 0), ...] (w and h as f32, D row-major), as
// `Vdt::gpu_table`. Specified for finite inputs only; see `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<f32>;

// sqrt(2) rounded to f32, as `core::f32::consts::SQRT_2`.
const SQRT_2: f32 = 1.4142135623730951;
// `vdt::R_MIN`, `vdt::R_MAX`, `vdt::Q_MIN`.
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

fn vdt_at(i: u32, j: u32, w: u32) -> f32 {
    return table[2u + j * w + i];
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = batch_row(gid);
    let n = params.n;
    if (row >= n) {
        return;
    }
    let u = input[row];
    let v = input[n + row];
    let r = input[2u * n + row];
    let w = u32(table[0]);
    let h = u32(table[1]);
    let ax = vdt_axis(u, w);
    let ay = vdt_axis(v, h);
    let i0 = u32(ax.x);
    let j0 = u32(ay.x);
    let i1 = min(i0 + 1u, w - 1u);
    let j1 = min(j0 + 1u, h - 1u);
    let fx = ax.y;
    let fy = ay.y;
    let d00 = vdt_at(i0, j0, w);
    let d10 = vdt_at(i1, j0, w);
    let d01 = vdt_at(i0, j1, w);
    let d11 = vdt_at(i1, j1, w);
    let d0 = vdt_lerp(d00, d10, fx);
    let d1 = vdt_lerp(d01, d11, fx);
    let d = vdt_lerp(d0, d1, fy);
    let gx = vdt_lerp(d10 - d00, d11 - d01, fy);
    let gy = vdt_lerp(d01 - d00, d11 - d10, fx);
    let rr = clamp(r, R_MIN, R_MAX);
    // Eq. 9.
    let k = SQRT_2 * rr;
    let e9 = clamp((k + d) / (2.0 * k), 0.0, 1.0);
    // Straight-edge fraction of the square cut by the line at D with normal along (gx, gy).
    let agx = abs(gx);
    let agy = abs(gy);
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
    output[row] = e9;
    output[n + row] = g;
}
