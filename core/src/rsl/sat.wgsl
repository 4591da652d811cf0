// steradian: summed-area table box query (mirrors `sat::SatView::box_sum`).
// Input columns [u0, v0, u1, v1] (texel units, corners in any order), output [value].
// Binding 3 is the table in the layout of `SatView::gpu_words`: the header
// [width, height, exponent (i32 bits), 0], then entry S(k, l) at word 4 + 2*(l*(width+1) + k)
// as the (low, high) words of a two's complement i64, in quanta of 2^exponent.
// The box sum is `sat_box_sum` of sat_lib.wgsl (concatenated before this file by `wgsl.rs`).
// Specified for finite inputs only; see `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let w = table[0];
    let h = table[1];
    let e = bitcast<i32>(table[2]);
    let ax = sat_axis(input[i], input[2u * n + i], w);
    let ay = sat_axis(input[n + i], input[3u * n + i], h);
    output[i] = sat_box_sum(4u, e, w, ax, ay);
}
