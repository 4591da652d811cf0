// steradian: visibility distance table query (mirrors `vdt::VdtView::query`): the visible
// fraction of the square with centre (u, v) and half-diagonal r (texel units), by eq. 9
// (one bilinear lookup of D) and by the straight-edge (gradient) variant (the fitted plane
// through a 4×4 stencil of D).
// Input columns [u, v, r], output columns [eq9, gradient]; column c of n rows at c*n.
// Binding 3: the table [w, h, D(0, 0), D(1, 0), ...] (w and h as f32, D row-major), as
// `Vdt::gpu_table`. The query is that of vdt_lib.wgsl (concatenated before this file by
// `wgsl/mod.rs`). Specified for finite inputs only; see `steradian_core::wgsl`.

@group(0) @binding(3) var<storage, read> table: array<f32>;

fn vdt_table(at: u32) -> f32 {
    return table[at];
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = batch_row(gid);
    let n = params.n;
    if (row >= n) {
        return;
    }
    let u = input[row];
    let v = input[n + row];
    let r = input[2u * n + row];
    let w = u32(table[0]);
    let h = u32(table[1]);
    output[row] = vdt_eq9(vdt_distance(vdt_cell(2u, w, h, u, v)), r);
    output[n + row] = vdt_straight_edge(2u, w, h, u, v, r);
}
