// steradian: the irradiance E(n) = ∫ L(ω)·max(n·ω, 0) dω (not divided by π) of one radiance
// vector at each normal (mirrors `sh::irradiance::irradiance`, in f32): the basis at the
// normal (`sh_basis`), each band's dot product with the radiance coefficients, times the
// band's clamped-cosine factor A_l, which the table carries. Input columns [x, y, z];
// output one column; the table (binding 3) is [bands, A_0 … A_{bands−1}, L_0 … L_{bands²−1}]
// (bands ≤ 32; A_l from `sh::irradiance::clamped_cosine`, rounded to f32).

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
    var e = 0.0;
    for (var l = 0u; l < bands; l++) {
        let a = table[1u + l];
        if (a == 0.0) {
            continue;
        }
        var band = 0.0;
        for (var c = l * l; c < (l + 1u) * (l + 1u); c++) {
            band = band + table[1u + bands + c] * ybuf[c];
        }
        e = e + a * band;
    }
    output[i] = e;
}
