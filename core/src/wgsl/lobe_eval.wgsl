// steradian: cosine lobe s*max(a.v, 0)^e (mirrors `lobe::eval`), computed as
// s*exp(e*log1p(-|a - v|^2/2)) and 0 where |a - v|^2/2 >= 1.
// Input columns [ax, ay, az, s, e, vx, vy, vz], output column [value]; column c of a batch
// of n rows at c*n. Specified for finite inputs only; see `steradian_core::wgsl`.

// log(1 + x) for x > -1. WGSL has no log1p, and the usual `log(u)*x/(u - 1)` with
// u = 1 + x does not survive GPU compilers: they may fold (1 + x) - 1 into x (Mesa was seen to),
// and WGSL's log only promises 2^-21 *absolute* error near 1 (lavapipe: ~1.6e-7), a
// relative error of 100% for |x| ~ 1e-7. So log is not used: with w = f/(2 + f),
// log(1 + f) = 2·atanh(w) = 2w·(1 + w²/3 + w⁴/5 + …), |w| ≤ 0.1716 for
// 1 + f in [sqrt(1/2), sqrt(2)), where six terms reach f32 precision. Near 0 (f = x, no
// rounding of 1 + x) that is used directly; otherwise 1 + x = 2^k·m with m in that range
// (frexp, exact) and log(1 + x) = k·ln2 + log(m), where rounding 1 + x costs at most
// 2^-24/0.71 absolute against |log(1 + x)| > 0.34.
fn log1p_atanh(w: f32) -> f32 {
    let w2 = w * w;
    let p = 1.0 / 3.0 + w2 * (1.0 / 5.0 + w2 * (1.0 / 7.0 + w2 * (1.0 / 9.0 + w2 * (1.0 / 11.0))));
    return 2.0 * w + 2.0 * w * (w2 * p);
}

fn log1p(x: f32) -> f32 {
    if (x >= -0.29289323 && x < 0.41421357) {
        return log1p_atanh(x / (2.0 + x));
    }
    let fr = frexp(1.0 + x);
    var m = fr.fract;
    var k = fr.exp;
    if (m < 0.70710677) {
        m = 2.0 * m;
        k = k - 1;
    }
    return f32(k) * 0.6931471805599453 + log1p_atanh((m - 1.0) / (m + 1.0));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let a = vec3<f32>(input[i], input[n + i], input[2u * n + i]);
    let scale = input[3u * n + i];
    // A negative exponent is clamped to 0.
    let exponent = select(input[4u * n + i], 0.0, input[4u * n + i] < 0.0);
    let v = vec3<f32>(input[5u * n + i], input[6u * n + i], input[7u * n + i]);
    let d = a - v;
    let t = 0.5 * (d.x * d.x + d.y * d.y + d.z * d.z);
    if (t >= 1.0) {
        output[i] = 0.0 * scale;
        return;
    }
    output[i] = scale * exp(exponent * log1p(-t));
}
