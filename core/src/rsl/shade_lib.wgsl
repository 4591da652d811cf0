// steradian: what the two RSL shading kernels (shade.wgsl, shade_moments.wgsl) share, in
// `wgsl.rs` concatenated after sat_lib.wgsl and before the kernel: the table at binding 3
// with its common header words, the BRDF SAT boxes, the extended equal-area map, the
// point's inputs and the view's BRDF-table constants.

@group(0) @binding(3) var<storage, read> table: array<u32>;

const FRAC_1_SQRT_2: f32 = 0.7071067811865476;

// Header words common to both layouts (`wgsl::SHADE`, `wgsl::SHADE_MOMENTS`); word 4 is the
// side of the per-point maps, word 7 where they start.
const H_LIGHTS: u32 = 0u;
const H_GRID: u32 = 1u;
const H_POLAR: u32 = 2u;
const H_SMAX: u32 = 3u;
const H_MAP_N: u32 = 4u;
const H_OFF_LIGHTS: u32 = 5u;
const H_OFF_BRDF: u32 = 6u;
const H_OFF_MAPS: u32 = 7u;

fn tf(i: u32) -> f32 {
    return bitcast<f32>(table[i]);
}

fn tv3(i: u32) -> vec3<f32> {
    return vec3<f32>(tf(i), tf(i + 1u), tf(i + 2u));
}

// Box sum of BRDF table `k` (its exponent word, then its entries) over precomputed axes.
fn brdf_box(k: u32, w: u32, ax: Axis, ay: Axis) -> f32 {
    let w1 = w + 1u;
    let stride = 1u + 2u * w1 * w1;
    let t0 = table[H_OFF_BRDF] + k * stride;
    return sat_box_sum(t0 + 1u, bitcast<i32>(table[t0]), w, ax, ay);
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
    return vec2<f32>(1.4142135623730951, 0.0);
}

// One row of the input columns [tx, ty, tz, bx, by, bz, nx, ny, nz, wox, woy, woz, point].
struct ShadePoint {
    t: vec3<f32>,
    b: vec3<f32>,
    n: vec3<f32>,
    wo: vec3<f32>,
    point: u32,
}

fn shade_point(row: u32, n: u32) -> ShadePoint {
    return ShadePoint(
        vec3<f32>(input[row], input[n + row], input[2u * n + row]),
        vec3<f32>(input[3u * n + row], input[4u * n + row], input[5u * n + row]),
        vec3<f32>(input[6u * n + row], input[7u * n + row], input[8u * n + row]),
        vec3<f32>(input[9u * n + row], input[10u * n + row], input[11u * n + row]),
        u32(input[12u * n + row]),
    );
}

// The view's place among the isotropic BRDF SAT's polar tables (`BrdfSat::locate`): the
// lower table `k0`, the weight `tw` of the upper one, and the view azimuth's cosine and
// sine (`rc`, `rs`) by which squares turn. `wl` is the local view, above the horizon.
struct ViewTables {
    k0: u32,
    tw: f32,
    rc: f32,
    rs: f32,
}

fn view_tables(wl: vec3<f32>) -> ViewTables {
    let wn = wl / length(wl);
    let pv = wn.xy / sqrt(1.0 + wn.z);
    let s = sqrt(pv.x * pv.x + pv.y * pv.y);
    let m = table[H_POLAR];
    let x = clamp(s / tf(H_SMAX) * f32(m - 1u), 0.0, f32(m - 1u));
    let k0 = min(u32(x), m - 2u);
    var rc = 1.0;
    var rs = 0.0;
    if (s > 0.0) {
        rc = pv.x / s;
        rs = pv.y / s;
    }
    return ViewTables(k0, x - f32(k0), rc, rs);
}

// A light's centre `c` (world) in the parametrisation of the frame (t, b, n).
fn light_square_centre(c: vec3<f32>, sp: ShadePoint) -> vec2<f32> {
    let cl = vec3<f32>(dot(c, sp.t), dot(c, sp.b), dot(c, sp.n));
    return map_ext(cl / length(cl));
}
