// steradian: all bands² real SH at a direction (mirrors `sh::eval_into`, in f32, through
// `sh_basis` of `sh_basis.wgsl`). Input columns [x, y, z]; output column k = l² + l + m of
// `bands²`; the table (binding 3) is one f32, the band count (1..=32).

@group(0) @binding(3) var<storage, read> table: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let bands = min(u32(table[0]), SH_MAX_BANDS);
    sh_basis(vec3<f32>(input[i], input[n + i], input[2u * n + i]), bands);
    for (var k = 0u; k < bands * bands; k++) {
        output[k * n + i] = ybuf[k];
    }
}
