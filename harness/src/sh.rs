//! SH studies shared by the report and the benches: the peers the evaluation is measured
//! against, a convention-free correctness check, the machine's multiply-add rate, and the
//! HVL test scene of the paper's Table 1 with its exact reference.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

use steradian_core::Vec3;
use steradian_core::sh::{brdf, hvl};
use steradian_reference::lobe::brdf::Model;
use steradian_reference::sh::hvl as href;

use crate::report::timing::timed;

// ---- Peers --------------------------------------------------------------------------------

/// The normalisation `√2^[m>0]·K_l^m` of the plain evaluation, `(l, m ≥ 0)` packed as
/// `l(l+1)/2 + m`, from `ln` factorials (what a renderer precomputes once).
pub fn plain_norms(bands: usize) -> Vec<f64> {
    let lnf = |k: usize| (2..=k).map(|i| (i as f64).ln()).sum::<f64>();
    let mut out = Vec::with_capacity(bands * (bands + 1) / 2);
    for l in 0..bands {
        for m in 0..=l {
            let k =
                ((2 * l + 1) as f64 / (4.0 * PI)).sqrt() * (0.5 * (lnf(l - m) - lnf(l + m))).exp();
            out.push(if m > 0 {
                std::f64::consts::SQRT_2 * k
            } else {
                k
            });
        }
    }
    out
}

/// The plain `f64` evaluation every renderer writes: `φ` from `atan2`, `cos mφ, sin mφ` by
/// angle addition, the unnormalised associated Legendre recurrence per `m`
/// (`P_m^m = (−1)^m(2m−1)!!·sin^mθ`, then the three-term recurrence in `l`), times the
/// precomputed [`plain_norms`]. O(n²) per direction.
pub fn plain_eval(d: [f64; 3], bands: usize, norms: &[f64], out: &mut [f64]) {
    let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let (x, y, z) = (d[0] / r, d[1] / r, d[2] / r);
    let phi = y.atan2(x);
    let s = (1.0 - z * z).max(0.0).sqrt();
    let (c1, s1) = (phi.cos(), phi.sin());
    let (mut cm, mut sm) = (1.0f64, 0.0f64);
    let mut pmm = 1.0f64;
    for m in 0..bands {
        if m > 0 {
            pmm *= -((2 * m - 1) as f64) * s;
            (cm, sm) = (cm * c1 - sm * s1, sm * c1 + cm * s1);
        }
        let (mut p2, mut p1) = (0.0f64, pmm);
        for l in m..bands {
            let p = if l == m {
                pmm
            } else if l == m + 1 {
                (2 * m + 1) as f64 * z * pmm
            } else {
                ((2 * l - 1) as f64 * z * p1 - (l + m - 1) as f64 * p2) / (l - m) as f64
            };
            if l > m {
                (p2, p1) = (p1, p);
            }
            let k = norms[l * (l + 1) / 2 + m] * p;
            let c = l * l + l;
            if m == 0 {
                out[c] = k;
            } else {
                out[c + m] = k * cm;
                out[c - m] = k * sm;
            }
        }
    }
}

/// The largest relative departure from the addition theorem,
/// `max_l |Σ_m Y_l^m(ω)² − (2l+1)/(4π)| / ((2l+1)/(4π))`: zero for every orthonormal real
/// basis of each band whatever its sign and ordering conventions, so it checks peers that
/// use other conventions.
pub fn band_identity_error(values: &[f64], bands: usize) -> f64 {
    (0..bands)
        .map(|l| {
            let want = (2 * l + 1) as f64 / (4.0 * PI);
            let got: f64 = values[l * l..(l + 1) * (l + 1)].iter().map(|v| v * v).sum();
            ((got - want) / want).abs()
        })
        .fold(0.0, f64::max)
}

/// `sphrs` 0.2.2's real SH set of `bands` bands at `d` (its own ordering and phase).
pub fn sphrs_eval(set: &sphrs::HarmonicsSet<f64, sphrs::RealSH>, d: [f64; 3]) -> Vec<f64> {
    set.eval(&sphrs::Coordinates::cartesian(d[0], d[1], d[2]))
}

/// `sphrs`' set of `bands` bands.
pub fn sphrs_set(bands: usize) -> sphrs::HarmonicsSet<f64, sphrs::RealSH> {
    sphrs::HarmonicsSet::new(bands.saturating_sub(1), sphrs::RealSH::Spherical)
}

/// Multiply–add pairs per nanosecond (counted per lane) of this binary on this machine on
/// the SIMD evaluation's `f64` lanes (`wide::f64x8` where the build enables AVX-512F,
/// `f64x4` otherwise: `steradian_simd::sh::SLICE_LANES`): eight independent `a = a·b + c`
/// chains (median of five runs after a warm-up), a multiply and an add, not a fused
/// multiply-add (the SH recurrence compiles to those). The one-lane rate is that divided by
/// the lane count: the same execution units run both, and a scalar loop cannot be timed on
/// its own, because the compiler packs independent scalar chains into vectors.
pub fn mul_add_rate() -> f64 {
    // The lanes of the SIMD evaluation (`steradian_simd::sh::SLICE_LANES`).
    macro_rules! rate {
        ($t:ident, $n:literal) => {{
            use wide::$t;
            let iters = 20_000_000u64;
            let lanes = || {
                let mut a: [$t; 8] = std::array::from_fn(|k| $t::splat(1.0 + 0.1 * k as f64));
                let (b, c) = (
                    $t::splat(black_box(0.999_999_9f64)),
                    $t::splat(black_box(1e-9f64)),
                );
                for _ in 0..iters / (8 * $n) {
                    for v in a.iter_mut() {
                        *v = *v * b + c;
                    }
                }
                black_box(a);
            };
            let t = crate::report::timing::median_time(5, lanes);
            iters as f64 / (t.as_secs_f64() * 1e9)
        }};
    }
    if steradian_simd::sh::SLICE_LANES == 8 {
        rate!(f64x8, 8)
    } else {
        rate!(f64x4, 4)
    }
}

/// The input rows of `wgsl::SH_HVL`, one per HVL: centre, its frame's tangent, bitangent
/// and normal, radius, power.
pub fn hvl_gpu_rows(hvls: &[hvl::Hvl]) -> Vec<[f32; 14]> {
    hvls.iter()
        .map(|h| {
            let f = h.frame();
            let (t, b, n) = (f.to_world(Vec3::X), f.to_world(Vec3::Y), f.normal());
            let p = h.position();
            [
                p.x,
                p.y,
                p.z,
                t.x,
                t.y,
                t.z,
                b.x,
                b.y,
                b.z,
                n.x,
                n.y,
                n.z,
                h.radius(),
                h.power(),
            ]
        })
        .collect()
}

/// The table of `wgsl::SH_HVL` for the receiver `rx` and the HVLs' emission `F′`:
/// `[n, n_e, point, frame tangent, bitangent, normal, F, F′]` (a count that is not a square
/// gives 0 bands).
pub fn hvl_gpu_table(rx: &hvl::Receiver<'_>, emission: &[f32]) -> Vec<f32> {
    let bands = |len: usize| steradian_core::sh::bands_of(len).map_or(0.0, |n| n as f32);
    let f = &rx.frame;
    let mut table = vec![bands(rx.coeffs.len()), bands(emission.len())];
    for q in [
        rx.point,
        f.to_world(Vec3::X),
        f.to_world(Vec3::Y),
        f.normal(),
    ] {
        table.extend([q.x, q.y, q.z]);
    }
    table.extend(rx.coeffs);
    table.extend(emission);
    table
}

// ---- The HVL scene of Table 1 -------------------------------------------------------------

/// A spot light above a floor lighting `M = side²` HVLs placed by a square reflective shadow
/// map, and receivers on a wall beside them.
pub struct HvlScene {
    /// The core HVLs.
    pub hvls: Vec<hvl::Hvl>,
    /// Their f64 twins for the reference.
    pub lights: Vec<href::Light>,
    /// Receiver points (on the wall `x = 1.2`, normal `−x`).
    pub points: Vec<[f64; 3]>,
    /// The receivers' normal.
    pub normal: [f64; 3],
    /// The eye the receivers are seen from.
    pub eye: [f64; 3],
}

/// Spot at `(0, 0, 3)` pointing down, field of view 90°, intensity 10 W/sr; the floor
/// `z = 0` of albedo 0.8 (Lambertian HVLs); the radius `r2` of eq. 25 with `k = 1`; 48
/// receivers on the wall `x = 1.2`.
pub fn hvl_scene(side: usize) -> HvlScene {
    let (spot, intensity, fov) = ([0.0f64, 0.0, 3.0], 10.0f64, PI / 2.0);
    let m = (side * side) as u32;
    let half = (0.5 * fov).tan();
    let du = 2.0 * half / side as f64;
    let mut hvls = Vec::new();
    let mut lights = Vec::new();
    for i in 0..side {
        for j in 0..side {
            let (u, v) = (-half + (i as f64 + 0.5) * du, -half + (j as f64 + 0.5) * du);
            let len = (u * u + v * v + 1.0).sqrt();
            let dir = [u / len, v / len, -1.0 / len];
            // Solid angle of the pixel on the image plane at distance 1: du²·cos³θ.
            let omega = du * du / (len * len * len);
            let t = spot[2] / -dir[2];
            let p = [spot[0] + t * dir[0], spot[1] + t * dir[1], 0.0];
            let power = intensity * omega;
            let radius = hvl::radius_from_fov(t as f32, fov as f32, m, 1.0) as f64;
            let to_light = dir.map(|c| -c);
            let model = Model::Lambert { a: 0.8 };
            let v3 = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
            hvls.push(
                hvl::Hvl::new(v3(p), Vec3::Z, v3(to_light), radius as f32, power as f32)
                    .expect("valid scene"),
            );
            lights.push(href::Light {
                position: p,
                normal: [0.0, 0.0, 1.0],
                to_light,
                radius,
                power,
                model,
            });
        }
    }
    let mut points = Vec::new();
    for a in 0..8 {
        for b in 0..6 {
            points.push([
                1.2,
                -1.0 + 2.0 * (a as f64 + 0.5) / 8.0,
                0.05 + 1.4 * (b as f64 + 0.5) / 6.0,
            ]);
        }
    }
    HvlScene {
        hvls,
        lights,
        points,
        normal: [-1.0, 0.0, 0.0],
        eye: [-3.0, 0.3, 1.2],
    }
}

/// One receiver's material for the study: a core BRDF table and its f64 model.
pub struct Material {
    /// Name for the report.
    pub name: &'static str,
    /// The core table.
    pub table: brdf::BrdfSh<'static>,
    /// The model.
    pub model: Model,
}

/// Bands of the study's Lambert table: Table 1's largest band limit. The committed Lambert
/// table has the 5 bands its 5 % target needs, which would make Table 1's Lambert rows at
/// 7 and 9 bands repeat its 5-band figure.
pub const LAMBERT_BANDS: usize = 9;

/// The study's Lambert table: [`LAMBERT_BANDS`] bands over 16 views (`F` of a Lambertian
/// BRDF does not depend on the view), generated once per process.
fn lambert_table() -> brdf::BrdfSh<'static> {
    static BYTES: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    let bytes = BYTES.get_or_init(|| {
        crate::generate::brdf_sh::table(&Model::Lambert { a: 1.0 }, LAMBERT_BANDS, 16)
    });
    brdf::BrdfSh::from_bytes(bytes).expect("a generated table reads back")
}

/// The two receivers of the study: Lambert (a table of [`LAMBERT_BANDS`] bands) and Phong
/// 30 (the committed table).
pub fn materials() -> [Material; 2] {
    [
        Material {
            name: "Lambert",
            table: lambert_table(),
            model: Model::Lambert { a: 1.0 },
        },
        Material {
            name: "Phong 30",
            table: brdf::phong(),
            model: Model::Phong {
                kd: 0.0,
                ks: 1.0,
                e: 30.0,
            },
        },
    ]
}

/// The shading of every receiver of `scene` by all its HVLs at `bands` bands (at most the
/// table's), and the time it took.
pub fn shade(scene: &HvlScene, mat: &Material, bands: usize) -> (Vec<f64>, Duration) {
    shade_with(scene, mat, bands, hvl::Horizon::Smoothstep)
}

/// [`shade`] with the horizon term `horizon` (the paper's smoothstep `H`, or the exact
/// fraction of the cap above the receiver's horizon).
pub fn shade_with(
    scene: &HvlScene,
    mat: &Material,
    bands: usize,
    horizon: hvl::Horizon,
) -> (Vec<f64>, Duration) {
    let n = bands.min(mat.table.bands());
    let em = hvl::lambert_emission(0.8);
    let v3 = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
    // The per-point setup (frame, table lookup) is part of the cost.
    let (out, t) = timed(|| {
        let mut coeffs = vec![0.0f32; n * n];
        let mut scratch = vec![0.0f32; n.max(1) * n.max(1)];
        scene
            .points
            .iter()
            .map(|&p| {
                let wo = v3([
                    scene.eye[0] - p[0],
                    scene.eye[1] - p[1],
                    scene.eye[2] - p[2],
                ])
                .normalize();
                let frame = brdf::view_frame(v3(scene.normal), wo).expect("unit normal");
                let theta = frame.to_local(wo).z.clamp(-1.0, 1.0).acos();
                mat.table
                    .lookup_into(brdf::Part::WithCosine, theta, n, &mut coeffs)
                    .expect("bands within the table");
                let rx = hvl::Receiver {
                    point: v3(p),
                    frame,
                    coeffs: &coeffs,
                };
                scene
                    .hvls
                    .iter()
                    .map(|h| {
                        f64::from(
                            hvl::contribution(h, &em, &rx, horizon, &mut scratch).expect("shapes"),
                        )
                    })
                    .sum::<f64>()
            })
            .collect::<Vec<f64>>()
    });
    (out, t)
}

/// The exact shading of every receiver (module docs of `steradian_reference::sh::hvl`).
pub fn shade_exact(scene: &HvlScene, model: &Model) -> Vec<f64> {
    scene
        .points
        .iter()
        .map(|&p| {
            let wo = {
                let v = [
                    scene.eye[0] - p[0],
                    scene.eye[1] - p[1],
                    scene.eye[2] - p[2],
                ];
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v.map(|c| c / l)
            };
            scene
                .lights
                .iter()
                .map(|l| href::contribution(l, p, scene.normal, wo, model, 12))
                .sum()
        })
        .collect()
}

/// Relative RMS error of `got` against `want`.
pub fn rel_rms(got: &[f64], want: &[f64]) -> f64 {
    let num: f64 = got.iter().zip(want).map(|(g, w)| (g - w).powi(2)).sum();
    let den: f64 = want.iter().map(|w| w * w).sum();
    (num / den.max(1e-300)).sqrt()
}

/// Evaluation throughput helpers: `dirs` random directions as `f32`.
pub fn directions(count: usize, seed: u64) -> Vec<[f32; 3]> {
    let mut rng = crate::rng::Rng::new(seed);
    (0..count).map(|_| rng.sphere().map(|c| c as f32)).collect()
}
