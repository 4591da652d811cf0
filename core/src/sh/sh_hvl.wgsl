// steradian: one HVL's contribution to one receiver per invocation (mirrors
// `sh::hvl::contribution` with the smoothstep horizon, or the exact one where the prelude
// sets HVL_EXACT_HORIZON, in f32): the geometry of
// `sh::hvl::prepare`, the emission F′·Y(−ω_j) in the HVL's frame and the cap toward the HVL
// in the receiver's frame dotted with its F (`sh_basis` and `sh_cap_scale` of
// `sh_basis.wgsl`), then P·e·G·s.
// Input columns (one row per HVL): [px, py, pz, tx, ty, tz, bx, by, bz, nx, ny, nz, r, P]
// (centre, the HVL frame's tangent, bitangent and normal, radius, power). Output: one
// column. Table (binding 3): [n, ne, x, y, z, rtx, rty, rtz, rbx, rby, rbz, rnx, rny, rnz,
// F_0 … F_{n²−1}, F′_0 … F′_{ne²−1}] (bands n, ne ≤ 16; the receiver's point and frame).

@group(0) @binding(3) var<storage, read> table: array<f32>;

// The most bands of F and F′: the kernel's tolerance is asserted through 16 bands (a sum of
// n² terms, each with the basis's error).
const HVL_MAX_BANDS: u32 = 16u;

fn col(k: u32, i: u32) -> f32 {
    return input[k * params.n + i];
}

// asin through atan2 with √((1 − x)(1 + x)), accurate near |x| = 1 (where 1 − x² loses
// the digits the horizon term and the cap's half-angle need).
fn asin_acc(x: f32) -> f32 {
    return atan2(x, sqrt((1.0 - x) * (1.0 + x)));
}

// The exact fraction of a cap of half-angle a (sin a = sa ∈ (0, 1]) above the horizon, its
// axis at cos θ = c from the normal (`sh::hvl::horizon_exact`, the same cancellation-free
// form): 1 − acos(w)/π + Δ/(π(1 − cos a)) with acos w = atan2(R, c·cos a),
// Δ = atan2(c·R, 1 + cos a − c²), R = √((sa − c)(sa + c)), 1 − cos a = sa²/(1 + cos a). No
// sin or cos of a (WGSL's lose the relative precision of small angles) and atan2_ of
// `atan2.wgsl`, exact in relative terms for the small Δ of a small cap.
fn horizon_exact(c: f32, sa: f32) -> f32 {
    if (c >= sa) {
        return 1.0;
    }
    if (-c >= sa) {
        return 0.0;
    }
    let ca = sqrt((1.0 - sa) * (1.0 + sa));
    let r = sqrt((sa - c) * (sa + c));
    let acw = atan2_(r, c * ca);
    let y = c * r;
    let d = sign(y) * atan2_(abs(y), 1.0 + ca - c * c);
    let omc = sa * sa / (1.0 + ca);
    let pi = 3.14159265358979;
    return clamp(1.0 - acw / pi + d / (pi * omc), 0.0, 1.0);
}

fn v3(at: u32) -> vec3<f32> {
    return vec3<f32>(table[at], table[at + 1u], table[at + 2u]);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    if (i >= params.n) {
        return;
    }
    let n = min(u32(table[0]), HVL_MAX_BANDS);
    let ne = min(u32(table[1]), HVL_MAX_BANDS);
    let x = v3(2u);
    let rt = v3(5u);
    let rb = v3(8u);
    let rn = v3(11u);
    let coeffs = 14u;
    let emission = coeffs + n * n;
    let p = vec3<f32>(col(0u, i), col(1u, i), col(2u, i));
    let ht = vec3<f32>(col(3u, i), col(4u, i), col(5u, i));
    let hb = vec3<f32>(col(6u, i), col(7u, i), col(8u, i));
    let hn = vec3<f32>(col(9u, i), col(10u, i), col(11u, i));
    let radius = col(12u, i);
    let power = col(13u, i);
    let v = p - x;
    let d = sqrt(dot(v, v));
    // NaN fails every comparison: a NaN distance is NaN, as on the CPU.
    if (!(d == d)) {
        output[i] = bitcast<f32>(0x7fc00000u);
        return;
    }
    if (d <= 0.0 || d > 3.4028235e38) {
        output[i] = 0.0;
        return;
    }
    let w = v / d;
    let cos_j = -dot(w, hn);
    if (cos_j <= 0.0) {
        output[i] = 0.0;
        return;
    }
    let sa = min(radius / d, 1.0);
    let a = asin_acc(sa);
    let c = clamp(dot(w, rn), -1.0, 1.0);
    var h = 0.0;
    if (HVL_EXACT_HORIZON) {
        h = horizon_exact(c, sa);
    } else {
        let t = clamp((a + asin_acc(c)) / (2.0 * a), 0.0, 1.0);
        h = t * t * (3.0 - 2.0 * t);
    }
    if (h == 0.0) {
        output[i] = 0.0;
        return;
    }
    // Emission toward x: F′·Y(−ω_j) in the HVL's frame.
    sh_basis(vec3<f32>(dot(-w, ht), dot(-w, hb), dot(-w, hn)), ne);
    var e = 0.0;
    for (var k = 0u; k < ne * ne; k++) {
        e = e + table[emission + k] * ybuf[k];
    }
    // The cap toward the HVL in the receiver's frame, dotted with F.
    sh_basis(vec3<f32>(dot(w, rt), dot(w, rb), dot(w, rn)), n);
    sh_cap_scale(a, n);
    var s = 0.0;
    for (var k = 0u; k < n * n; k++) {
        s = s + table[coeffs + k] * ybuf[k];
    }
    let pi = 3.14159265358979;
    let g = cos_j * h / (pi * radius * radius);
    output[i] = power * e * g * s;
}
