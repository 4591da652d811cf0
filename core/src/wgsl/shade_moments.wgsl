// steradian: RSL shading with visibility moments, one point per invocation (mirrors
// `shade::shade_moments` with an isotropic BRDF SAT and one `VisMoments` per point; see
// `wgsl::SHADE_MOMENTS` for the layout). Input columns [tx, ty, tz, bx, by, bz, nx, ny, nz,
// wox, woy, woz, point_index], output [r, g, b]. Specified for finite inputs only; see
// `steradian_core::wgsl`. The BRDF box sums are those of sat_lib.wgsl (concatenated before
// this file by `wgsl.rs`); the visibility moments read the three exact integer tables of
// the point directly (`vis_moments::VisMoments::moments`).

@group(0) @binding(3) var<storage, read> table: array<u32>;

const FRAC_1_SQRT_2: f32 = 0.7071067811865476;
const SQRT_2: f32 = 1.4142135623730951;
// 2^61: above it a product s * (V >> k) might not fit the 64-bit difference.
const TWO_POW_61: f32 = 2305843009213693952.0;

// Header words.
const H_LIGHTS: u32 = 0u;
const H_GRID: u32 = 1u;
const H_POLAR: u32 = 2u;
const H_SMAX: u32 = 3u;
const H_VIS_N: u32 = 4u;
const H_OFF_LIGHTS: u32 = 5u;
const H_OFF_BRDF: u32 = 6u;
const H_OFF_VIS: u32 = 7u;
// Words per light: centre, r, 1/Ω, E (RGB), gradient (3 × RGB).
const LIGHT_WORDS: u32 = 17u;

fn tf(i: u32) -> f32 {
    return bitcast<f32>(table[i]);
}

fn tv3(i: u32) -> vec3<f32> {
    return vec3<f32>(tf(i), tf(i + 1u), tf(i + 2u));
}

// x * 2^e in two steps: WGSL's ldexp needs its exponent within [-126, 127].
fn scale2(x: f32, e: i32) -> f32 {
    let e_half = e / 2;
    return ldexp(ldexp(x, e_half), e - e_half);
}

// ---- 64-bit integers as (low, high) u32 pairs (sub64, i64_to_f32: sat_lib.wgsl) ----

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    let carry = select(0u, 1u, lo < a.x);
    return vec2<u32>(lo, a.y + b.y + carry);
}

// The full 64-bit product of two u32, from 16-bit halves.
fn mul32(a: u32, b: u32) -> vec2<u32> {
    let al = a & 0xffffu;
    let ah = a >> 16u;
    let bl = b & 0xffffu;
    let bh = b >> 16u;
    let ll = al * bl;
    let lh = al * bh;
    let hl = ah * bl;
    let mid = (ll >> 16u) + (lh & 0xffffu) + (hl & 0xffffu);
    let lo = (ll & 0xffffu) | (mid << 16u);
    let hi = ah * bh + (lh >> 16u) + (hl >> 16u) + (mid >> 16u);
    return vec2<u32>(lo, hi);
}

// a * m modulo 2^64.
fn mul64_32(a: vec2<u32>, m: u32) -> vec2<u32> {
    let p = mul32(a.x, m);
    return vec2<u32>(p.x, p.y + a.y * m);
}

// Logical a >> k, 0 <= k < 64 (WGSL shifts take their amount modulo 32).
fn shr64(a: vec2<u32>, k: u32) -> vec2<u32> {
    if (k == 0u) {
        return a;
    }
    if (k < 32u) {
        return vec2<u32>((a.x >> k) | (a.y << (32u - k)), a.y >> k);
    }
    return vec2<u32>(a.y >> (k - 32u), 0u);
}

// a << k modulo 2^64, 0 <= k < 64.
fn shl64(a: vec2<u32>, k: u32) -> vec2<u32> {
    if (k == 0u) {
        return a;
    }
    if (k < 32u) {
        return vec2<u32>(a.x << k, (a.y << k) | (a.x >> (32u - k)));
    }
    return vec2<u32>(0u, a.x << (k - 32u));
}

// ---- BRDF SAT: integral and plane-fit gradient (`BrdfSat::integral_gradient`) ----

// Box sum of BRDF table `k` (its exponent word, then its entries) over precomputed axes.
fn brdf_box(k: u32, w: u32, ax: Axis, ay: Axis) -> f32 {
    let w1 = w + 1u;
    let stride = 1u + 2u * w1 * w1;
    let t0 = table[H_OFF_BRDF] + k * stride;
    return sat_box_sum(t0 + 1u, bitcast<i32>(table[t0]), w, ax, ay);
}

// [whole, right - left, top - bottom] of BRDF table `k` around `tc` with half-side `h`
// (texel units): the whole square, then twice its right (top) half minus the whole.
fn brdf_parts(k: u32, w: u32, tc: vec2<f32>, h: f32) -> vec3<f32> {
    let ax = sat_axis(tc.x - h, tc.x + h, w);
    let ay = sat_axis(tc.y - h, tc.y + h, w);
    let whole = brdf_box(k, w, ax, ay);
    let right = brdf_box(k, w, sat_axis(tc.x, tc.x + h, w), ay);
    let top = brdf_box(k, w, ax, sat_axis(tc.y, tc.y + h, w));
    return vec3<f32>(whole, 2.0 * right - whole, 2.0 * top - whole);
}

// ---- Visibility moments (`VisMoments::moments`) ----

// One axis of the query in the map's texel units, relative to the integer origin `o`
// near the centre (the centre is o + fc): relative coordinates keep the square's edges to
// the precision of its size rather than of the table's.
struct VisAxis {
    o: f32,
    fc: f32,
    lo: f32,
    hi: f32,
}

// Centre coordinate `pc` (disk units) with half-side `h` (texels) on an n-texel axis: the
// extent clipped to the table, [lo, hi] relative to `o`.
fn vis_axis(pc: f32, hn: f32, h: f32, nf: f32) -> VisAxis {
    let pu = pc * hn;
    let fl = floor(pu);
    let o = fl + floor(hn);
    let fc = (pu - fl) + (hn - floor(hn));
    let lo = clamp(fc - h, -o, nf - o);
    let hi = clamp(fc + h, -o, nf - o);
    return VisAxis(o, fc, lo, hi);
}

// Texels [i0, i1): one partly covered texel (covered width w, covered centre `mid`
// relative to the origin) or a run of whole texels (w = 1).
struct Seg {
    i0: u32,
    i1: u32,
    partial: bool,
    w: f32,
    mid: f32,
}

struct Segs {
    s: array<Seg, 3>,
    n: u32,
}

// [lo, hi] (relative to the origin `o`, inside the table) as the partial first texel,
// the whole texels between and the partial last texel (`vis_moments::segments`).
fn segments(lo: f32, hi: f32, o: f32, n: u32) -> Segs {
    var out: Segs;
    out.n = 0u;
    if (!(hi > lo)) {
        return out;
    }
    let last = f32(n - 1u);
    let c0 = min(floor(lo) + o, last);
    let c1 = min(floor(hi) + o, last);
    let i0 = u32(c0);
    let i1 = u32(c1);
    if (c0 == c1) {
        out.s[0] = Seg(i0, i0 + 1u, true, hi - lo, 0.5 * (lo + hi));
        out.n = 1u;
        return out;
    }
    let e0 = (c0 + 1.0) - o;
    out.s[0] = Seg(i0, i0 + 1u, true, e0 - lo, 0.5 * (lo + e0));
    var k = 1u;
    if (c1 > c0 + 1.0) {
        out.s[k] = Seg(i0 + 1u, i1, false, 1.0, 0.0);
        k = k + 1u;
    }
    let e1 = c1 - o;
    if (hi > e1) {
        out.s[k] = Seg(i1, i1 + 1u, true, hi - e1, 0.5 * (e1 + hi));
        k = k + 1u;
    }
    out.n = k;
    return out;
}

// Exact integer box [i0, i1) x [j0, j1) of the table whose entries start at `base`.
fn ibox(base: u32, w1: u32, i0: u32, i1: u32, j0: u32, j1: u32) -> vec2<u32> {
    let r0 = j0 * w1;
    let r1 = j1 * w1;
    return sub64(
        sub64(sat_entry(base, r1 + i1), sat_entry(base, r1 + i0)),
        sub64(sat_entry(base, r0 + i1), sat_entry(base, r0 + i0)),
    );
}

// ∫(x − c)·V over a block whose extent along the moment's axis is a run of whole texels:
// M·2^me − (c − n/2)·B·2^ve with M, B the exact integer box sums of the moment and V
// tables (`bv` = B·2^ve in f32). M and (c − n/2)·B grow with the distance from the table's
// centre while their difference stays within a few half-sides of B, so with c − n/2 =
// s + frac (s an integer) the difference M − s·(B >> k) is formed exactly in 64-bit
// integers (k = me − ve, the quanta's ratio); only the remainder s·(B mod 2^k)·2^ve (below
// |s| quanta of V) and frac·bv are added in f32. Falls back to the plain f32 difference
// where that integer form could overflow (a moment table with a finer quantum than the V
// table's, or a huge s·B).
fn run_moment(
    mb: u32,
    me: i32,
    vi: vec2<u32>,
    ve: i32,
    bv: f32,
    s: i32,
    frac: f32,
    w1: u32,
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
) -> f32 {
    let mi = ibox(mb, w1, i0, i1, j0, j1);
    let k = me - ve;
    let sa = u32(abs(s));
    if (k >= 0 && k <= 62 && (vi.y & 0x80000000u) == 0u) {
        let vh = shr64(vi, u32(k));
        if (f32(sa) * i64_to_f32(vh) < TWO_POW_61) {
            let vl = sub64(vi, shl64(vh, u32(k)));
            let p = mul64_32(vh, sa);
            var d = add64(mi, p);
            if (s >= 0) {
                d = sub64(mi, p);
            }
            return (scale2(i64_to_f32(d), me) - f32(s) * scale2(i64_to_f32(vl), ve)) - frac * bv;
        }
    }
    return scale2(i64_to_f32(mi), me) - (f32(s) + frac) * bv;
}

// (f, m.x, m.y) of the square with centre `p` and half-side `hd` (disk units) from the
// three tables [V, XV, YV] of an n×n map starting at word `vb`, each `ts` words (its
// exponent, then its entries): `VisMoments::moments` with `inside`, outside the table
// visible.
fn vis_moments(vb: u32, n: u32, ts: u32, p: vec2<f32>, hd: f32) -> vec3<f32> {
    let hn = 0.5 * f32(n);
    let h = hd * hn;
    if (!(h > 0.0)) {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let nf = f32(n);
    let ax = vis_axis(p.x, hn, h, nf);
    let ay = vis_axis(p.y, hn, h, nf);
    let xs = segments(ax.lo, ax.hi, ax.o, n);
    let ys = segments(ay.lo, ay.hi, ay.o, n);
    let w1 = n + 1u;
    let ev = bitcast<i32>(table[vb]);
    let ex = bitcast<i32>(table[vb + ts]);
    let ey = bitcast<i32>(table[vb + 2u * ts]);
    let vbase = vb + 1u;
    let xbase = vb + ts + 1u;
    let ybase = vb + 2u * ts + 1u;
    // c − n/2 = s + frac per axis (s integer).
    let odd = hn - floor(hn);
    let sx_int = i32(ax.o) - i32(floor(hn));
    let sy_int = i32(ay.o) - i32(floor(hn));
    let fx = ax.fc - odd;
    let fy = ay.fc - odd;
    var s = 0.0;
    var mx = 0.0;
    var my = 0.0;
    for (var a = 0u; a < xs.n; a = a + 1u) {
        let sx = xs.s[a];
        for (var c = 0u; c < ys.n; c = c + 1u) {
            let sy = ys.s[c];
            let vi = ibox(vbase, w1, sx.i0, sx.i1, sy.i0, sy.i1);
            let bv = scale2(i64_to_f32(vi), ev);
            s = s + (sx.w * sy.w) * bv;
            var tx: f32;
            if (sx.partial) {
                tx = sx.w * bv * (sx.mid - ax.fc);
            } else {
                tx = run_moment(xbase, ex, vi, ev, bv, sx_int, fx, w1, sx.i0, sx.i1, sy.i0, sy.i1);
            }
            mx = mx + sy.w * tx;
            var ty: f32;
            if (sy.partial) {
                ty = sy.w * bv * (sy.mid - ay.fc);
            } else {
                ty = run_moment(ybase, ey, vi, ev, bv, sy_int, fy, w1, sx.i0, sx.i1, sy.i0, sy.i1);
            }
            my = my + sx.w * ty;
        }
    }
    let area = 4.0 * h * h;
    let area_in = (ax.hi - ax.lo) * (ay.hi - ay.lo);
    // Outside is visible: ∫_out (x − c) = −∫_in (x − c).
    let mx_out = -area_in * (0.5 * (ax.lo + ax.hi) - ax.fc);
    let my_out = -area_in * (0.5 * (ay.lo + ay.hi) - ay.fc);
    let f = clamp((s + (area - area_in)) / area, 0.0, 1.0);
    let to_disk = 1.0 / (area * hn);
    return vec3<f32>(f, (mx + mx_out) * to_disk, (my + my_out) * to_disk);
}

// ---- The kernel (`shade::light_moments`) ----

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

// x clamped to [0, hi] in the scalar kernel's order (`shade::clamp_keep_nan`).
fn clamp_to(x: f32, hi: f32) -> f32 {
    return select(select(x, hi, x > hi), 0.0, x < 0.0);
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
        // View constants of the isotropic BRDF SAT (`BrdfSat::locate`).
        let wn = wl / length(wl);
        let pv = wn.xy / sqrt(1.0 + wn.z);
        let sv = sqrt(pv.x * pv.x + pv.y * pv.y);
        let m = table[H_POLAR];
        let x = clamp(sv / tf(H_SMAX) * f32(m - 1u), 0.0, f32(m - 1u));
        let k0 = min(u32(x), m - 2u);
        let tw = x - f32(k0);
        var rc = 1.0;
        var rs = 0.0;
        if (sv > 0.0) {
            rc = pv.x / sv;
            rs = pv.y / sv;
        }
        let grid = table[H_GRID];
        let half_b = 0.5 * f32(grid);
        let vn = table[H_VIS_N];
        let ts = 1u + 2u * (vn + 1u) * (vn + 1u);
        let vbase = table[H_OFF_VIS] + point * 3u * ts;
        let nl = table[H_LIGHTS];
        let lo = table[H_OFF_LIGHTS];
        for (var i = 0u; i < nl; i = i + 1u) {
            let o = lo + LIGHT_WORDS * i;
            let c = tv3(o);
            let r = tf(o + 3u);
            let cl = vec3<f32>(dot(c, t), dot(c, b), dot(c, nn));
            let p = map_ext(cl / length(cl));
            if (length(p) - r >= 1.0) {
                continue;
            }
            let hd = r * FRAC_1_SQRT_2;
            // BRDF integral I and density gradient g (`BrdfSat::integral_gradient`).
            let q = vec2<f32>(p.x * rc + p.y * rs, p.y * rc - p.x * rs);
            let tc = (q + vec2<f32>(1.0, 1.0)) * half_b;
            let h = hd * half_b;
            let s0 = brdf_parts(k0, grid, tc, h);
            let s1 = brdf_parts(k0 + 1u, grid, tc, h);
            let sums = s0 + tw * (s1 - s0);
            let hdb = h / half_b;
            var g = vec2<f32>(0.0, 0.0);
            if (hdb > 0.0) {
                let kk = 1.0 / (2.0 * hdb * hdb * hdb);
                let gx = sums.y * kk;
                let gy = sums.z * kk;
                g = vec2<f32>(rc * gx - rs * gy, rs * gx + rc * gy);
            }
            let ii = sums.x;
            // Visible fraction f and first moment m.
            let fm = vis_moments(vbase, vn, ts, p, hd);
            let f = fm.x;
            let mm = fm.yz;
            let area = 2.0 * r * r;
            let joint = clamp_to(ii * f + area * dot(g, mm), ii) * tf(o + 4u);
            var out = tv3(o + 5u) * joint;
            let g_r = tv3(o + 8u);
            let g_g = tv3(o + 11u);
            let g_b = tv3(o + 14u);
            if (any(g_r != vec3<f32>(0.0)) || any(g_g != vec3<f32>(0.0)) || any(g_b != vec3<f32>(0.0))) {
                let w = ii * mm + (area * f * r * r * (1.0 / 6.0)) * g;
                // `hemisphere::unmap_jacobian`
                let r2 = min(p.x * p.x + p.y * p.y, 2.0 - 1.0 / 4096.0);
                let sj = sqrt(2.0 - r2);
                let inv = 1.0 / sj;
                let uv = p.x * p.y * inv;
                let ju = vec3<f32>(sj - p.x * p.x * inv, -uv, -2.0 * p.x);
                let jv = vec3<f32>(-uv, sj - p.y * p.y * inv, -2.0 * p.y);
                let vl = ju * w.x + jv * w.y;
                let u = t * vl.x + b * vl.y + nn * vl.z;
                let y = out + vec3<f32>(dot(g_r, u), dot(g_g, u), dot(g_b, u));
                out = select(y, vec3<f32>(0.0), y < vec3<f32>(0.0));
            }
            acc = acc + out;
        }
    }
    output[row] = acc.x;
    output[n + row] = acc.y;
    output[2u * n + row] = acc.z;
}
