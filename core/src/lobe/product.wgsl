// steradian: product of two cosine lobes as one lobe (mirrors `product::product_with` with
// `ProductFit::ExactIntegral`), by `lobe_product` of product_lib.wgsl (concatenated before
// this file by `wgsl.rs`, with the table at binding 3 as it describes).
// Input columns [a1x, a1y, a1z, s1, e1, a2x, a2y, a2z, s2, e2] (unit axes), output columns
// [ax, ay, az, scale, exponent]; column c of a batch of n rows at c*n.

fn write_row(i: u32, n: u32, axis: vec3<f32>, scale: f32, exponent: f32) {
    output[i] = axis.x;
    output[n + i] = axis.y;
    output[2u * n + i] = axis.z;
    output[3u * n + i] = scale;
    output[4u * n + i] = exponent;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let p = lobe_product(
        vec3<f32>(input[i], input[n + i], input[2u * n + i]),
        input[3u * n + i],
        input[4u * n + i],
        vec3<f32>(input[5u * n + i], input[6u * n + i], input[7u * n + i]),
        input[8u * n + i],
        input[9u * n + i],
    );
    write_row(i, n, p.axis, p.scale, p.exponent);
}
