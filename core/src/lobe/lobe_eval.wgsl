// steradian: cosine lobe s*max(a.v, 0)^e (mirrors `lobe::eval`), computed as
// s*exp(e*log1p(-|a - v|^2/2)) and 0 where |a - v|^2/2 >= 1.
// Input columns [ax, ay, az, s, e, vx, vy, vz], output column [value]; column c of a batch
// of n rows at c*n. Specified for finite inputs only; see `steradian_core::wgsl`.
// `log1p` is that of log1p.wgsl (concatenated before this file by `wgsl.rs`).

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
