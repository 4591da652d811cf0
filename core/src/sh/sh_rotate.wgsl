// steradian: the built SH rotation operator applied to one coefficient vector per invocation
// (mirrors `sh::rotate::apply_operator`, f32 as it is): band by band, output coefficient
// l² + r is Σ_c M_l[r][c]·input[l² + c], summed left to right from 0. Input and output:
// bands² columns (coefficient k of vector i at k·n + i); the table (binding 3) is
// [bands, the blocks of `sh::rotate::operator_into`] (block l: (2l+1)² row-major entries
// from offset l·(4l²−1)/3). Bands from SH_ROTATE_MAX_BANDS on are NaN: lavapipe ends a
// shader's loops after about 65 000 iterations in all, which the sums of more bands pass
// (at 40 bands it silently dropped bands 36 on).

const SH_ROTATE_MAX_BANDS: u32 = 32u;

@group(0) @binding(3) var<storage, read> table: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let bands = u32(table[0]);
    for (var l = 0u; l < bands; l++) {
        let w = 2u * l + 1u;
        let base = 1u + l * (4u * l * l - 1u) / 3u;
        let first = l * l;
        if (l >= SH_ROTATE_MAX_BANDS) {
            // Past the supported bands: NaN, not a silently truncated sum.
            for (var r = 0u; r < w; r++) {
                output[(first + r) * n + i] = bitcast<f32>(0x7fc00000u);
            }
            continue;
        }
        for (var r = 0u; r < w; r++) {
            var acc = 0.0;
            for (var c = 0u; c < w; c++) {
                acc = acc + table[base + r * w + c] * input[(first + c) * n + i];
            }
            output[(first + r) * n + i] = acc;
        }
    }
}
