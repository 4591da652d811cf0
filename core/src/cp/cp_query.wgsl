// steradian: control-point query, one direction per invocation (mirrors
// `cp::Icosphere::query`). Input columns [x, y, z]; output [value]. Binding 3 is the table
// of `cp::Icosphere::gpu_table`: header [level, weights (0 area, 1 gnomonic), V], then the
// canonical octant edge normals (9), the base faces' plane normals (20 × 9), the octant
// table (8 × 4 face indices), the grid (20 × side² vertex indices), the vertices (3V) and
// the values (V), integers stored as f32 (exact: all below 2²⁴). Same operations as the
// scalar kernel: normalisation by the largest component, octant sign bits and the region
// by the edge planes, the grid cell on the face's plane, gnomonic or Van Oosterom–Strackee
// area weights. A zero or non-finite direction gives NaN.

@group(0) @binding(3) var<storage, read> table: array<f32>;

fn tv3(o: u32) -> vec3<f32> {
    return vec3<f32>(table[o], table[o + 1u], table[o + 2u]);
}

fn tri_area(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    let det = dot(b - a, cross(c - a, a));
    let den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
    return 2.0 * atan2(max(det, 0.0), den);
}

fn normalise3(w: vec3<f32>) -> vec3<f32> {
    let s = w.x + w.y + w.z;
    if (s > 0.0) {
        return w / s;
    }
    return vec3<f32>(1.0 / 3.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    let n = params.n;
    if (i >= n) {
        return;
    }
    let level = u32(table[0]);
    let gnomonic = table[1] != 0.0;
    let nv = u32(table[2]);
    let nu = 1u << level;
    let side = nu + 1u;
    let off_planes = 12u;
    let off_oct = off_planes + 180u;
    let off_grid = off_oct + 32u;
    let off_vert = off_grid + 20u * side * side;
    let off_val = off_vert + 3u * nv;
    let d = vec3<f32>(input[i], input[n + i], input[2u * n + i]);
    let ad = abs(d);
    let m = max(ad.x, max(ad.y, ad.z));
    // Not finite (NaN fails every comparison; WGSL's `max` may drop a NaN, so each
    // component is tested) or zero: NaN, as the scalar query's error.
    if (!all(ad <= vec3<f32>(3.4028235e38)) || m == 0.0) {
        output[i] = bitcast<f32>(0x7fc00000u);
        return;
    }
    let s0 = d / m;
    let u = s0 / sqrt(dot(s0, s0));
    let a = abs(u);
    let o = (bitcast<u32>(u.x) >> 31u) | ((bitcast<u32>(u.y) >> 31u) << 1u)
        | ((bitcast<u32>(u.z) >> 31u) << 2u);
    var region = 0u;
    var worst = 0.0;
    for (var k = 0u; k < 3u; k++) {
        let t = dot(a, tv3(3u + 3u * k));
        if (t < worst) {
            worst = t;
            region = k + 1u;
        }
    }
    let f = u32(table[off_oct + 4u * o + region]);
    let b = vec3<f32>(
        dot(u, tv3(off_planes + 9u * f)),
        dot(u, tv3(off_planes + 9u * f + 3u)),
        dot(u, tv3(off_planes + 9u * f + 6u)),
    );
    let sum = b.x + b.y + b.z;
    let nf = f32(nu);
    var x = b.y / sum * nf;
    var y = b.z / sum * nf;
    // Rust's `max(0.0)` maps NaN to 0; WGSL's `max` need not.
    if (!(x > 0.0)) {
        x = 0.0;
    }
    if (!(y > 0.0)) {
        y = 0.0;
    }
    let ci = min(u32(floor(x)), nu - 1u);
    let cj = min(u32(floor(y)), nu - 1u - ci);
    let fx = x - f32(ci);
    let fy = y - f32(cj);
    let up = fx + fy <= 1.0 || ci + cj + 1u == nu;
    let g0 = off_grid + f * side * side;
    var ids: vec3<u32>;
    var gw: vec3<f32>;
    if (up) {
        ids = vec3<u32>(
            u32(table[g0 + cj * side + ci]),
            u32(table[g0 + cj * side + ci + 1u]),
            u32(table[g0 + (cj + 1u) * side + ci]),
        );
        gw = vec3<f32>(1.0 - fx - fy, fx, fy);
    } else {
        ids = vec3<u32>(
            u32(table[g0 + cj * side + ci + 1u]),
            u32(table[g0 + (cj + 1u) * side + ci + 1u]),
            u32(table[g0 + (cj + 1u) * side + ci]),
        );
        gw = vec3<f32>(1.0 - fy, fx + fy - 1.0, 1.0 - fx);
    }
    var w: vec3<f32>;
    if (gnomonic) {
        w = normalise3(max(gw, vec3<f32>(0.0)));
    } else {
        let v0 = tv3(off_vert + 3u * ids.x);
        let v1 = tv3(off_vert + 3u * ids.y);
        let v2 = tv3(off_vert + 3u * ids.z);
        w = normalise3(vec3<f32>(tri_area(u, v1, v2), tri_area(v0, u, v2), tri_area(v0, v1, u)));
    }
    output[i] = w.x * table[off_val + ids.x] + w.y * table[off_val + ids.y]
        + w.z * table[off_val + ids.z];
}
