// steradian: equal-area hemisphere map, direction -> disk point (mirrors `hemisphere::map`).
// Input columns [x, y, z], output columns [u, v]; column c of a batch of n rows at c*n.
// Specified for finite, normal (not subnormal) inputs only; see `steradian_core::wgsl`.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let dx = input[i];
    let dy = input[n + i];
    let dz = input[2u * n + i];
    let m = max(max(abs(dx), abs(dy)), abs(dz));
    // Zero vector -> pole. Tested before the division: WGSL gives no guarantee for 1/0.
    if (m == 0.0) {
        output[i] = 0.0;
        output[n + i] = 0.0;
        return;
    }
    // The scalar kernel scales by r = 1/m, which is subnormal for m > 2^126 and would be
    // flushed to zero on the GPU. Scaling by the power of two 2^-exp(m) instead is exact,
    // keeps every value normal, and differs from 1/m only by a common factor that the
    // normalisation below removes.
    let e = frexp(m).exp;
    let x = ldexp(dx, -e);
    let y = ldexp(dy, -e);
    let z = ldexp(dz, -e);
    let inv_len = 1.0 / sqrt(x * x + y * y + z * z);
    // Lower hemisphere mirrored: z -> |z|.
    let zn = abs(z) * inv_len;
    let s = inv_len / sqrt(1.0 + zn);
    output[i] = x * s;
    output[n + i] = y * s;
}
