// steradian: L2-optimal lobe exponent of a spherical cap of half-angle alpha, looked up in
// the table of h(alpha) = e*(alpha)*alpha^2 on a uniform grid over [0, pi/2] (mirrors
// `cap::lookup`). Input column [half_angle], output column [exponent]; the table is the
// storage buffer at binding 3, N = arrayLength(&table) samples. Specified for finite inputs
// only; see `steradian_core::wgsl`.

struct Params {
    n: u32,
    row_stride: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read> table: array<f32>;

// `cap::MIN_HALF_ANGLE`: smaller (and negative) half-angles are clamped to it.
const MIN_HALF_ANGLE: f32 = 1e-18;
// pi/2 rounded to f32, as `core::f32::consts::FRAC_PI_2`.
const FRAC_PI_2: f32 = 1.5707963267948966;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x + gid.y * params.row_stride;
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
    let x = min(a * (last / FRAC_PI_2), last);
    let k = min(u32(floor(x)), len - 2u);
    let f = x - f32(k);
    let h0 = table[k];
    let h1 = table[k + 1u];
    output[i] = (h0 + f * (h1 - h0)) / (a * a);
}
