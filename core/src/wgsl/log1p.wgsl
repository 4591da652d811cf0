// steradian: log without WGSL's `log`, shared by the lobe-eval and lobe-product kernels
// (`wgsl.rs` concatenates it into both).
//
// WGSL has no log1p, and the usual `log(u)*x/(u - 1)` with u = 1 + x does not survive GPU
// compilers: they may fold (1 + x) - 1 into x (Mesa was seen to), and WGSL's log only
// promises 2^-21 *absolute* error near 1 (lavapipe: ~1.6e-7), a relative error of 100% for
// |x| ~ 1e-7. So log is not used: with w = f/(2 + f),
// log(1 + f) = 2·atanh(w) = 2w·(1 + w²/3 + w⁴/5 + …), |w| ≤ 0.1716 for
// 1 + f in [sqrt(1/2), sqrt(2)), where six terms reach f32 precision. Near 0 (f = x, no
// rounding of 1 + x) that is used directly; otherwise 1 + x = 2^k·m with m in that range
// (frexp, exact) and log(1 + x) = k·ln2 + log(m), where rounding 1 + x costs at most
// 2^-24/0.71 absolute against |log(1 + x)| > 0.34.

const LN2: f32 = 0.6931471805599453;

// 2·atanh(w) by its odd series (six terms), for |w| ≤ 0.1716.
fn log1p_atanh(w: f32) -> f32 {
    let w2 = w * w;
    let p = 1.0 / 3.0 + w2 * (1.0 / 5.0 + w2 * (1.0 / 7.0 + w2 * (1.0 / 9.0 + w2 * (1.0 / 11.0))));
    return 2.0 * w + 2.0 * w * (w2 * p);
}

// ln(x) for x > 0 (normal): k·ln2 + 2·atanh((m − 1)/(m + 1)), x = 2^k·m, m in
// [sqrt(1/2), sqrt(2)); m − 1 is exact, so the result keeps its relative precision near 1.
fn ln_(x: f32) -> f32 {
    let fr = frexp(x);
    var m = fr.fract;
    var k = fr.exp;
    if (m < 0.70710677) {
        m = 2.0 * m;
        k = k - 1;
    }
    return f32(k) * LN2 + log1p_atanh((m - 1.0) / (m + 1.0));
}

// log(1 + x) for x > -1.
fn log1p(x: f32) -> f32 {
    if (x >= -0.29289323 && x < 0.41421357) {
        return log1p_atanh(x / (2.0 + x));
    }
    return ln_(1.0 + x);
}
