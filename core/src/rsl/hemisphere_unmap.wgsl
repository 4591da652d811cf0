// steradian: inverse equal-area hemisphere map, disk point -> unit direction (mirrors
// `hemisphere::unmap`). Input columns [u, v], output columns [x, y, z]; column c of a batch
// of n rows at c*n. Specified for finite inputs with |p| < 1.8e19 (|p|^2 must not
// overflow); see `steradian_core::wgsl`.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    var px = input[i];
    var py = input[n + i];
    var r2 = px * px + py * py;
    // Points outside the disk are clamped radially onto the unit circle (the horizon).
    // Scale by the larger component first, as the scalar kernel does.
    if (r2 > 1.0) {
        let m = max(abs(px), abs(py));
        let qx = px / m;
        let qy = py / m;
        let k = 1.0 / sqrt(qx * qx + qy * qy);
        px = qx * k;
        py = qy * k;
        r2 = 1.0;
    }
    let s = sqrt(2.0 - r2);
    output[i] = px * s;
    output[n + i] = py * s;
    output[2u * n + i] = 1.0 - r2;
}
