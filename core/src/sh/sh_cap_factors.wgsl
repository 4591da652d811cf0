// steradian: the factors k_l that turn the SH basis at a cap's axis into the cap's
// coefficients (mirrors `sh::cap::band_scales`), band by band; shared by `sh_cap_scale`
// (`sh_basis.wgsl`) and the zonal sum of `sh_hvl_sum.wgsl`.
// k_l = √(4π/(2l+1))·L̃_l = 2π·sin²a·P_l′(cos a)/(l(l+1)), k_0 = 4π·sin²(a/2), P_l′ by the
// derivative recurrence P′_{l+1} = P′_{l−1} + (2l+1)·P_l (a sum of positive terms near
// cos a = 1: no cancellation for small caps), sin a from a/2 as `sh::cap::cap_trig`. P_l
// itself by its recurrence on the differences d_l = P_l − P_{l−1} with
// u = 1 − cos a = 2·sin²(a/2): (l+1)·d_{l+1} = l·d_l − (2l+1)·u·P_l (the Legendre
// recurrence minus (l+1)·P_l), whose errors add where the plain one's grow like l² near
// cos a = 1 (see `sh_basis`).

struct CapFactors {
    // sin(a/2), sin²a, u = 1 − cos a.
    sh: f32,
    s2: f32,
    u: f32,
    // P_l(cos a), d_l, P′_{l−1}, P′_l of the band about to be taken.
    p: f32,
    d: f32,
    dp_prev: f32,
    dp: f32,
}

fn cap_factors(a: f32) -> CapFactors {
    let sh = sin(0.5 * a);
    let ch = cos(0.5 * a);
    let s = 2.0 * sh * ch;
    let u = 2.0 * sh * sh;
    return CapFactors(sh, s * s, u, 1.0 - u, -u, 0.0, 1.0);
}

// k_l of band `l`, called for l = 0, 1, 2, … in turn (each call past band 0 advances the
// recurrences to the next band).
fn cap_factor_next(f: ptr<function, CapFactors>, l: u32) -> f32 {
    let pi = 3.14159265358979;
    if (l == 0u) {
        return 4.0 * pi * (*f).sh * (*f).sh;
    }
    let lf = f32(l);
    let k = 2.0 * pi * (*f).s2 * (*f).dp / (lf * (lf + 1.0));
    let p = (*f).p;
    let d_next = (lf * (*f).d - (2.0 * lf + 1.0) * (*f).u * p) / (lf + 1.0);
    let dp_next = (*f).dp_prev + (2.0 * lf + 1.0) * p;
    (*f).p = p + d_next;
    (*f).d = d_next;
    (*f).dp_prev = (*f).dp;
    (*f).dp = dp_next;
    return k;
}
