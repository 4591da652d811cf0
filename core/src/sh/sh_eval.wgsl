// steradian: all bands² real SH at a direction (mirrors `sh::eval_into`, in f32). Input
// columns [x, y, z]; output column k = l² + l + m of `bands²`; the table (binding 3) is one
// f32, the band count (1..=16). Same recurrence and order of operations as the scalar kernel
// (homogeneous form, the direction scaled by its largest component and normalised), with
// its coefficients formed here by `sqrt` of the same rationals; in f32 throughout, so the
// rounding of the recurrence grows with the band (see `steradian_core::wgsl::SH_EVAL_TOL`).

@group(0) @binding(3) var<storage, read> table: array<f32>;

const Y00: f32 = 0.28209479177387814;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let bands = min(u32(table[0]), 16u);
    var d = vec3<f32>(input[i], input[n + i], input[2u * n + i]);
    let big = max(abs(d.x), max(abs(d.y), abs(d.z)));
    if (big == 0.0) {
        d = vec3<f32>(0.0, 0.0, 1.0);
    } else {
        d = d / big;
        d = d / sqrt(dot(d, d));
    }
    let x = d.x;
    let y = d.y;
    let z = d.z;
    let r2 = x * x + y * y + z * z;
    if (bands == 0u) {
        return;
    }
    output[i] = Y00;
    if (bands == 1u) {
        return;
    }
    // m = 0.
    var p2 = Y00;
    var p1 = sqrt(3.0) * z * Y00;
    output[2u * n + i] = p1;
    for (var l = 2u; l < bands; l++) {
        let lf = f32(l);
        let l1 = lf - 1.0;
        let a = sqrt((4.0 * lf * lf - 1.0) / (lf * lf));
        let b = sqrt((l1 * l1) / (4.0 * l1 * l1 - 1.0));
        let p = a * (z * p1 - b * r2 * p2);
        output[(l * l + l) * n + i] = p;
        p2 = p1;
        p1 = p;
    }
    // m ≥ 1: √2·Π_l^m times C_m and S_m.
    var pmm = Y00;
    var c = 1.0;
    var s = 0.0;
    for (var m = 1u; m < bands; m++) {
        let mf = f32(m);
        pmm = pmm * -sqrt((2.0 * mf + 1.0) / (2.0 * mf));
        let cn = x * c - y * s;
        let sn = x * s + y * c;
        c = cn;
        s = sn;
        var q2 = sqrt(2.0) * pmm;
        var at = m * m + m;
        output[(at + m) * n + i] = q2 * c;
        output[(at - m) * n + i] = q2 * s;
        if (m + 1u == bands) {
            break;
        }
        var q1 = sqrt(2.0 * mf + 3.0) * z * q2;
        at = at + 2u * m + 2u;
        output[(at + m) * n + i] = q1 * c;
        output[(at - m) * n + i] = q1 * s;
        for (var l = m + 2u; l < bands; l++) {
            let lf = f32(l);
            let l1 = lf - 1.0;
            let a = sqrt((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf));
            let b = sqrt((l1 * l1 - mf * mf) / (4.0 * l1 * l1 - 1.0));
            let q = a * (z * q1 - b * r2 * q2);
            let at2 = l * l + l;
            output[(at2 + m) * n + i] = q * c;
            output[(at2 - m) * n + i] = q * s;
            q2 = q1;
            q1 = q;
        }
    }
}
