// steradian: exact sphere integral of a cosine lobe, 2*pi*s/(e + 1) (mirrors
// `lobe::integral`). Input columns [e, s], output column [integral]; column c of a batch of
// n rows at c*n. Specified for finite inputs with |2*pi*s| and e + 1 below 2^126; see
// `steradian_core::wgsl`.

// 2*pi rounded to f32, as `steradian_core::TWO_PI`.
const TWO_PI: f32 = 6.283185307179586;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let exponent = input[i];
    let scale = input[n + i];
    // A negative exponent is clamped to 0.
    let e = select(exponent, 0.0, exponent < 0.0);
    // Divide first, as the scalar kernel does (2π·s overflows for |s| > 5.4e37).
    output[i] = TWO_PI * (scale / (e + 1.0));
}
