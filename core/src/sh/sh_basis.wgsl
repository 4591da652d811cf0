// steradian: all bands² real SH at a direction in f32 (mirrors `sh::eval_into`), the shared
// part of the SH kernels (`sh_eval.wgsl`, `sh_cap.wgsl`, `sh_irradiance.wgsl`,
// `sh_hvl.wgsl`): `sh_basis(d, bands)` fills `ybuf[l² + l + m]` for `bands ≤ 32`, and
// `sh_cap_scale(a, bands)` turns that basis at a cap's axis into the cap's coefficients.
//
// Not the scalar kernel's recurrence: in f32, its three-term recurrence in l has a double
// characteristic root at the poles (|cos θ| → 1), where rounding and the f32 error of cos θ
// grow like l². Here, per order m, with t = |cos θ| and u = 1 − t formed without
// cancellation as (x² + y²)/(r(r + |z|)), and P̃_l^m(t) = P_l^m(t)/sin^m θ (a polynomial in t):
//   g_l = P̃_l^m(t)/P̃_l^m(1) (so g_m = 1, g_{m+1} = t, g_l(1) = 1),
//   (l + m)·g_l = (2l − 1)·t·g_{l−1} − (l − m − 1)·g_{l−2} (the Legendre recurrence divided
//   by P̃_l^m(1)/P̃_{l−1}^m(1) = (l + m)/(l − m)), run on the differences e_l = g_l − g_{l−1}:
//   (l + m)·e_l = (l − m − 1)·e_{l−1} − (2l − 1)·u·g_{l−1} (subtract (l + m)·g_{l−1} =
//   ((2l − 1) − (l − m − 1))·g_{l−1}), g_l = g_{l−1} + e_l: small corrections to a value near
//   1 at the poles, so errors add instead of growing like l².
// The normalisation F_l^m = √((2l+1)/4π · (l+m)!/(l−m)!)/(2^m m!) (the value of the
// normalised Π_l^m at the pole, divided by sin^m) by F_l/F_{l−1} = √((2l+1)(l+m)/((2l−1)(l−m)))
// from F_m^m = Π_m^m (F_m/F_{m−1} = √((2m+1)/(2m))), then Y = √2·(−1)^m·F·g·C_m (S_m) with
// C_m + i·S_m = (x + i·y)^m on the unit direction; cos θ < 0 by parity, (−1)^(l+m). The
// direction is scaled by its largest component first (f32 would overflow on squares of
// large components).

const Y00: f32 = 0.28209479177387814;
const SH_MAX_BANDS: u32 = 32u;

var<private> ybuf: array<f32, 1024>;

fn sh_basis(d_in: vec3<f32>, bands: u32) {
    var d = d_in;
    let big = max(abs(d.x), max(abs(d.y), abs(d.z)));
    if (big == 0.0) {
        d = vec3<f32>(0.0, 0.0, 1.0);
    } else {
        d = d / big;
    }
    let r = sqrt(dot(d, d));
    let x = d.x / r;
    let y = d.y / r;
    let u = (d.x * d.x + d.y * d.y) / (r * (r + abs(d.z)));
    let t = 1.0 - u;
    let below = d.z < 0.0;
    var c = 1.0;
    var s = 0.0;
    var fmm = Y00;
    for (var m = 0u; m < bands; m++) {
        let mf = f32(m);
        var scale = 1.0;
        if (m > 0u) {
            fmm = fmm * sqrt((2.0 * mf + 1.0) / (2.0 * mf));
            let cn = x * c - y * s;
            let sn = x * s + y * c;
            c = cn;
            s = sn;
            scale = select(sqrt(2.0), -sqrt(2.0), (m & 1u) == 1u);
        }
        var g = 1.0;
        var e = 0.0;
        var f = fmm;
        for (var l = m; l < bands; l++) {
            let lf = f32(l);
            if (l > m) {
                f = f * sqrt(((2.0 * lf + 1.0) * (lf + mf)) / ((2.0 * lf - 1.0) * (lf - mf)));
                if (l == m + 1u) {
                    e = -u;
                    g = t;
                } else {
                    e = ((lf - mf - 1.0) * e - (2.0 * lf - 1.0) * u * g) / (lf + mf);
                    g = g + e;
                }
            }
            var q = scale * f * g;
            if (below && ((l + m) & 1u) == 1u) {
                q = -q;
            }
            let at = l * l + l;
            if (m == 0u) {
                ybuf[at] = q;
            } else {
                ybuf[at + m] = q * c;
                ybuf[at - m] = q * s;
            }
        }
    }
}

// The basis in `ybuf` at a cap's axis times each band's factor `k_l` (`cap_factor_next`
// of `sh_cap_factors.wgsl`, which must precede this file). `ybuf` then holds
// ∫_cap Y_l^m dω of the cap of half-angle `a`.
fn sh_cap_scale(a: f32, bands: u32) {
    var f = cap_factors(a);
    for (var l = 0u; l < bands; l++) {
        let k = cap_factor_next(&f, l);
        for (var c = l * l; c < (l + 1u) * (l + 1u); c++) {
            ybuf[c] = ybuf[c] * k;
        }
    }
}
