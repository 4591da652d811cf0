// steradian: RSL shading of one point per invocation (mirrors `shade::shade` with an
// isotropic BRDF SAT and one VDT per point; see `wgsl::SHADE` for the layout).
// Input columns [tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz, vdt_index], output
// [r, g, b]. Specified for finite inputs only; see `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<u32>;

const SQRT_2: f32 = 1.4142135623730951;
const FRAC_1_SQRT_2: f32 = 0.7071067811865476;
const R_MIN: f32 = 1e-12;
const R_MAX: f32 = 1.2089258196146292e24;
const Q_MIN: f32 = 1e-20;

// Header words.
const H_LIGHTS: u32 = 0u;
const H_GRID: u32 = 1u;
const H_POLAR: u32 = 2u;
const H_SMAX: u32 = 3u;
const H_VDT_N: u32 = 4u;
const H_OFF_LIGHTS: u32 = 5u;
const H_OFF_BRDF: u32 = 6u;
const H_OFF_VDT: u32 = 7u;
const H_QUERY: u32 = 8u;

fn tf(i: u32) -> f32 {
    return bitcast<f32>(table[i]);
}

// ---- summed-area tables (as `wgsl::SAT_BOX`, with a table base offset) ----

fn sat_entry(base: u32, at: u32) -> vec2<u32> {
    return vec2<u32>(table[base + 2u * at], table[base + 2u * at + 1u]);
}

fn sub64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let borrow = select(0u, 1u, a.x < b.x);
    return vec2<u32>(a.x - b.x, a.y - b.y - borrow);
}

fn i64_to_f32(a: vec2<u32>) -> f32 {
    let neg = (a.y & 0x80000000u) != 0u;
    var m = a;
    if (neg) {
        m = sub64(vec2<u32>(0u, 0u), a);
    }
    let v = f32(m.y) * 4294967296.0 + f32(m.x);
    return select(v, -v, neg);
}

struct Axis {
    i0: u32,
    a0: f32,
    i1: u32,
    a1: f32,
}

fn sat_axis(c0: f32, c1: f32, n: u32) -> Axis {
    let nf = f32(n);
    let lo = clamp(min(c0, c1), 0.0, nf);
    let hi = clamp(max(c0, c1), 0.0, nf);
    let last = f32(n - 1u);
    let i0 = min(floor(lo), last);
    let i1 = min(floor(hi), last);
    return Axis(u32(i0), lo - i0, u32(i1), hi - i1);
}

fn sat_row(base: u32, l: u32, w1: u32, i0: u32, i1: u32) -> array<vec2<u32>, 4> {
    let b = l * w1;
    return array<vec2<u32>, 4>(
        sat_entry(base, b + i0),
        sat_entry(base, b + i0 + 1u),
        sat_entry(base, b + i1),
        sat_entry(base, b + i1 + 1u),
    );
}

fn sat_x(l: array<vec2<u32>, 4>, m: array<vec2<u32>, 4>, a0: f32, a1: f32) -> f32 {
    let p = sub64(sub64(m[2], m[0]), sub64(l[2], l[0]));
    let e1 = sub64(sub64(m[3], m[2]), sub64(l[3], l[2]));
    let e0 = sub64(sub64(m[1], m[0]), sub64(l[1], l[0]));
    return (i64_to_f32(p) + a1 * i64_to_f32(e1)) - a0 * i64_to_f32(e0);
}

// Box sum of table `k` (its exponent word, then its entries) over precomputed axes.
fn sat_box(k: u32, w: u32, ax: Axis, ay: Axis) -> f32 {
    let w1 = w + 1u;
    let stride = 1u + 2u * w1 * w1;
    let t0 = table[H_OFF_BRDF] + k * stride;
    let e = bitcast<i32>(table[t0]);
    let base = t0 + 1u;
    let r0 = sat_row(base, ay.i0, w1, ax.i0, ax.i1);
    let r0p = sat_row(base, ay.i0 + 1u, w1, ax.i0, ax.i1);
    let r1 = sat_row(base, ay.i1, w1, ax.i0, ax.i1);
    let r1p = sat_row(base, ay.i1 + 1u, w1, ax.i0, ax.i1);
    let q = (sat_x(r0, r1, ax.a0, ax.a1) + ay.a1 * sat_x(r1, r1p, ax.a0, ax.a1))
        - ay.a0 * sat_x(r0, r0p, ax.a0, ax.a1);
    let e_half = e / 2;
    return ldexp(ldexp(q, e_half), e - e_half);
}

// ---- visibility distance table (as `wgsl::VDT_QUERY`) ----

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

fn vdt_fraction(base: u32, n: u32, u: f32, v: f32, r: f32, gradient: bool) -> f32 {
    let ax = vdt_axis(u, n);
    let ay = vdt_axis(v, n);
    let i0 = u32(ax.x);
    let j0 = u32(ay.x);
    let i1 = min(i0 + 1u, n - 1u);
    let j1 = min(j0 + 1u, n - 1u);
    let d00 = tf(base + j0 * n + i0);
    let d10 = tf(base + j0 * n + i1);
    let d01 = tf(base + j1 * n + i0);
    let d11 = tf(base + j1 * n + i1);
    let d = vdt_lerp(vdt_lerp(d00, d10, ax.y), vdt_lerp(d01, d11, ax.y), ay.y);
    let rr = clamp(r, R_MIN, R_MAX);
    if (!gradient) {
        let k = SQRT_2 * rr;
        return clamp((k + d) / (2.0 * k), 0.0, 1.0);
    }
    let agx = abs(vdt_lerp(d10 - d00, d11 - d01, ay.y));
    let agy = abs(vdt_lerp(d01 - d00, d11 - d10, ax.y));
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

// Extended equal-area map of a unit direction (`rsl::map_extended`).
fn map_ext(d: vec3<f32>) -> vec2<f32> {
    if (d.z >= 0.0) {
        return d.xy / sqrt(1.0 + d.z);
    }
    let s2 = d.x * d.x + d.y * d.y;
    if (s2 > 0.0) {
        return d.xy * (sqrt(1.0 - d.z) / sqrt(s2));
    }
    return vec2<f32>(SQRT_2, 0.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = batch_row(gid);
    let n = params.n;
    if (row >= n) {
        return;
    }
    let t = vec3<f32>(input[row], input[n + row], input[2u * n + row]);
    let b = vec3<f32>(input[3u * n + row], input[4u * n + row], input[5u * n + row]);
    let nn = vec3<f32>(input[6u * n + row], input[7u * n + row], input[8u * n + row]);
    let wo = vec3<f32>(input[9u * n + row], input[10u * n + row], input[11u * n + row]);
    let point = u32(input[12u * n + row]);
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    let wl = vec3<f32>(dot(wo, t), dot(wo, b), dot(wo, nn));
    if (wl.z > 0.0) {
        // View constants of the isotropic BRDF SAT (`BrdfSat::integral`).
        let wn = wl / length(wl);
        let pv = wn.xy / sqrt(1.0 + wn.z);
        let s = sqrt(pv.x * pv.x + pv.y * pv.y);
        let m = table[H_POLAR];
        let x = clamp(s / tf(H_SMAX) * f32(m - 1u), 0.0, f32(m - 1u));
        let k0 = min(u32(x), m - 2u);
        let tw = x - f32(k0);
        var rc = 1.0;
        var rs = 0.0;
        if (s > 0.0) {
            rc = pv.x / s;
            rs = pv.y / s;
        }
        let grid = table[H_GRID];
        let half_b = 0.5 * f32(grid);
        let vn = table[H_VDT_N];
        let half_v = 0.5 * f32(vn);
        let vbase = table[H_OFF_VDT] + point * vn * vn;
        let gradient = table[H_QUERY] != 0u;
        let nl = table[H_LIGHTS];
        let lo = table[H_OFF_LIGHTS];
        for (var i = 0u; i < nl; i = i + 1u) {
            let o = lo + 8u * i;
            let c = vec3<f32>(tf(o), tf(o + 1u), tf(o + 2u));
            let r = tf(o + 3u);
            let cl = vec3<f32>(dot(c, t), dot(c, b), dot(c, nn));
            let p = map_ext(cl / length(cl));
            if (length(p) - r >= 1.0) {
                continue;
            }
            let q = vec2<f32>(p.x * rc + p.y * rs, p.y * rc - p.x * rs);
            let tc = (q + vec2<f32>(1.0, 1.0)) * half_b;
            let h = r * half_b * FRAC_1_SQRT_2;
            let ax = sat_axis(tc.x - h, tc.x + h, grid);
            let ay = sat_axis(tc.y - h, tc.y + h, grid);
            let v0 = sat_box(k0, grid, ax, ay);
            let v1 = sat_box(k0 + 1u, grid, ax, ay);
            let rho = (v0 + tw * (v1 - v0)) * tf(o + 4u);
            let tv = (p + vec2<f32>(1.0, 1.0)) * half_v;
            let vis = vdt_fraction(vbase, vn, tv.x, tv.y, r * half_v, gradient);
            let f = rho * vis;
            acc = acc + vec3<f32>(tf(o + 5u), tf(o + 6u), tf(o + 7u)) * f;
        }
    }
    output[row] = acc.x;
    output[n + row] = acc.y;
    output[2u * n + row] = acc.z;
}
