// steradian: the SH coefficients ∫_cap Y_l^m dω of a spherical cap (mirrors
// `sh::cap::coefficients_into`, in f32): the basis at the axis (`sh_basis`) times each
// band's factor k_l = √(4π/(2l+1))·L̃_l = 2π·sin²a·P_l′(cos a)/(l(l+1)) (k_0 = 4π·sin²(a/2)),
// P_l′ by the derivative recurrence P′_{l+1} = P′_{l−1} + (2l+1)·P_l (a sum of positive
// terms near cos a = 1, no cancellation for small caps), sin a and cos a from a/2 as the
// scalar kernel's `cap_trig`. Input columns [x, y, z, a]; output column k = l² + l + m of
// `bands²`; the table (binding 3) is one f32, the band count (1..=16). A half-angle outside
// [0, π] or NaN gives NaN in every output (the scalar kernel's error).

@group(0) @binding(3) var<storage, read> table: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let bands = min(u32(table[0]), SH_MAX_BANDS);
    sh_basis(vec3<f32>(input[i], input[n + i], input[2u * n + i]), bands);
    let a = input[3u * n + i];
    // `!(a >= 0 && a <= π)` is true for NaN too (comparisons with NaN are false).
    let bad = !(a >= 0.0 && a <= 3.14159274);
    let sh = sin(0.5 * a);
    let ch = cos(0.5 * a);
    let s = 2.0 * sh * ch;
    let s2 = s * s;
    let x = 1.0 - 2.0 * sh * sh;
    let pi = 3.14159265358979;
    var p_prev = 1.0;
    var p = x;
    var dp_prev = 0.0;
    var dp = 1.0;
    for (var l = 0u; l < bands; l++) {
        var k = 4.0 * pi * sh * sh;
        if (l > 0u) {
            let lf = f32(l);
            k = 2.0 * pi * s2 * dp / (lf * (lf + 1.0));
            let p_next = ((2.0 * lf + 1.0) * x * p - lf * p_prev) / (lf + 1.0);
            let dp_next = dp_prev + (2.0 * lf + 1.0) * p;
            p_prev = p;
            p = p_next;
            dp_prev = dp;
            dp = dp_next;
        }
        for (var c = l * l; c < (l + 1u) * (l + 1u); c++) {
            var v = ybuf[c] * k;
            if (bad) {
                v = bitcast<f32>(0x7fc00000u);
            }
            output[c * n + i] = v;
        }
    }
}
