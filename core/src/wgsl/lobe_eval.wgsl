// steradian: cosine lobe s*max(a.v, 0)^e (mirrors `lobe::eval`), computed as
// s*exp(e*log1p(-|a - v|^2/2)) and 0 where |a - v|^2/2 >= 1.
// Input columns [ax, ay, az, s, e, vx, vy, vz], output column [value]; column c of a batch
// of n rows at c*n. Specified for finite inputs only; see `steradian_core::wgsl`.

struct Params {
    n: u32,
    row_stride: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;
@group(0) @binding(2) var<uniform> params: Params;

// WGSL has no log1p: log(u)*x/(u - 1) with u = 1 + x corrects the rounding of 1 + x
// (Goldberg's trick); x itself where 1 + x rounds to 1.
fn log1p(x: f32) -> f32 {
    let u = 1.0 + x;
    return select(log(u) * x / (u - 1.0), x, u == 1.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x + gid.y * params.row_stride;
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
