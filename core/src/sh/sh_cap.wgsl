// steradian: the SH coefficients ∫_cap Y_l^m dω of a spherical cap (mirrors
// `sh::cap::coefficients_into`, in f32): the basis at the axis (`sh_basis`) times each
// band's factor (`sh_cap_scale`, both in `sh_basis.wgsl`). Input columns [x, y, z, a];
// output column k = l² + l + m of `bands²`; the table (binding 3) is one f32, the band count
// (1..=32). A half-angle outside [0, π] or NaN gives NaN in every output (the scalar
// kernel's error).

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
    let a = input[3u * n + i];
    // `!(a >= 0 && a <= π)` is true for NaN too (comparisons with NaN are false).
    let bad = !(a >= 0.0 && a <= 3.14159274);
    sh_cap_scale(a, bands);
    for (var c = 0u; c < bands * bands; c++) {
        var v = ybuf[c];
        if (bad) {
            v = bitcast<f32>(0x7fc00000u);
        }
        output[c * n + i] = v;
    }
}
