// steradian: product of two cosine lobes as one lobe (mirrors `product::product_with` with
// `ProductFit::ExactIntegral`), the functions of `lobe_product`: the axis and scale are the
// product's peak (closed form), the exponent makes the result integrate to I = B·exp(g),
// B the logit-Laplace baseline and g the table's trilinear correction. See
// `steradian_core::product` for the formulas. The table at binding 3 begins with
// [exponents, angles, g...]: the two sizes as f32, then the g values in the packed layout
// of `ProductTable` (pairs i <= j at j(j+1)/2 + i, each followed by its angles); a kernel
// may append its own data after them. Specified for finite inputs only; see
// `steradian_core::wgsl`. `log1p` and `ln_` (log without WGSL's `log`) are those of
// log1p.wgsl, `atan2_` that of atan2.wgsl (concatenated before this file by `wgsl.rs`).

@group(0) @binding(3) var<storage, read> table: array<f32>;

// ln(2*pi) as the f32 the scalar kernel computes.
const LN_TWO_PI: f32 = 1.837877;
// `product::EXPONENT_EPS`, `1/ln(1 + E/eps)`, `product::ANGLE_LOG_DROP`.
const EXPONENT_EPS: f32 = 0.05;
const INV_LN_SPAN: f32 = 0.06892436;
const ANGLE_LOG_DROP: f32 = 30.0;

// (1 − cos φ, 1 + cos φ) of φ = atan2(sn, cs), sn >= 0, each without cancellation.
fn one_pm_cos(sn: f32, cs: f32) -> vec2<f32> {
    let h = sqrt(sn * sn + cs * cs);
    if (h == 0.0) {
        return vec2<f32>(1.0, 1.0);
    }
    let s2 = sn * sn / h;
    if (cs >= 0.0) {
        return vec2<f32>(s2 / (h + cs), (h + cs) / h);
    }
    return vec2<f32>((h - cs) / h, s2 / (h - cs));
}

// A power of two k with k·n in [2^-49, 2^44], 1 for n in [2^-20, 2^20] (the scalar
// `pow2_range`).
fn pow2_range(n: f32) -> f32 {
    if (n < 9.5367431640625e-7) {
        return select(1.8446744073709552e19, 1.2676506002282294e30, n < 8.673617379884035e-19);
    }
    if (n > 1048576.0) {
        return select(9.094947017729282e-13, 7.888609052210118e-31, n > 1.152921504606847e18);
    }
    return 1.0;
}

// Two lanes of the scalar kernel's `arcs` that share their exponents (a0, b0): the doubled
// angles from an axis (c4 = c) or a horizon (c4 = −c) to the peak, with r = b − a (first)
// and r = −(b − a) (second), everything times n = a + b (prescaled by pow2_range); each
// (sn, cs, 1 − cos, 1 + cos).
struct ArcPair {
    plus: vec4<f32>,
    minus: vec4<f32>,
}

fn arc_lane(r: f32, c4: f32, s: f32, cy: f32, ab4: f32, h: f32) -> vec4<f32> {
    let rc = -r * c4;
    let den = cy + rc;
    let pos = select(0.0, s * ab4 / den, den > 0.0);
    let sn = select(s * (cy - rc), pos, rc >= 0.0);
    let cs = c4 * cy - r * s * s;
    if (h == 0.0) {
        return vec4<f32>(sn, cs, 1.0, 1.0);
    }
    let d = h + abs(cs);
    let small = sn * sn / (h * d);
    let big = d / h;
    if (cs >= 0.0) {
        return vec4<f32>(sn, cs, small, big);
    }
    return vec4<f32>(sn, cs, big, small);
}

fn arc_pair(a0: f32, b0: f32, c4: f32, c: f32, s: f32) -> ArcPair {
    let k = pow2_range(a0 + b0);
    let a = a0 * k;
    let b = b0 * k;
    let n = a + b;
    let ab4 = 4.0 * a * b;
    let cy = sqrt(n * n * (c * c) + ab4 * (s * s));
    // |(sn, cs)| = n·(c² + s²) for either sign.
    let h = n * (c * c + s * s);
    let r = b - a;
    return ArcPair(arc_lane(r, c4, s, cy, ab4, h), arc_lane(-r, c4, s, cy, ab4, h));
}

// e^(−g): the scalar `exp_neg_small` (degree-6 Taylor polynomial where |g| <= 1/4).
fn exp_neg_small(g: f32) -> f32 {
    if (abs(g) <= 0.25) {
        let g2 = g * g;
        let q = (1.0 - g * 0.5) + g2 * (1.0 / 6.0 - g * (1.0 / 24.0))
            + (g2 * g2) * (1.0 / 120.0 - g * (1.0 / 720.0));
        return 1.0 - g * q;
    }
    return exp(-g);
}

// ln cos t from (1 − cos 2t, 1 + cos 2t).
fn ln_cos_half(omc: f32, opc: f32) -> f32 {
    if (omc < opc) {
        return 0.5 * log1p(-0.5 * omc);
    }
    return 0.5 * ln_(0.5 * opc);
}

// ln of the rounded 1 + e/ε (absolute precision suffices for a coordinate).
fn exponent_coord(e: f32) -> f32 {
    return min(ln_(1.0 + max(e, 0.0) * (1.0 / EXPONENT_EPS)) * INV_LN_SPAN, 1.0);
}

// The table value of pair (a, b) at angle node k, and the next one.
fn pair_at(a: u32, b: u32, k: u32, angles: u32) -> vec2<f32> {
    let lo = min(a, b);
    let hi = max(a, b);
    let base = 2u + (hi * (hi + 1u) / 2u + lo) * angles + k;
    return vec2<f32>(table[base], table[base + 1u]);
}

fn correction(u1: f32, u2: f32, w: f32) -> f32 {
    let ne = u32(table[0]);
    let na = u32(table[1]);
    let le = f32(ne - 1u);
    let la = f32(na - 1u);
    let ti = clamp(u1 * le, 0.0, le);
    let tj = clamp(u2 * le, 0.0, le);
    let tk = clamp(w * la, 0.0, la);
    let i = min(u32(ti), ne - 2u);
    let j = min(u32(tj), ne - 2u);
    let k = min(u32(tk), na - 2u);
    let fi = ti - f32(i);
    let fj = tj - f32(j);
    let fk = tk - f32(k);
    let p00 = pair_at(i, j, k, na);
    let p01 = pair_at(i, j + 1u, k, na);
    let p10 = pair_at(i + 1u, j, k, na);
    let p11 = pair_at(i + 1u, j + 1u, k, na);
    let g00 = p00.x + fk * (p00.y - p00.x);
    let g01 = p01.x + fk * (p01.y - p01.x);
    let g10 = p10.x + fk * (p10.y - p10.x);
    let g11 = p11.x + fk * (p11.y - p11.x);
    let g0 = g00 + fj * (g01 - g00);
    let g1 = g10 + fj * (g11 - g10);
    return g0 + fi * (g1 - g0);
}

// The scalar `result_lobe`'s axis: divided by its length where its squared length is in
// [1/4, 4], else `frame::normalize_or_zero`, zero → +z (`CosineLobe::saturating`).
fn normalize_axis(v: vec3<f32>) -> vec3<f32> {
    let l2 = v.x * v.x + v.y * v.y + v.z * v.z;
    if (l2 >= 0.25 && l2 <= 4.0) {
        return v * (1.0 / sqrt(l2));
    }
    let m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (m == 0.0) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let s = v * (1.0 / m);
    return s * (1.0 / sqrt(s.x * s.x + s.y * s.y + s.z * s.z));
}


// A lobe as the product returns it: unit axis, scale, exponent.
struct ProductLobe {
    axis: vec3<f32>,
    scale: f32,
    exponent: f32,
}

// The product of s1·max(a1·v, 0)^e1 and s2·max(a2·v, 0)^e2 (unit axes; negative exponents
// clamped to 0) as one lobe: the scalar `product_with(table, ExactIntegral, ..)`.
fn lobe_product(a1: vec3<f32>, s1: f32, e1_in: f32, a2: vec3<f32>, s2: f32, e2_in: f32) -> ProductLobe {
    let e1 = max(e1_in, 0.0);
    let e2 = max(e2_in, 0.0);
    let scale = s1 * s2;

    // Arc frame: cos α, sin α and the unit perpendicular w of a1 toward a2.
    let c0 = a1.x * a2.x + a1.y * a2.y + a1.z * a2.z;
    let perp = a2 - a1 * c0;
    let s0 = sqrt(perp.x * perp.x + perp.y * perp.y + perp.z * perp.z);
    var w: vec3<f32>;
    if (s0 > 1e-30) {
        w = perp / s0;
    } else {
        // `Frame::from_unit_normal(a1).tangent()`.
        let sg = select(-1.0, 1.0, a1.z >= 0.0);
        let fa = -1.0 / (sg + a1.z);
        let fb = a1.x * a1.y * fa;
        w = vec3<f32>(1.0 + sg * a1.x * a1.x * fa, sg * fb, -sg * a1.x);
    }
    let c = clamp(c0, -1.0, 1.0);
    let s = min(s0, 1.0);

    // The product's peak: direction (cos t*, sin t*) from a1 and ln of its value (lanes 2
    // and 3 of the scalar kernel's arcs).
    var ct: f32;
    var st: f32;
    var ln_peak = 0.0;
    if (e1 + e2 > 0.0) {
        let pp = arc_pair(e1, e2, c, c, s);
        let p1 = pp.plus;
        let p2 = pp.minus;
        if (e1 != 0.0) {
            ln_peak = ln_peak + e1 * ln_cos_half(p1.z, p1.w);
        }
        if (e2 != 0.0) {
            ln_peak = ln_peak + e2 * ln_cos_half(p2.z, p2.w);
        }
        ct = sqrt(0.5 * p1.w);
        st = sqrt(0.5 * p1.z);
    } else {
        let q = one_pm_cos(s, c);
        ct = sqrt(0.5 * q.y);
        st = sqrt(0.5 * q.x);
    }
    let axis = normalize_axis(a1 * ct + w * st);

    // Laplace in the logit variable around the peak of sin^(e1+1)·sin^(e2+1) (lanes 0 and
    // 1 of the arcs).
    let f1 = e1 + 1.0;
    let f2 = e2 + 1.0;
    let ph = arc_pair(f1, f2, -c, c, s);
    let px = ph.minus;
    let py = ph.plus;
    let x = 0.5 * atan2_(px.x, px.y);
    let y = 0.5 * atan2_(py.x, py.y);
    if (!(x > 0.0 && y > 0.0)) {
        // α = π: the open hemispheres are disjoint.
        return ProductLobe(axis, 0.0 * scale, 0.0);
    }
    let ln_sin_x = ln_cos_half(px.w, px.z);
    let ln_sin_y = ln_cos_half(py.w, py.z);
    let wc = sqrt(clamp(-(f1 * ln_sin_x + f2 * ln_sin_y) * (1.0 / ANGLE_LOG_DROP), 0.0, 1.0));
    // The table's loads first, so that they overlap the rest of the baseline.
    let g = correction(exponent_coord(e1), exponent_coord(e2), wc);
    let ix = 1.0 / x;
    let iy = 1.0 / y;
    let cot_x = sqrt(px.w / px.z);
    let cot_y = sqrt(py.w / py.z);
    let d = (e1 * cot_x + ix) - (e2 * cot_y + iy);
    let ap = e1 * (2.0 / px.z) + ix * ix;
    let bp = e2 * (2.0 / py.z) + iy * iy;
    // −φ''/m² (the scalar kernel's hq); ln B = ln_sines + ln 2π − ½·ln((n + 1.5)·hq) + quad.
    let hq = max(ap + bp - d * (y - x) * (ix * iy), 1e-30);
    if (hq > 3.4028235e38) {
        return ProductLobe(axis, 0.0 * scale, 0.0);
    }
    let quad = 0.5 * d * (d / hq);
    let n15 = e1 + e2 + 1.5;
    let ln_sines = e1 * ln_sin_x + e2 * ln_sin_y;
    // 2π·peak/(e_r + 1) = I = B·e^g: e_r + 1 = e^(ln p − ln_sines)·√(n + 1.5)·√hq·e^(−(quad
    // + g)), or from ln I whole where that first exponent leaves [−80, 80].
    let arg = ln_peak - ln_sines;
    var e_r: f32;
    if (abs(arg) < 80.0) {
        e_r = exp(arg) * (sqrt(n15) * sqrt(hq)) * exp_neg_small(quad + g) - 1.0;
    } else {
        let ln_b = ln_sines + (LN_TWO_PI - 0.5 * (ln_(n15) + ln_(hq))) + quad;
        e_r = exp(LN_TWO_PI + ln_peak - (ln_b + g)) - 1.0;
    }
    return ProductLobe(axis, scale * exp(ln_peak), max(e_r, 0.0));
}
