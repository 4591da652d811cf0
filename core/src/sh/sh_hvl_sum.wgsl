// steradian: the diffuse light a receiver gets from a set of HVLs, one receiver per
// invocation (mirrors `sh::hvl::contribution_zonal` with the smoothstep horizon and a
// Lambertian emitter, summed over the HVLs as the harness's `scene::hvl::indirect` sums
// them, in f32): per HVL the geometry of `sh::hvl::prepare` (as `sh_hvl.wgsl`), the
// emission `F′_0·Y_0^0 = 1/π` of `lambert_emission(1)`, the cap toward the HVL in the
// receiver's view frame dotted with its zonal `F_l` (`zonal_cap_dot`), `c = P·e·G·s`
// clamped at 0; then, where the table asks for it, a shadow ray
// from the receiver's offset origin to the HVL's centre against the occluders (spheres
// and planes, the harness's `Shape::intersect` in f32), and `acc += c·w` with the HVL's
// RGB weight.
// Input columns (one row per receiver): [x, y, z, nx, ny, nz (its normal: a zonal `F` needs
// no more of its view frame), ox, oy, oz (shadow-ray origin), F_0 … F_{n−1}] (n = the
// table's band count ≤ 16). Output: three columns, the RGB sum.
// Table (binding 3): [n_hvl, n_occ, n, visibility (0 or 1), eps (the shadow ray stops at
// d·(1 − eps)), then per HVL 12 values [px, py, pz, nx, ny, nz, r, P, wr, wg, wb, object
// (the occluder it lies on, which its shadow rays skip: they cannot meet it before their end,
// and in f32 one grazing a plane toward an HVL on it would)], then per
// occluder 7 values [kind (0 sphere, 1 plane), ax, ay, az (centre or point), bx (radius) or
// bx, by, bz (normal)]].

@group(0) @binding(3) var<storage, read> table: array<f32>;

const HVL_SUM_MAX_BANDS: u32 = 16u;

fn col(k: u32, i: u32) -> f32 {
    return input[k * params.n + i];
}

fn tv3(at: u32) -> vec3<f32> {
    return vec3<f32>(table[at], table[at + 1u], table[at + 2u]);
}

fn asin_acc(x: f32) -> f32 {
    return atan2(x, sqrt((1.0 - x) * (1.0 + x)));
}

// Whether the segment o + t·d, t ∈ (0, t_max), meets occluder k (`Shape::intersect`).
fn blocked(k: u32, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> bool {
    let at = 5u + 12u * u32(table[0]) + 7u * k;
    let a = tv3(at + 1u);
    if (table[at] == 0.0) {
        let r = table[at + 4u];
        let oc = o - a;
        let b = dot(oc, d);
        let h = oc - b * d;
        let disc = r * r - dot(h, h);
        if (disc < 0.0) {
            return false;
        }
        let c = dot(oc, oc) - r * r;
        let q = -b - sign(b) * sqrt(disc);
        if (q == 0.0) {
            return false;
        }
        let t0 = min(c / q, q);
        let t1 = max(c / q, q);
        return (t0 > 0.0 && t0 < t_max) || (t1 > 0.0 && t1 < t_max);
    }
    let nrm = tv3(at + 4u);
    let den = dot(nrm, d);
    if (den == 0.0) {
        return false;
    }
    let t = dot(nrm, a - o) / den;
    return t > 0.0 && t < t_max;
}

// s = Σ_l F_l·C_l^0 of the cap of half-angle `a` whose axis is at cos θ = z from the
// receiver's normal: C_l^0 = k_l·Y_l^0(z) with Y_l^0 = √((2l+1)/4π)·P_l(z) (the plain
// Legendre recurrence: at most 16 bands) and k_l from `sh_cap_factors.wgsl`, without the
// basis buffer: the m = 0 column is all a zonal receiver reads.
fn zonal_cap_dot(z: f32, a: f32, n: u32, i: u32) -> f32 {
    let pi = 3.14159265358979;
    var f = cap_factors(a);
    var q_prev = 0.0;
    var q = 1.0;
    var sum = 0.0;
    for (var l = 0u; l < n; l++) {
        let lf = f32(l);
        let k = cap_factor_next(&f, l);
        let y = sqrt((2.0 * lf + 1.0) / (4.0 * pi)) * q;
        sum = sum + col(9u + l, i) * (y * k);
        let q_next = ((2.0 * lf + 1.0) * z * q - lf * q_prev) / (lf + 1.0);
        q_prev = q;
        q = q_next;
    }
    return sum;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = batch_row(gid);
    if (i >= params.n) {
        return;
    }
    let n_hvl = u32(table[0]);
    let n_occ = u32(table[1]);
    let n = min(u32(table[2]), HVL_SUM_MAX_BANDS);
    let vis = table[3] != 0.0;
    let eps = table[4];
    let x = vec3<f32>(col(0u, i), col(1u, i), col(2u, i));
    let rn = vec3<f32>(col(3u, i), col(4u, i), col(5u, i));
    let o = vec3<f32>(col(6u, i), col(7u, i), col(8u, i));
    let pi = 3.14159265358979;
    // F′_0·Y_0^0 of `lambert_emission(1)`: 1/π.
    let e = 1.0 / pi;
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    for (var j = 0u; j < n_hvl; j++) {
        let at = 5u + 12u * j;
        let p = tv3(at);
        let hn = tv3(at + 3u);
        let radius = table[at + 6u];
        let power = table[at + 7u];
        let v = p - x;
        let d = sqrt(dot(v, v));
        if (!(d > 0.0) || d > 3.4028235e38) {
            continue;
        }
        let w = v / d;
        let cos_j = -dot(w, hn);
        if (cos_j <= 0.0) {
            continue;
        }
        let sa = min(radius / d, 1.0);
        let a = asin_acc(sa);
        let c = clamp(dot(w, rn), -1.0, 1.0);
        let t = clamp((a + asin_acc(c)) / (2.0 * a), 0.0, 1.0);
        let h = t * t * (3.0 - 2.0 * t);
        if (h == 0.0) {
            continue;
        }
        let s = zonal_cap_dot(c, a, n, i);
        let g = cos_j * h / (pi * radius * radius);
        let contrib = power * e * g * s;
        if (!(contrib > 0.0)) {
            continue;
        }
        if (vis) {
            let to = p - o;
            let dist = sqrt(dot(to, to));
            let dir = to / dist;
            var hit = false;
            let own = u32(table[at + 11u]);
            for (var k = 0u; k < n_occ; k++) {
                if (k != own && blocked(k, o, dir, dist * (1.0 - eps))) {
                    hit = true;
                    break;
                }
            }
            if (hit) {
                continue;
            }
        }
        acc = acc + contrib * tv3(at + 8u);
    }
    output[i] = acc.x;
    output[params.n + i] = acc.y;
    output[2u * params.n + i] = acc.z;
}
