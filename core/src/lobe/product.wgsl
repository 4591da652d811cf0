// steradian: product of two cosine lobes as one lobe (mirrors `product::product_with` with
// `ProductFit::ExactIntegral`): the axis and scale are the product's peak (closed form), the
// exponent makes the result integrate to I = B·exp(g), B the logit-Laplace baseline and g
// the table's trilinear correction. See `steradian_core::product` for the formulas.
// Input columns [a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2] (unit axes), output columns
// [ax, ay, az, scale, exponent]; column c of a batch of n rows at c*n. The table at binding
// 3 is [exponents, angles, g...]: the two sizes as f32, then the g values in the packed
// layout of `ProductTable` (pairs i <= j at j(j+1)/2 + i, each followed by its angles).
// Specified for finite inputs only; see `steradian_core::wgsl`. `log1p` and `ln_` (log
// without WGSL's `log`) are those of log1p.wgsl (concatenated before this file by `wgsl.rs`).

@group(0) @binding(3) var<storage, read> table: array<f32>;

const TWO_PI: f32 = 6.2831855;
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

// (sin, cos) of 2t* for the peak of cos^f1(t)·cos^f2(α − t), t from axis 1.
fn peak_pair(s: f32, c: f32, r: f32, omr2: f32, cy: f32) -> vec2<f32> {
    let rc = -r * c;
    var sn: f32;
    if (rc >= 0.0) {
        let den = cy + rc;
        sn = select(0.0, s * omr2 / den, den > 0.0);
    } else {
        sn = s * (cy - rc);
    }
    return vec2<f32>(sn, c * cy - r * s * s);
}

// (r, 1 − r²) for exponents f1, f2 >= 0, f1 + f2 > 0.
fn ratio(f1: f32, f2: f32) -> vec2<f32> {
    let n = f1 + f2;
    return vec2<f32>((f2 - f1) / n, 4.0 * (f1 / n) * (f2 / n));
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

fn write_row(i: u32, n: u32, axis: vec3<f32>, scale: f32, exponent: f32) {
    output[i] = axis.x;
    output[n + i] = axis.y;
    output[2u * n + i] = axis.z;
    output[3u * n + i] = scale;
    output[4u * n + i] = exponent;
}

// `frame::normalize_or_zero`, zero → +z (`CosineLobe::saturating`).
fn normalize_axis(v: vec3<f32>) -> vec3<f32> {
    let m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    if (m == 0.0) {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    let s = v * (1.0 / m);
    return s * (1.0 / sqrt(s.x * s.x + s.y * s.y + s.z * s.z));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let a1 = vec3<f32>(input[i], input[n + i], input[2u * n + i]);
    let s1 = input[3u * n + i];
    let e1 = max(input[4u * n + i], 0.0);
    let a2 = vec3<f32>(input[5u * n + i], input[6u * n + i], input[7u * n + i]);
    let s2 = input[8u * n + i];
    let e2 = max(input[9u * n + i], 0.0);
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

    // The product's peak: direction (cos t*, sin t*) from a1 and ln of its value.
    var ct: f32;
    var st: f32;
    var ln_peak = 0.0;
    if (e1 + e2 > 0.0) {
        let rr = ratio(e1, e2);
        let cy = sqrt(c * c + rr.y * s * s);
        let p1 = peak_pair(s, c, rr.x, rr.y, cy);
        let p2 = peak_pair(s, c, -rr.x, rr.y, cy);
        let q1 = one_pm_cos(p1.x, p1.y);
        let q2 = one_pm_cos(p2.x, p2.y);
        if (e1 != 0.0) {
            ln_peak = ln_peak + e1 * ln_cos_half(q1.x, q1.y);
        }
        if (e2 != 0.0) {
            ln_peak = ln_peak + e2 * ln_cos_half(q2.x, q2.y);
        }
        ct = sqrt(0.5 * q1.y);
        st = sqrt(0.5 * q1.x);
    } else {
        let q = one_pm_cos(s, c);
        ct = sqrt(0.5 * q.y);
        st = sqrt(0.5 * q.x);
    }
    let axis = normalize_axis(a1 * ct + w * st);

    // Laplace in the logit variable around the peak of sin^(e1+1)·sin^(e2+1).
    let f1 = e1 + 1.0;
    let f2 = e2 + 1.0;
    let rr = ratio(f1, f2);
    let cy = sqrt(c * c + rr.y * s * s);
    let px = peak_pair(s, -c, -rr.x, rr.y, cy);
    let py = peak_pair(s, -c, rr.x, rr.y, cy);
    let x = 0.5 * atan2_(px.x, px.y);
    let y = 0.5 * atan2_(py.x, py.y);
    if (!(x > 0.0 && y > 0.0)) {
        // α = π: the open hemispheres are disjoint.
        write_row(i, n, axis, 0.0 * scale, 0.0);
        return;
    }
    let qx = one_pm_cos(px.x, px.y);
    let qy = one_pm_cos(py.x, py.y);
    let ln_sin_x = ln_cos_half(qx.y, qx.x);
    let ln_sin_y = ln_cos_half(qy.y, qy.x);
    let wc = sqrt(clamp(-(f1 * ln_sin_x + f2 * ln_sin_y) * (1.0 / ANGLE_LOG_DROP), 0.0, 1.0));
    // The table's loads first, so that they overlap the rest of the baseline.
    let g = correction(exponent_coord(e1), exponent_coord(e2), wc);
    let l = x + y;
    let ix = 1.0 / x;
    let iy = 1.0 / y;
    let il = 1.0 / l;
    let iox = 1.0 / qx.x;
    let ioy = 1.0 / qy.x;
    let m = x * y * il;
    let cot_x = sqrt(qx.y * iox);
    let cot_y = sqrt(qy.y * ioy);
    let a = e1 * cot_x + ix;
    let b = e2 * cot_y + iy;
    let d = a - b;
    let phi1 = d * m;
    let ap = e1 * 2.0 * iox + ix * ix;
    let bp = e2 * 2.0 * ioy + iy * iy;
    let h = max(m * m * (ap + bp) - d * (y - x) * m * il, 1e-30);
    // ln K + ln m + ½·ln(2π/h) = ½·ln((2π·m)²/((n + 1.5)·h)): one logarithm where that
    // argument is a normal number (the scalar kernel's choice), three elsewhere.
    let n15 = e1 + e2 + 1.5;
    let inv = 1.0 / (n15 * h);
    let q = (TWO_PI * m) * (TWO_PI * m) * inv;
    var logs: f32;
    var quad: f32;
    if (q >= 1.1754944e-38 && q <= 3.4028235e38 && inv <= 3.4028235e38) {
        logs = 0.5 * ln_(q);
        quad = phi1 * phi1 * (0.5 * n15) * inv;
    } else {
        logs = 0.5 * ln_(TWO_PI / n15) + ln_(m) + 0.5 * ln_(TWO_PI / h);
        quad = phi1 * phi1 / (2.0 * h);
    }
    let ln_b = e1 * ln_sin_x + e2 * ln_sin_y + logs + quad;
    let ln_i = ln_b + g;

    // 2π·peak/(e_r + 1) = I.
    let e_r = exp(LN_TWO_PI + ln_peak - ln_i) - 1.0;
    write_row(i, n, axis, scale * exp(ln_peak), max(e_r, 0.0));
}
