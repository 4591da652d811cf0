// steradian: RSL shading of one point per invocation (mirrors `shade::shade` with an
// isotropic BRDF SAT and one VDT per point; see `wgsl::SHADE` for the layout).
// Input columns [tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz, vdt_index], output
// [r, g, b]. Specified for finite inputs only; see `steradian_core::wgsl`. The SAT box sums
// and the VDT query are those of sat_lib.wgsl and vdt_lib.wgsl (concatenated before this
// file by `wgsl.rs`).

@group(0) @binding(3) var<storage, read> table: array<u32>;

const FRAC_1_SQRT_2: f32 = 0.7071067811865476;

// Header words.
const H_LIGHTS: u32 = 0u;
const H_GRID: u32 = 1u;
const H_POLAR: u32 = 2u;
const H_SMAX: u32 = 3u;
const H_VDT_N: u32 = 4u;
const H_OFF_LIGHTS: u32 = 5u;
const H_OFF_BRDF: u32 = 6u;
const H_OFF_VDT: u32 = 7u;
const H_QUERY: u32 = 8u;

fn tf(i: u32) -> f32 {
    return bitcast<f32>(table[i]);
}

// Box sum of BRDF table `k` (its exponent word, then its entries) over precomputed axes.
fn sat_box(k: u32, w: u32, ax: Axis, ay: Axis) -> f32 {
    let w1 = w + 1u;
    let stride = 1u + 2u * w1 * w1;
    let t0 = table[H_OFF_BRDF] + k * stride;
    return sat_box_sum(t0 + 1u, bitcast<i32>(table[t0]), w, ax, ay);
}

fn vdt_table(at: u32) -> f32 {
    return tf(at);
}

// Visible fraction from the n×n VDT at word `base`, by eq. 9 or the gradient variant.
fn vdt_fraction(base: u32, n: u32, u: f32, v: f32, r: f32, gradient: bool) -> f32 {
    let c = vdt_cell(base, n, n, u, v);
    let d = vdt_distance(c);
    if (!gradient) {
        return vdt_eq9(d, r);
    }
    return vdt_edge(d, vdt_gradient(c), r);
}

// Extended equal-area map of a unit direction (`rsl::map_extended`).
fn map_ext(d: vec3<f32>) -> vec2<f32> {
    if (d.z >= 0.0) {
        return d.xy / sqrt(1.0 + d.z);
    }
    let s2 = d.x * d.x + d.y * d.y;
    if (s2 > 0.0) {
        return d.xy * (sqrt(1.0 - d.z) / sqrt(s2));
    }
    return vec2<f32>(SQRT_2, 0.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = batch_row(gid);
    let n = params.n;
    if (row >= n) {
        return;
    }
    let t = vec3<f32>(input[row], input[n + row], input[2u * n + row]);
    let b = vec3<f32>(input[3u * n + row], input[4u * n + row], input[5u * n + row]);
    let nn = vec3<f32>(input[6u * n + row], input[7u * n + row], input[8u * n + row]);
    let wo = vec3<f32>(input[9u * n + row], input[10u * n + row], input[11u * n + row]);
    let point = u32(input[12u * n + row]);
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    let wl = vec3<f32>(dot(wo, t), dot(wo, b), dot(wo, nn));
    if (wl.z > 0.0) {
        // View constants of the isotropic BRDF SAT (`BrdfSat::integral`).
        let wn = wl / length(wl);
        let pv = wn.xy / sqrt(1.0 + wn.z);
        let s = sqrt(pv.x * pv.x + pv.y * pv.y);
        let m = table[H_POLAR];
        let x = clamp(s / tf(H_SMAX) * f32(m - 1u), 0.0, f32(m - 1u));
        let k0 = min(u32(x), m - 2u);
        let tw = x - f32(k0);
        var rc = 1.0;
        var rs = 0.0;
        if (s > 0.0) {
            rc = pv.x / s;
            rs = pv.y / s;
        }
        let grid = table[H_GRID];
        let half_b = 0.5 * f32(grid);
        let vn = table[H_VDT_N];
        let half_v = 0.5 * f32(vn);
        let vbase = table[H_OFF_VDT] + point * vn * vn;
        let gradient = table[H_QUERY] != 0u;
        let nl = table[H_LIGHTS];
        let lo = table[H_OFF_LIGHTS];
        for (var i = 0u; i < nl; i = i + 1u) {
            let o = lo + 8u * i;
            let c = vec3<f32>(tf(o), tf(o + 1u), tf(o + 2u));
            let r = tf(o + 3u);
            let cl = vec3<f32>(dot(c, t), dot(c, b), dot(c, nn));
            let p = map_ext(cl / length(cl));
            if (length(p) - r >= 1.0) {
                continue;
            }
            let q = vec2<f32>(p.x * rc + p.y * rs, p.y * rc - p.x * rs);
            let tc = (q + vec2<f32>(1.0, 1.0)) * half_b;
            let h = r * half_b * FRAC_1_SQRT_2;
            let ax = sat_axis(tc.x - h, tc.x + h, grid);
            let ay = sat_axis(tc.y - h, tc.y + h, grid);
            let v0 = sat_box(k0, grid, ax, ay);
            let v1 = sat_box(k0 + 1u, grid, ax, ay);
            let rho = (v0 + tw * (v1 - v0)) * tf(o + 4u);
            let tv = (p + vec2<f32>(1.0, 1.0)) * half_v;
            let vis = vdt_fraction(vbase, vn, tv.x, tv.y, r * half_v, gradient);
            let f = rho * vis;
            acc = acc + vec3<f32>(tf(o + 5u), tf(o + 6u), tf(o + 7u)) * f;
        }
    }
    output[row] = acc.x;
    output[n + row] = acc.y;
    output[2u * n + row] = acc.z;
}
