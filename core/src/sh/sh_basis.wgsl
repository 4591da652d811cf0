// steradian: all bands² real SH at a direction in f32 (mirrors `sh::eval_into`), the shared
// part of the SH kernels (`sh_eval.wgsl`, `sh_cap.wgsl`, `sh_irradiance.wgsl`,
// `sh_hvl.wgsl`): `sh_basis(d, bands)` fills `ybuf[l² + l + m]` for `bands ≤ 16`, and
// `sh_cap_scale(a, bands)` turns that basis at a cap's axis into the cap's coefficients. The scalar kernel's
// recurrence in f32, in its homogeneous form (`r² = x² + y² + z²` kept: an f32 unit vector
// is a few 1e-8 off the sphere, and the Legendre coefficients amplify that; the f64 scalar
// kernel does not see it), the direction scaled by its largest component and normalised
// (f32 would overflow on squares of large components), the coefficients formed here by
// `sqrt` of the same rationals; the rounding of the recurrence grows with the band (see
// `steradian_core::wgsl::SH_EVAL_TOL`).

const Y00: f32 = 0.28209479177387814;
const SH_MAX_BANDS: u32 = 16u;

var<private> ybuf: array<f32, 256>;

fn sh_basis(d_in: vec3<f32>, bands: u32) {
    var d = d_in;
    let big = max(abs(d.x), max(abs(d.y), abs(d.z)));
    if (big == 0.0) {
        d = vec3<f32>(0.0, 0.0, 1.0);
    } else {
        d = d / big;
        d = d / sqrt(dot(d, d));
    }
    let x = d.x;
    let y = d.y;
    let z = d.z;
    let r2 = x * x + y * y + z * z;
    if (bands == 0u) {
        return;
    }
    ybuf[0] = Y00;
    if (bands == 1u) {
        return;
    }
    // m = 0.
    var p2 = Y00;
    var p1 = sqrt(3.0) * z * Y00;
    ybuf[2] = p1;
    for (var l = 2u; l < bands; l++) {
        let lf = f32(l);
        let l1 = lf - 1.0;
        let a = sqrt((4.0 * lf * lf - 1.0) / (lf * lf));
        let b = sqrt((l1 * l1) / (4.0 * l1 * l1 - 1.0));
        let p = a * (z * p1 - b * r2 * p2);
        ybuf[l * l + l] = p;
        p2 = p1;
        p1 = p;
    }
    // m ≥ 1: √2·Π_l^m times C_m and S_m.
    var pmm = Y00;
    var c = 1.0;
    var s = 0.0;
    for (var m = 1u; m < bands; m++) {
        let mf = f32(m);
        pmm = pmm * -sqrt((2.0 * mf + 1.0) / (2.0 * mf));
        let cn = x * c - y * s;
        let sn = x * s + y * c;
        c = cn;
        s = sn;
        var q2 = sqrt(2.0) * pmm;
        var at = m * m + m;
        ybuf[at + m] = q2 * c;
        ybuf[at - m] = q2 * s;
        if (m + 1u == bands) {
            break;
        }
        var q1 = sqrt(2.0 * mf + 3.0) * z * q2;
        at = at + 2u * m + 2u;
        ybuf[at + m] = q1 * c;
        ybuf[at - m] = q1 * s;
        for (var l = m + 2u; l < bands; l++) {
            let lf = f32(l);
            let l1 = lf - 1.0;
            let a = sqrt((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf));
            let b = sqrt((l1 * l1 - mf * mf) / (4.0 * l1 * l1 - 1.0));
            let q = a * (z * q1 - b * r2 * q2);
            let at2 = l * l + l;
            ybuf[at2 + m] = q * c;
            ybuf[at2 - m] = q * s;
            q2 = q1;
            q1 = q;
        }
    }
}

// The basis in `ybuf` at a cap's axis times each band's factor (mirrors
// `sh::cap::band_scales`): k_l = √(4π/(2l+1))·L̃_l = 2π·sin²a·P_l′(cos a)/(l(l+1)),
// k_0 = 4π·sin²(a/2), P_l′ by the derivative recurrence P′_{l+1} = P′_{l−1} + (2l+1)·P_l (a
// sum of positive terms near cos a = 1: no cancellation for small caps), sin a and cos a from
// a/2 as `sh::cap::cap_trig`. `ybuf` then holds ∫_cap Y_l^m dω of the cap of half-angle `a`.
fn sh_cap_scale(a: f32, bands: u32) {
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
            ybuf[c] = ybuf[c] * k;
        }
    }
}
