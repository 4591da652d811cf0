// steradian: L2-optimal lobe exponent of a spherical cap of half-angle alpha, looked up in
// the table of h(alpha) = e*(alpha)*alpha^2 sampled at alpha_i = (pi/2)(1 - (1 - i/(N-1))^2),
// interpolated linearly in alpha between the knots, e = h/alpha^2 (mirrors `cap::lookup`):
// with u = pi/2 - alpha (two-part pi/2) and r = (N - 1)*sqrt(2u/pi), the interval is
// k = max(ceil(r), 1) counted from the end, at fraction (k - r)(k + r)/(2k - 1).
// Input column [half_angle], output column [exponent]; the table is the storage buffer at
// binding 3, N = arrayLength(&table) samples. Specified for finite inputs only; see
// `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<f32>;

// `cap::MIN_HALF_ANGLE`: smaller (and negative) half-angles are clamped to it.
const MIN_HALF_ANGLE: f32 = 1e-18;
// pi/2 rounded to f32, as `core::f32::consts::FRAC_PI_2`.
const FRAC_PI_2: f32 = 1.5707963267948966;
// pi/2 - FRAC_PI_2 (the f32 constant rounds pi/2 up by this much).
const FRAC_PI_2_LO: f32 = -4.371139e-8;
// 2/pi rounded to f32 (0x3f22f983), the value of `2.0 / core::f32::consts::PI`.
const TWO_OVER_PI: f32 = 0.63661975;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let len = arrayLength(&table);
    if (len < 2u) {
        // A table with fewer than two samples gives NaN, as the scalar lookup.
        output[i] = bitcast<f32>(0x7fc00000u);
        return;
    }
    let last = f32(len - 1u);
    let a = clamp(input[i], MIN_HALF_ANGLE, FRAC_PI_2);
    // GPU compilers may reassociate (FRAC_PI_2 - a) + FRAC_PI_2_LO into
    // (FRAC_PI_2 + FRAC_PI_2_LO) - a, which rounds the low part away (Mesa was seen to);
    // a low part that is not a compile-time constant (len > 1 always holds here) keeps the
    // sum as written.
    let lo = select(0.0, FRAC_PI_2_LO, len > 1u);
    let u = max((FRAC_PI_2 - a) + lo, 0.0);
    let r = min(sqrt(u * TWO_OVER_PI) * last, last);
    let k = max(ceil(r), 1.0);
    let j = u32(last - k);
    let f = min((k - r) * (k + r) / (2.0 * k - 1.0), 1.0);
    let h0 = table[j];
    let h1 = table[j + 1u];
    output[i] = (h0 + f * (h1 - h0)) / (a * a);
}
