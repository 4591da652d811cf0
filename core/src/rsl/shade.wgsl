// steradian: RSL shading of one point per invocation (mirrors `shade::shade` with an
// isotropic BRDF SAT and one VDT per point; see `wgsl::SHADE` for the layout).
// Input columns [tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz, vdt_index], output
// [r, g, b]. Specified for finite inputs only; see `steradian_core::wgsl`. The SAT box sums,
// the VDT query and the shared shading pieces are those of sat_lib.wgsl, vdt_lib.wgsl and
// shade_lib.wgsl (concatenated before this file by `wgsl.rs`).

// Header word after the common ones of shade_lib.wgsl.
const H_QUERY: u32 = 8u;

fn vdt_table(at: u32) -> f32 {
    return tf(at);
}

// Visible fraction from the n×n VDT at word `base`, by eq. 9 or the straight-edge variant
// (`shade::VdtVisibility`).
fn vdt_fraction(base: u32, n: u32, u: f32, v: f32, r: f32, gradient: bool) -> f32 {
    if (!gradient) {
        return vdt_eq9(vdt_distance(vdt_cell(base, n, n, u, v)), r);
    }
    return vdt_straight_edge(base, n, n, u, v, r);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let row = batch_row(gid);
    let n = params.n;
    if (row >= n) {
        return;
    }
    let sp = shade_point(row, n);
    var acc = vec3<f32>(0.0, 0.0, 0.0);
    let wl = vec3<f32>(dot(sp.wo, sp.t), dot(sp.wo, sp.b), dot(sp.wo, sp.n));
    if (wl.z > 0.0) {
        let vt = view_tables(wl);
        let grid = table[H_GRID];
        let half_b = 0.5 * f32(grid);
        let vn = table[H_MAP_N];
        let half_v = 0.5 * f32(vn);
        let vbase = table[H_OFF_MAPS] + sp.point * vn * vn;
        let gradient = table[H_QUERY] != 0u;
        let nl = table[H_LIGHTS];
        let lo = table[H_OFF_LIGHTS];
        for (var i = 0u; i < nl; i = i + 1u) {
            let o = lo + 8u * i;
            let r = tf(o + 3u);
            let p = light_square_centre(tv3(o), sp);
            if (length(p) - r >= 1.0) {
                continue;
            }
            let q = vec2<f32>(p.x * vt.rc + p.y * vt.rs, p.y * vt.rc - p.x * vt.rs);
            let tc = (q + vec2<f32>(1.0, 1.0)) * half_b;
            let h = r * half_b * FRAC_1_SQRT_2;
            let ax = sat_axis(tc.x - h, tc.x + h, grid);
            let ay = sat_axis(tc.y - h, tc.y + h, grid);
            let v0 = brdf_box(vt.k0, grid, ax, ay);
            let v1 = brdf_box(vt.k0 + 1u, grid, ax, ay);
            let rho = (v0 + vt.tw * (v1 - v0)) * tf(o + 4u);
            let tv = (p + vec2<f32>(1.0, 1.0)) * half_v;
            let vis = vdt_fraction(vbase, vn, tv.x, tv.y, r * half_v, gradient);
            acc = acc + tv3(o + 5u) * (rho * vis);
        }
    }
    output[row] = acc.x;
    output[n + row] = acc.y;
    output[2u * n + row] = acc.z;
}
