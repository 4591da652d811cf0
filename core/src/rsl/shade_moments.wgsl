// steradian: RSL shading with visibility moments, one point per invocation (mirrors
// `shade::shade_moments` with an isotropic BRDF SAT and one `VisMoments` per point; see
// `wgsl::SHADE_MOMENTS` for the layout). Input columns [tx, ty, tz, bx, by, bz, nx, ny, nz,
// wox, woy, woz, point_index], output [r, g, b]. Specified for finite inputs only; see
// `steradian_core::wgsl`. The BRDF box sums and the shared shading pieces are those of
// sat_lib.wgsl and shade_lib.wgsl (concatenated before this file by `wgsl.rs`); the
// visibility moments read the three exact integer tables of the point directly
// (`vis_moments::VisMomentsView::moments`).

// 2^61: above it a product s * (V >> k) might not fit the 64-bit difference.
const TWO_POW_61: f32 = 2305843009213693952.0;
// Words per light: centre, r, 1/Ω, E (RGB), gradient (3 × RGB).
const LIGHT_WORDS: u32 = 17u;

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

// One axis as three blocks of texels (`vis_moments::axis_knots`): the partly covered first
// texel [x0, x1), the run of whole texels [x1, x2), the partly covered last texel [x2, x3);
// `w` the blocks' covered lengths (the run's is 1), `mid` the covered centres of the first
// and last texels relative to the origin.
struct Knots {
    x: array<u32, 4>,
    w: array<f32, 3>,
    mid: array<f32, 3>,
}

// [lo, hi] (relative to the integer origin `o`, inside the table, lo <= hi) on an n-texel
// axis: c0 = floor(lo), c1 = floor(hi) (at most n − 1), knots [c0, min(c0 + 1, c1), c1,
// c1 + 1]; when both ends share a texel the last block carries [lo, hi].
fn axis_knots(lo: f32, hi: f32, o: f32, n: u32) -> Knots {
    let last = f32(n - 1u);
    let c0 = min(floor(lo) + o, last);
    let c1 = min(floor(hi) + o, last);
    let split = c0 < c1;
    let e0 = (c0 + 1.0) - o;
    let start = select(lo, c1 - o, split);
    let i0 = u32(c0);
    let i1 = u32(c1);
    return Knots(
        array<u32, 4>(i0, min(i0 + 1u, i1), i1, i1 + 1u),
        array<f32, 3>(select(0.0, e0 - lo, split), 1.0, hi - start),
        array<f32, 3>(0.5 * (lo + e0), 0.0, 0.5 * (start + hi)),
    );
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
// exponent, then its entries): `VisMomentsView::moments` with `inside`, outside the table
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
    let kx = axis_knots(ax.lo, ax.hi, ax.o, n);
    let ky = axis_knots(ay.lo, ay.hi, ay.o, n);
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
    // The nine blocks (`vis_moments::combine_blocks`): x-block a, y-block c.
    var s = 0.0;
    var mx = 0.0;
    var my = 0.0;
    for (var c = 0u; c < 3u; c = c + 1u) {
        let j0 = ky.x[c];
        let j1 = ky.x[c + 1u];
        for (var a = 0u; a < 3u; a = a + 1u) {
            let i0 = kx.x[a];
            let i1 = kx.x[a + 1u];
            let vi = ibox(vbase, w1, i0, i1, j0, j1);
            let bv = scale2(i64_to_f32(vi), ev);
            s = s + (kx.w[a] * ky.w[c]) * bv;
            var tx: f32;
            if (a == 1u) {
                tx = run_moment(xbase, ex, vi, ev, bv, sx_int, fx, w1, i0, i1, j0, j1);
            } else {
                tx = kx.w[a] * bv * (kx.mid[a] - ax.fc);
            }
            mx = mx + ky.w[c] * tx;
            var ty: f32;
            if (c == 1u) {
                ty = run_moment(ybase, ey, vi, ev, bv, sy_int, fy, w1, i0, i1, j0, j1);
            } else {
                ty = ky.w[c] * bv * (ky.mid[c] - ay.fc);
            }
            my = my + kx.w[a] * ty;
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
    let sp = shade_point(row, n);
    let t = sp.t;
    let b = sp.b;
    let nn = sp.n;
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    let wl = vec3<f32>(dot(sp.wo, t), dot(sp.wo, b), dot(sp.wo, nn));
    if (wl.z > 0.0) {
        let vt = view_tables(wl);
        let k0 = vt.k0;
        let tw = vt.tw;
        let rc = vt.rc;
        let rs = vt.rs;
        let grid = table[H_GRID];
        let half_b = 0.5 * f32(grid);
        let vn = table[H_MAP_N];
        let ts = 1u + 2u * (vn + 1u) * (vn + 1u);
        let vbase = table[H_OFF_MAPS] + sp.point * 3u * ts;
        let nl = table[H_LIGHTS];
        let lo = table[H_OFF_LIGHTS];
        for (var i = 0u; i < nl; i = i + 1u) {
            let o = lo + LIGHT_WORDS * i;
            let r = tf(o + 3u);
            let p = light_square_centre(tv3(o), sp);
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
