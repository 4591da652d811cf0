// steradian: the batch layout every kernel shares; `wgsl.rs` prepends this to each source.
// Column c of a batch of n rows is at c*n in `input` and in `output`.

struct Params {
    n: u32,
    row_stride: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;
@group(0) @binding(2) var<uniform> params: Params;

// The row of this invocation: dispatches fold into 2-D (at most 65535 workgroups per
// dimension), `row_stride` threads per row of workgroups.
fn batch_row(gid: vec3<u32>) -> u32 {
    return gid.x + gid.y * params.row_stride;
}

