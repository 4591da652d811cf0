//! Environment maps (cube maps, .hdr/.exr loading, the default sky), their decomposition
//! into rotatable square lights, and the RSL projection into a local hemisphere
//! parametrisation.

#![allow(clippy::needless_range_loop)] // RGB channels are indexed in parallel arrays

use std::collections::VecDeque;
use std::f64::consts::PI;

use glam::{DVec2, DVec3, Vec3};
use steradian_core::frame::Frame;
use steradian_core::rsl::{self, Rsl};
use steradian_harness::env::decompose::{
    Decomposition, Objective, Options, bound_cost, decompose, decompose_rescan, fit_region,
};
use steradian_harness::env::{self, CubeMap, EnvError, Equirect, Sky};
use steradian_harness::rng::Rng;

fn real() -> CubeMap {
    env::load_cubemap(&env::real_env_path(), 32).expect("harness/data/sky.exr")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// A random environment with smooth variation and a few hot spots (no ties in the fit).
fn random_env(n: usize, seed: u64) -> CubeMap {
    let mut rng = Rng::new(seed);
    let spots: Vec<(DVec3, f64, f64)> = (0..4)
        .map(|_| {
            let s = rng.sphere();
            (
                DVec3::from_array(s),
                rng.log_range(20.0, 400.0),
                rng.range(1.0, 30.0),
            )
        })
        .collect();
    CubeMap::from_fn(n, 2, |d| {
        let mut l = 0.3 + 0.2 * d.x + 0.1 * d.y * d.z + 0.25;
        for (a, lam, e) in &spots {
            l += e * (lam * (d.dot(*a) - 1.0)).exp();
        }
        [l, 0.8 * l, 0.6 * l]
    })
    .unwrap()
}

#[test]
fn cube_texel_solid_angles_sum_to_four_pi() {
    for n in [1, 2, 7, 32] {
        let c = CubeMap::new(n, vec![[1.0; 3]; 6 * n * n]).unwrap();
        let s: f64 = c.solid_angles().iter().sum();
        assert!(rel(s, 4.0 * PI) < 1e-13, "n = {n}: {s}");
        assert!(c.solid_angles().iter().all(|&w| w > 0.0));
    }
}

#[test]
fn cube_neighbours_are_symmetric_and_adjacent() {
    let c = CubeMap::new(8, vec![[0.0; 3]; 6 * 64]).unwrap();
    // the widest texels are at the face centres: atan(2/n)
    let texel = (2.0f64 / 8.0).atan();
    for k in 0..c.len() {
        assert_eq!(c.dir_to_texel(c.dirs()[k]), k);
        for nb in c.neighbours(k) {
            assert_ne!(nb, k);
            let ang = c.dirs()[k].angle_between(c.dirs()[nb]);
            assert!(ang < 1.01 * texel, "{k} → {nb}: {ang}");
            // Symmetric except at the cube corners, where three faces meet.
            let (_, i, j) = c.unflatten(k);
            let corner = (i == 0 || i == 7) && (j == 0 || j == 7);
            assert!(corner || c.neighbours(nb).contains(&k), "{k} ↔ {nb}");
        }
    }
}

#[test]
fn resampling_conserves_the_integral_of_a_constant() {
    let eq = Equirect::new(64, 32, vec![[2.5, 1.0, 0.0]; 64 * 32]).unwrap();
    assert!(rel(eq.integral()[0], 2.5 * 4.0 * PI) < 1e-13);
    let cube = eq.to_cubemap(32).unwrap();
    let i = cube.integral();
    assert!(rel(i[0], 2.5 * 4.0 * PI) < 1e-12, "{i:?}");
    assert!(rel(i[1], 4.0 * PI) < 1e-12, "{i:?}");
    assert_eq!(i[2], 0.0);
    let f = CubeMap::from_fn(16, 3, |_| [0.7; 3]).unwrap();
    assert!(rel(f.integral()[0], 0.7f32 as f64 * 4.0 * PI) < 1e-12);
    // every texel is the constant itself (f32 rounding)
    assert!(cube.texels().iter().all(|t| (t[0] - 2.5).abs() < 1e-6));
}

#[test]
fn resampling_conserves_the_integral_of_an_analytic_environment() {
    // L = 1 + 0.5x + 0.3z² + exp(λ(d·a − 1)), exact ∫ = 4π + 0.3·4π/3 + 2π(1 − e^(−2λ))/λ.
    let a = DVec3::new(0.3, -0.5, 0.6).normalize();
    let lam = 40.0;
    let f = |d: DVec3| 1.0 + 0.5 * d.x + 0.3 * d.z * d.z + (lam * (d.dot(a) - 1.0)).exp();
    let exact = 4.0 * PI + 0.4 * PI + 2.0 * PI * (-(-2.0 * lam).exp_m1()) / lam;
    // Directly as a cube map (box filter, exact sub-texel solid angles).
    let cube = CubeMap::from_fn(32, 4, |d| [f(d); 3]).unwrap();
    let e1 = rel(cube.integral()[0], exact);
    // Through an equirectangular image of pixel-centre samples.
    let (w, h) = (512, 256);
    let mut px = Vec::with_capacity(w * h);
    for y in 0..h {
        let th = PI * (y as f64 + 0.5) / h as f64;
        for x in 0..w {
            let ph = 2.0 * PI * (x as f64 + 0.5) / w as f64;
            let d = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            px.push([f(d) as f32; 3]);
        }
    }
    let eq = Equirect::new(w, h, px).unwrap();
    let e2 = rel(eq.integral()[0], exact);
    let e3 = rel(eq.to_cubemap(32).unwrap().integral()[0], exact);
    println!(
        "relative integral errors: from_fn {e1:.2e}, equirect {e2:.2e}, equirect → cube {e3:.2e}"
    );
    assert!(e1 < 2e-6, "{e1}");
    assert!(e2 < 1e-5, "{e2}");
    assert!(e3 < 1e-5, "{e3}");
}

#[test]
fn default_sky_cubemap_matches_its_analytic_integral() {
    let sky = Sky::default();
    let cube = sky.cubemap(32).unwrap();
    let (got, exact) = (cube.integral(), sky.integral());
    for c in 0..3 {
        let e = rel(got[c], exact[c]);
        assert!(
            e < 1e-5,
            "channel {c}: {} vs {} ({e:.2e})",
            got[c],
            exact[c]
        );
    }
    // the sun is the brightest texel and sits where it should
    let (kmax, _) = (0..cube.len())
        .map(|k| (k, cube.luminance(k)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert_eq!(kmax, cube.dir_to_texel(sky.sun_dir));
}

#[test]
fn loads_the_real_exr_and_a_hdr_written_from_it() {
    let path = env::real_env_path();
    let eq = Equirect::load(&path).unwrap();
    assert_eq!((eq.width(), eq.height()), (512, 256));
    let i = eq.integral();
    assert!(i.iter().all(|v| v.is_finite() && *v > 1.0), "{i:?}");
    // Resampling keeps the energy (bilinear reconstruction; measured 3.7e-4).
    let cube = eq.to_cubemap(32).unwrap();
    for c in 0..3 {
        let e = rel(cube.integral()[c], i[c]);
        assert!(e < 1e-3, "resampling the real sky, channel {c}: {e:.2e}");
    }
    // Radiance .hdr: write the same image (RGBE, 8-bit mantissas) and read it back.
    let dir = std::env::temp_dir().join(format!("steradian-env-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let hdr = dir.join("sky.hdr");
    let buf = image::Rgb32FImage::from_fn(eq.width() as u32, eq.height() as u32, |x, y| {
        image::Rgb(eq.data()[y as usize * eq.width() + x as usize])
    });
    image::DynamicImage::ImageRgb32F(buf).save(&hdr).unwrap();
    let back = Equirect::load(&hdr).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!((back.width(), back.height()), (512, 256));
    for (a, b) in eq.data().iter().zip(back.data()) {
        let m = a.iter().fold(0f32, |m, v| m.max(*v));
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() <= m / 128.0 + 1e-30, "{a:?} {b:?}");
        }
    }
    for c in 0..3 {
        assert!(rel(back.integral()[c], i[c]) < 1e-2);
    }
    // The three files of the shared data set, where it is present (CI has it beside the
    // repository).
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/hdri");
    if shared.is_dir() {
        for name in ["city.exr", "sky.exr", "studio.exr"] {
            let c = env::load_cubemap(&shared.join(name), 16).unwrap();
            assert!(c.integral().iter().all(|v| *v > 0.0), "{name}");
        }
    } else {
        println!(
            "{} absent: only the committed copy tested",
            shared.display()
        );
    }
}

#[test]
fn rejects_bad_environments() {
    assert!(matches!(
        Equirect::load(std::path::Path::new("/nonexistent/x.exr")),
        Err(EnvError::Io(_))
    ));
    let mut px = vec![[1.0f32; 3]; 8];
    px[3][1] = f32::NAN;
    assert!(Equirect::new(4, 2, px).is_err());
    assert!(Equirect::new(4, 2, vec![[1.0; 3]; 7]).is_err());
    // negatives clamp to zero
    let e = Equirect::new(2, 1, vec![[-1.0, 1.0, 0.0]; 2]).unwrap();
    assert_eq!(e.data()[0], [0.0, 1.0, 0.0]);
    assert!(CubeMap::new(0, vec![]).is_err());
    assert!(CubeMap::new(2, vec![[1.0; 3]; 23]).is_err());
    assert!(CubeMap::new(1, vec![[1.0, f32::INFINITY, 0.0]; 6]).is_err());
    assert!(CubeMap::new(1, vec![[1.0, -1.0, 0.0]; 6]).is_err());
    let cube = random_env(4, 1);
    for ks in [vec![], vec![0], vec![97]] {
        assert!(decompose(&cube, &Options::quiet(&ks)).is_err(), "{ks:?}");
    }
    let same_face = Options {
        cross_face: false,
        ..Options::quiet(&[5])
    };
    assert!(decompose(&cube, &same_face).is_err());
}

fn check_partition(cube: &CubeMap, d: &Decomposition) {
    let mut seen = vec![0u32; cube.len()];
    for (ri, r) in d.regions.iter().enumerate() {
        assert!(!r.texels.is_empty());
        assert!(r.texels.windows(2).all(|w| w[0] < w[1]), "ascending");
        for &t in &r.texels {
            seen[t as usize] += 1;
            assert_eq!(d.region_of[t as usize], ri as u32);
        }
        // connected through texel edges
        let inside: std::collections::HashSet<u32> = r.texels.iter().copied().collect();
        let mut reached = std::collections::HashSet::from([r.texels[0]]);
        let mut q = VecDeque::from([r.texels[0]]);
        while let Some(t) = q.pop_front() {
            for nb in cube.neighbours(t as usize) {
                let nb = nb as u32;
                if inside.contains(&nb) && reached.insert(nb) {
                    q.push_back(nb);
                }
            }
            // corner texels: the neighbour relation is made symmetric by the decomposition
            for &o in &r.texels {
                if !reached.contains(&o) && cube.neighbours(o as usize).contains(&(t as usize)) {
                    reached.insert(o);
                    q.push_back(o);
                }
            }
        }
        assert_eq!(reached.len(), r.texels.len(), "region {ri} is connected");
    }
    assert!(
        seen.iter().all(|&s| s == 1),
        "every texel in exactly one region"
    );
}

#[test]
fn every_texel_in_exactly_one_connected_region() {
    let cube = env::default_sky(16).unwrap();
    for d in decompose(&cube, &Options::quiet(&[100, 30, 10])).unwrap() {
        check_partition(&cube, &d);
    }
    let same_face = Options {
        ks: vec![12],
        cross_face: false,
        progress: false,
        objective: Objective::Bound,
    };
    let d = &decompose(&cube, &same_face).unwrap()[0];
    check_partition(&cube, d);
    let per_face = 16 * 16;
    for r in &d.regions {
        let f = r.texels[0] / per_face;
        assert!(r.texels.iter().all(|t| t / per_face == f), "same-face rule");
    }
}

#[test]
fn k_is_respected() {
    let cube = random_env(8, 3);
    let ks = [384, 383, 100, 37, 10, 2, 1];
    let ds = decompose(&cube, &Options::quiet(&ks)).unwrap();
    assert_eq!(ds.len(), ks.len());
    for (d, k) in ds.iter().zip(ks) {
        assert_eq!(d.k, k);
        assert_eq!(d.regions.len(), k);
        assert!(d.rsls().unwrap().len() == k);
    }
    // the partitions are nested: every region at a smaller K is a union of larger-K ones
    for w in ds.windows(2) {
        for r in &w[0].regions {
            let outer = w[1].region_of[r.texels[0] as usize];
            assert!(
                r.texels
                    .iter()
                    .all(|&t| w[1].region_of[t as usize] == outer)
            );
        }
    }
}

#[test]
fn decomposition_preserves_total_energy() {
    for (name, cube) in [
        ("default sky", env::default_sky(32).unwrap()),
        ("real", real()),
    ] {
        let total = cube.integral();
        for d in decompose(&cube, &Options::quiet(&[100, 60, 30, 10])).unwrap() {
            let mut sum = [0.0f64; 3];
            let mut sum32 = [0.0f64; 3];
            for (r, l) in d.regions.iter().zip(d.rsls().unwrap()) {
                for c in 0..3 {
                    sum[c] += r.energy[c];
                    sum32[c] += l.energy()[c] as f64;
                }
            }
            for c in 0..3 {
                assert!(
                    rel(sum[c], total[c]) < 1e-12,
                    "{name} K={} channel {c}",
                    d.k
                );
                assert!(
                    rel(sum32[c], total[c]) < 1e-6,
                    "{name} K={} f32 channel {c}",
                    d.k
                );
            }
        }
    }
}

#[test]
fn decomposition_is_deterministic() {
    let cube = real();
    let a = decompose(&cube, &Options::quiet(&[30, 10])).unwrap();
    let b = decompose(&cube, &Options::quiet(&[30, 10])).unwrap();
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.region_of, y.region_of);
        for (r, s) in x.regions.iter().zip(&y.regions) {
            assert_eq!(r.fit, s.fit, "bit-identical fits");
            assert_eq!(r.energy, s.energy);
        }
    }
}

#[test]
fn priority_queue_matches_the_figure_5_rescan() {
    for (cube, k, cross) in [
        (random_env(6, 11), 10, true),
        (random_env(6, 12), 20, false),
        (env::default_sky(6).unwrap(), 8, true),
        // a constant environment: every merge ties, broken by the smallest texels
        (CubeMap::new(4, vec![[1.0; 3]; 96]).unwrap(), 9, true),
    ] {
        for objective in [Objective::Paper, Objective::Bound] {
            let o = Options {
                cross_face: cross,
                objective,
                ..Options::quiet(&[k])
            };
            let fast = &decompose(&cube, &o).unwrap()[0];
            let slow = decompose_rescan(&cube, k, cross, objective).unwrap();
            assert_eq!(
                fast.region_of, slow.region_of,
                "{objective:?}: K = {k}, cross = {cross}"
            );
        }
    }
}

#[test]
fn fit_error_decreases_with_k() {
    for (name, cube) in [
        ("default sky", env::default_sky(32).unwrap()),
        ("real", real()),
    ] {
        for objective in [Objective::Paper, Objective::Bound] {
            let o = Options {
                objective,
                ..Options::quiet(&[100, 60, 30, 10])
            };
            let ds = decompose(&cube, &o).unwrap();
            let pw: Vec<f64> = ds.iter().map(|d| d.piecewise_rel_l2(&cube)).collect();
            let eta: Vec<f64> = ds.iter().map(|d| d.rsl_rel_l2()).collect();
            // The summed objective that the merge minimises.
            let obj: Vec<f64> = ds
                .iter()
                .map(|d| match objective {
                    Objective::Paper => d.objective(),
                    Objective::Bound => d.bound(),
                })
                .collect();
            println!(
                "{name} {objective:?}: K = 100, 60, 30, 10: piecewise {pw:.5?}, RSL η {eta:.5?}, objective {obj:.3?}"
            );
            for w in pw.windows(2) {
                assert!(
                    w[0] < w[1],
                    "{name}: piecewise-constant error must drop with K: {pw:?}"
                );
            }
            for w in eta.windows(2) {
                assert!(
                    w[0] < w[1],
                    "{name}: RSL fitting error must drop with K: {eta:?}"
                );
            }
            for w in obj.windows(2) {
                assert!(
                    w[0] < w[1],
                    "{name}: total objective must drop with K: {obj:?}"
                );
            }
        }
    }
}

#[test]
fn decomposition_of_6x32x32_takes_seconds() {
    // A regression guard, not a benchmark (the report times it): the paper needs about two
    // minutes; a rescan per merge would need hours at this size.
    let cube = env::default_sky(32).unwrap();
    let t = std::time::Instant::now();
    let ds = decompose(&cube, &Options::quiet(&[10])).unwrap();
    let s = t.elapsed().as_secs_f64();
    println!("6 × 32 × 32 → 10 RSLs in {s:.2} s");
    assert_eq!(ds[0].regions.len(), 10);
    assert!(s < 20.0, "{s} s");
}

#[test]
fn fit_of_simple_regions() {
    let cube = CubeMap::new(16, vec![[1.0; 3]; 6 * 256]).unwrap();
    // one texel: the square is the texel's solid angle, centred on it, error ~ 0
    let k = (4 * 16 + 5) * 16 + 7;
    let f = fit_region(&cube, &[k as u32]);
    assert!(f.centre.angle_between(cube.dirs()[k]) < 1e-12);
    assert!(rel(f.solid_angle, cube.solid_angles()[k]) < 1e-9, "{f:?}");
    assert!(f.eta2 < 1e-3 * cube.solid_angles()[k]);
    // a 6 × 6 block at the face centre: square of about the block's solid angle, centred
    let block: Vec<u32> = (5..11)
        .flat_map(|j| (5..11).map(move |i| ((4 * 16 + j) * 16 + i) as u32))
        .collect();
    let s: f64 = block.iter().map(|&t| cube.solid_angles()[t as usize]).sum();
    let f = fit_region(&cube, &block);
    assert!(f.centre.angle_between(DVec3::Z) < 1e-9);
    assert!(rel(f.solid_angle, s) < 0.1, "{} vs {s}", f.solid_angle);
    // a uniform square fitted by a rotatable square: the error is the rotation average of
    // the square-vs-rotated-square mismatch, (0 + 0.2 + 0.34 + 0.2)/4 ≈ 0.19 of Q = s for
    // exact squares, a little more on texels
    assert!(f.eta2 > 0.15 * s && f.eta2 < 0.3 * s, "{} vs {s}", f.eta2);
    assert_eq!(f.rotation, 0.0, "axis-aligned block prefers θ = 0");
    assert!(f.tangent.dot(f.centre).abs() < 1e-12);
    // a uniform 1 × 12 strip fits worse per unit area than the block
    let strip: Vec<u32> = (2..14).map(|i| ((4 * 16 + 8) * 16 + i) as u32).collect();
    let ss: f64 = strip.iter().map(|&t| cube.solid_angles()[t as usize]).sum();
    let g = fit_region(&cube, &strip);
    assert!(g.eta2 / ss > f.eta2 / s);
}

#[test]
fn regions_expose_what_shading_needs() {
    let cube = env::default_sky(32).unwrap();
    let sky = Sky::default();
    let d = &decompose(&cube, &Options::quiet(&[30])).unwrap()[0];
    let rsls = d.rsls().unwrap();
    let sun_texel = cube.dir_to_texel(sky.sun_dir);
    let sun_region = d.region_of[sun_texel] as usize;
    for (r, l) in d.regions.iter().zip(&rsls) {
        assert!((l.centre().length() - 1.0).abs() < 1e-6);
        assert!(l.tangent().dot(l.centre()).abs() < 1e-6);
        assert!(l.solid_angle() > 0.0);
        for c in 0..3 {
            assert!(rel(l.energy()[c] as f64, r.energy[c]) < 1e-6);
        }
        // the square's solid angle is of the order of the region's
        let ratio = r.fit.solid_angle / r.solid_angle;
        assert!((0.2..5.0).contains(&ratio), "Ω/|S| = {ratio}");
    }
    // the sun gets a small light of its own, centred on the sun
    let s = &d.regions[sun_region];
    assert!(s.solid_angle < 0.01, "sun region {} sr", s.solid_angle);
    assert!(
        rsls[sun_region]
            .centre()
            .as_dvec3()
            .angle_between(sky.sun_dir)
            < 0.02
    );
}

// ---------- the RSL projection into a local parametrisation (core::rsl) ----------

/// Extended inverse of the equal-area map, `|p| ≤ √2`.
fn unmap_ext(p: DVec2) -> Option<DVec3> {
    let r2 = p.length_squared();
    if r2 > 2.0 {
        return None;
    }
    let s = (2.0 - r2).sqrt();
    Some(DVec3::new(p.x * s, p.y * s, 1.0 - r2))
}

/// Symmetric-difference fraction (relative to the approximation's area) between the exact
/// projection of a rotatable square of solid angle `omega` centred on local direction
/// (polar `gamma`, azimuth `phi`), averaged over the paper's four rotations, and the
/// paper's square / the moment-matched box.
fn mismatch(gamma: f64, phi: f64, omega: f64) -> ([f64; 4], [f64; 4]) {
    let c = DVec3::new(
        gamma.sin() * phi.cos(),
        gamma.sin() * phi.sin(),
        gamma.cos(),
    );
    let e1 = DVec3::new(
        gamma.cos() * phi.cos(),
        gamma.cos() * phi.sin(),
        -gamma.sin(),
    );
    let e2 = c.cross(e1);
    let sq = rsl::project(c.as_vec3(), omega as f32);
    let bx = rsl::project_box(c.as_vec3(), omega as f32);
    let pc = sq.centre.as_dvec2();
    let half_side = sq.half_diagonal as f64 / 2f64.sqrt();
    let he = bx.half_extent.as_dvec2();
    let rho_q = (omega / 2.0).sqrt();
    let win = 3.0 * he.x.max(he.y).max(half_side);
    let m = 500;
    let cell = 2.0 * win / m as f64;
    let (mut sq_err, mut bx_err) = ([0.0; 4], [0.0; 4]);
    for (ti, theta) in [0.0, PI / 8.0, PI / 4.0, 3.0 * PI / 8.0]
        .into_iter()
        .enumerate()
    {
        let (cs, sn) = (f64::cos(theta), f64::sin(theta));
        let (mut d_sq, mut d_bx) = (0usize, 0usize);
        for j in 0..m {
            for i in 0..m {
                let off = DVec2::new(
                    -win + cell * (i as f64 + 0.5),
                    -win + cell * (j as f64 + 0.5),
                );
                let inside_c = unmap_ext(pc + off).is_some_and(|d| {
                    let z = d.dot(c);
                    let s = (2.0 / (1.0 + z).max(1e-300)).sqrt();
                    let (qx, qy) = (d.dot(e1) * s, d.dot(e2) * s);
                    let (xr, yr) = (qx * cs + qy * sn, -qx * sn + qy * cs);
                    xr.abs().max(yr.abs()) <= rho_q / 2f64.sqrt()
                });
                let in_sq = off.x.abs().max(off.y.abs()) <= half_side;
                let in_bx = off.x.abs() <= he.x && off.y.abs() <= he.y;
                d_sq += (inside_c != in_sq) as usize;
                d_bx += (inside_c != in_bx) as usize;
            }
        }
        let area = omega / 2.0;
        sq_err[ti] = d_sq as f64 * cell * cell / area;
        bx_err[ti] = d_bx as f64 * cell * cell / area;
    }
    (sq_err, bx_err)
}

#[test]
fn projection_mismatch_square_and_box() {
    // Symmetric difference / area between the exact projection of the light and the
    // approximation, for the square's orientation θ = 0 (sides along the radial and
    // tangential directions at the centre) and averaged over the paper's four rotations.
    // Bounds: the measured values (printed; documented in core::rsl) plus one point.
    let cases = [
        // polar°, azimuth°, bound for the square, for the box (rotation means)
        (0.0, 0.0, 0.228, 0.228),
        (30.0, 30.0, 0.253, 0.250),
        (60.0, 30.0, 0.294, 0.271),
        (80.0, 30.0, 0.387, 0.335),
        (60.0, 0.0, 0.321, 0.234),
        (80.0, 0.0, 0.444, 0.237),
    ];
    for (deg, az, sq_b, bx_b) in cases {
        let (s, b) = mismatch(f64::to_radians(deg), f64::to_radians(az), 0.01);
        let (sm, bm) = (s.iter().sum::<f64>() / 4.0, b.iter().sum::<f64>() / 4.0);
        println!(
            "polar {deg:>4}° azimuth {az:>4}°: θ = 0: square {:.1} %, box {:.1} %; mean over θ: square {:.1} %, box {:.1} %",
            100.0 * s[0],
            100.0 * b[0],
            100.0 * sm,
            100.0 * bm
        );
        assert!(sm <= sq_b, "square at {deg}°/{az}°: {sm}");
        assert!(bm <= bx_b, "box at {deg}°/{az}°: {bm}");
        assert!(bm <= sm + 0.005, "the box is never worse than the square");
    }
}

#[test]
fn projection_is_equal_area_across_the_horizon() {
    // The extended map carries solid angle 2·(area in p) everywhere: the solid angle of the
    // directions landing in a square straddling the unit circle is twice its area.
    let frame = Frame::from_normal(Vec3::Z).unwrap();
    let c = Vec3::new(1.0, 0.2, -0.05).normalize();
    let l = Rsl::new(c, Vec3::Z, 0.05, [1.0; 3]).unwrap();
    let s = l.project(&frame);
    assert!(s.centre.length() > 1.0 && !s.is_below_horizon());
    let half = s.half_diagonal as f64 / 2f64.sqrt();
    let pc = s.centre.as_dvec2();
    let fine = CubeMap::new(128, vec![[0.0; 3]; 6 * 128 * 128]).unwrap();
    let mut omega = 0.0;
    for (d, w) in fine.dirs().iter().zip(fine.solid_angles()) {
        let p = rsl::map_extended(d.as_vec3()).as_dvec2();
        if (p - pc).abs().max_element() <= half {
            omega += w;
        }
    }
    assert!(
        rel(omega, 0.05) < 0.03,
        "{omega} sr landed in a square of 0.05 sr"
    );
    // centre exact: the projection of the centre direction is the square's centre
    let local = frame.to_local(c);
    assert!((rsl::map_extended(local) - s.centre).length() < 1e-6);
}

/// The eq. 13 merge cost: zero without area, energy or fit error; grows with energy and
/// with angular extent (a uniform region's cost is `E·½·|S|^¾`, so merging two equal
/// uniform halves costs more than keeping them); bad input clamps to 0, never NaN.
#[test]
fn bound_cost_penalises_energy_times_extent() {
    assert_eq!(bound_cost(0.0, 5.0, 1.0), 0.0);
    assert_eq!(bound_cost(0.3, 0.0, 0.0), 0.0);
    for bad in [f64::NAN, -1.0, f64::INFINITY] {
        let c = bound_cost(bad, bad, bad);
        assert!(c == 0.0, "{bad}: {c}");
    }
    let (s, e) = (0.2f64, 3.0f64);
    let uniform = bound_cost(s, e, 0.0);
    assert!(rel(uniform, e * 0.5 * s.powf(0.75)) < 1e-12, "{uniform}");
    assert!(bound_cost(2.0 * s, 2.0 * e, 0.0) > 2.0 * uniform);
    assert!(bound_cost(s, 2.0 * e, 0.0) > uniform);
    assert!(bound_cost(s, e, 1e-3) > uniform);
}

/// The default objective is the eq. 13 one, and on the default sky at K = 30 its largest
/// region energy × angular extent, `E·sqrt|S|`, is below the paper's merge (measured 0.24
/// against 0.65): the term eq. 7 ignores.
#[test]
fn bound_objective_is_the_default_and_splits_large_regions() {
    assert_eq!(Options::default().objective, Objective::Bound);
    let cube = env::default_sky(32).unwrap();
    let largest = |objective| {
        let o = Options {
            objective,
            ..Options::quiet(&[30])
        };
        let d = decompose(&cube, &o).unwrap();
        assert_eq!(d[0].merge, objective);
        d[0].regions
            .iter()
            .map(|r| r.luminance_energy * r.solid_angle.sqrt())
            .fold(0.0, f64::max)
    };
    let (b, p) = (largest(Objective::Bound), largest(Objective::Paper));
    println!("largest E·sqrt|S| at K = 30: bound {b:.4}, paper {p:.4}");
    assert!(b < p, "bound {b} paper {p}");
}

/// The moment-matched radiance gradient of a region (`decompose::moment_gradient`): for
/// radiance linear in direction over a square block of texels at a face centre, whose
/// square has the block's own solid angle, it recovers the tangent-plane gradient up to the
/// sphere's curvature (measured 3.3 % low for this 0.06 sr block: `|q| = sin θ` and the
/// block is gnomonic, not a flat square); for a uniform channel it is zero.
#[test]
fn moment_gradient_recovers_a_linear_radiance() {
    use steradian_harness::env::decompose::moment_gradient;
    let n = 32;
    // L = 2 + 0.5·d·e per channel with different e (the second flat, the third along the
    // face's normal, which has no tangential part at its centre).
    let es = [
        DVec3::new(0.8, -0.3, 0.2),
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 1.0),
    ];
    let cube =
        CubeMap::from_fn(n, 4, |d| std::array::from_fn(|c| 2.0 + 0.5 * d.dot(es[c]))).unwrap();
    let centre = cube.dirs()[cube.dir_to_texel(DVec3::Z)];
    let face = cube.unflatten(cube.dir_to_texel(DVec3::Z)).0;
    // An 8 × 8 block around the face centre (about 0.06 sr: first-order regime).
    let block: Vec<u32> = (0..cube.len())
        .filter(|&k| {
            let (f, i, j) = cube.unflatten(k);
            f == face && (12..20).contains(&i) && (12..20).contains(&j)
        })
        .map(|k| k as u32)
        .collect();
    let omega: f64 = block.iter().map(|&k| cube.solid_angles()[k as usize]).sum();
    let c = block
        .iter()
        .map(|&k| cube.dirs()[k as usize] * cube.solid_angles()[k as usize])
        .sum::<DVec3>()
        .normalize();
    assert!(c.distance(centre.normalize()) < 0.05);
    let g = moment_gradient(&cube, &block, c, omega);
    for ch in 0..3 {
        let want = 0.5 * (es[ch] - c * c.dot(es[ch]));
        let err = (g[ch] - want).length();
        assert!(
            err <= 0.04 * want.length() + 1e-3,
            "channel {ch}: {} vs {want}",
            g[ch]
        );
        // Orthogonal to the centre, as the light model needs.
        assert!(g[ch].dot(c).abs() < 1e-9, "{}", g[ch]);
    }
    assert!(g[0].length() > 0.3, "{}", g[0]);
}
