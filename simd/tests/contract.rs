//! The lane-by-lane contract against the scalar kernels of `steradian-core`:
//! bit-identical for the hemisphere map/unmap, lobe integral and cap lookup; within
//! `lobe::EVAL_REL_TOL` for lobe evaluation. Inputs: deterministic pseudo-random values,
//! arbitrary bit patterns, named special values in every lane position, and slice lengths
//! around the batch size.

use glam::{Vec2, Vec3};
use steradian_core as core_;
use steradian_simd::{LobeX8, Vec2x8, Vec3x8, f32x8, lobe, lobe::cap, rsl::hemisphere};

// ---------------------------------------------------------------------------------------
// Inputs

use crate::common::rng;
use rng::Rng;

impl Rng {
    /// A component drawn from mixed magnitudes and signs (including specials now and then).
    fn mixed(&mut self) -> f32 {
        match self.next_u64() % 8 {
            0 => self.bits(),
            1 => SPECIALS[(self.next_u64() % SPECIALS.len() as u64) as usize],
            2 => self.log_range(1e-38, 1e38) * if self.unit() < 0.5 { -1.0 } else { 1.0 },
            _ => self.range(-1.0, 1.0),
        }
    }
}

use crate::common::specials;
use specials::SPECIALS;

use crate::common::lanes::{LENGTHS, in_every_lane, same};

// ---------------------------------------------------------------------------------------
// Kernels over rows: the scalar kernel, and the SIMD slice function on SoA columns.

fn check_map(rows: &[Vec3]) {
    let n = rows.len();
    let x: Vec<f32> = rows.iter().map(|d| d.x).collect();
    let y: Vec<f32> = rows.iter().map(|d| d.y).collect();
    let z: Vec<f32> = rows.iter().map(|d| d.z).collect();
    let (mut u, mut v) = (vec![f32::NAN; n], vec![f32::NAN; n]);
    hemisphere::map_slices(&x, &y, &z, &mut u, &mut v);
    for (i, d) in rows.iter().enumerate() {
        let p = core_::rsl::hemisphere::map(*d);
        assert!(
            same(p.x, u[i]) && same(p.y, v[i]),
            "map({d:?}) [row {i}]: scalar {p:?} simd ({}, {})",
            u[i],
            v[i]
        );
    }
    // The batch API on the same rows.
    for (k, chunk) in rows.chunks(8).enumerate() {
        let out = hemisphere::map(Vec3x8::from_slice(chunk)).to_array();
        for (j, d) in chunk.iter().enumerate() {
            let p = core_::rsl::hemisphere::map(*d);
            assert!(
                same(p.x, out[j].x) && same(p.y, out[j].y),
                "batch map({d:?}) [row {}]",
                k * 8 + j
            );
        }
    }
}

fn check_unmap(rows: &[Vec2]) {
    let n = rows.len();
    let u: Vec<f32> = rows.iter().map(|p| p.x).collect();
    let v: Vec<f32> = rows.iter().map(|p| p.y).collect();
    let (mut x, mut y, mut z) = (vec![f32::NAN; n], vec![f32::NAN; n], vec![f32::NAN; n]);
    hemisphere::unmap_slices(&u, &v, &mut x, &mut y, &mut z);
    for (i, p) in rows.iter().enumerate() {
        let d = core_::rsl::hemisphere::unmap(*p);
        assert!(
            same(d.x, x[i]) && same(d.y, y[i]) && same(d.z, z[i]),
            "unmap({p:?}) [row {i}]: scalar {d:?} simd ({}, {}, {})",
            x[i],
            y[i],
            z[i]
        );
    }
    for chunk in rows.chunks(8) {
        let out = hemisphere::unmap(Vec2x8::from_slice(chunk)).to_array();
        for (j, p) in chunk.iter().enumerate() {
            let d = core_::rsl::hemisphere::unmap(*p);
            assert!(same(d.x, out[j].x) && same(d.y, out[j].y) && same(d.z, out[j].z));
        }
    }
}

/// `(e, s)` rows.
fn check_integral(rows: &[(f32, f32)]) {
    let n = rows.len();
    let e: Vec<f32> = rows.iter().map(|r| r.0).collect();
    let s: Vec<f32> = rows.iter().map(|r| r.1).collect();
    let mut out = vec![f32::NAN; n];
    lobe::integral_slices(&e, &s, &mut out);
    for (i, &(e, s)) in rows.iter().enumerate() {
        let c = core_::lobe::integral(e, s);
        assert!(
            same(c, out[i]),
            "integral({e:e}, {s:e}) [row {i}]: scalar {c:e} simd {:e}",
            out[i]
        );
    }
}

fn check_cap(rows: &[f32]) {
    let mut out = vec![f32::NAN; rows.len()];
    cap::exponent_l2_slices(rows, &mut out);
    for (i, &a) in rows.iter().enumerate() {
        let c = core_::lobe::cap::exponent_l2(a);
        assert!(
            same(c, out[i]),
            "exponent_l2({a:e}) [row {i}]: scalar {c:e} simd {:e}",
            out[i]
        );
    }
}

/// A lobe-eval row: axis, scale, exponent, direction.
#[derive(Clone, Copy, Debug)]
struct EvalRow {
    a: Vec3,
    s: f32,
    e: f32,
    v: Vec3,
}

/// How far the SIMD value `w` is from the scalar value `c` in units of the documented
/// bound's relative part: `max(|Δ| − U·(1+|s|), 0) / ((1 + |ln(c/s)|)·|c|)`; `None` when
/// the contract's exact parts (NaN-ness, zero-ness) are violated.
fn eval_error(r: &EvalRow, c: f32, w: f32) -> Option<f64> {
    if c.is_nan() || w.is_nan() {
        return (c.is_nan() == w.is_nan()).then_some(0.0);
    }
    if (c == 0.0) != (w == 0.0) {
        return None;
    }
    if c.to_bits() == w.to_bits() {
        return Some(0.0);
    }
    if c.is_infinite() || w.is_infinite() {
        return None;
    }
    let (c, w, s) = (c as f64, w as f64, r.s as f64);
    let slack = lobe::EVAL_UNDERFLOW_ABS as f64 * (1.0 + s.abs());
    let d = ((c - w).abs() - slack).max(0.0);
    if d == 0.0 {
        return Some(0.0);
    }
    let l = (c / s).abs().ln().abs();
    Some(d / ((1.0 + l) * c.abs()))
}

/// Checks the eval rows; returns the largest relative error measured.
fn check_eval(rows: &[EvalRow]) -> f64 {
    let n = rows.len();
    let col = |f: &dyn Fn(&EvalRow) -> f32| rows.iter().map(f).collect::<Vec<f32>>();
    let (ax, ay, az) = (col(&|r| r.a.x), col(&|r| r.a.y), col(&|r| r.a.z));
    let (s, e) = (col(&|r| r.s), col(&|r| r.e));
    let (vx, vy, vz) = (col(&|r| r.v.x), col(&|r| r.v.y), col(&|r| r.v.z));
    let mut out = vec![f32::NAN; n];
    lobe::eval_slices([&ax, &ay, &az], &s, &e, [&vx, &vy, &vz], &mut out);
    let mut worst = 0.0f64;
    for (i, r) in rows.iter().enumerate() {
        let c = core_::lobe::eval(r.a, r.s, r.e, r.v);
        let w = out[i];
        let err = eval_error(r, c, w)
            .unwrap_or_else(|| panic!("eval {r:?} [row {i}]: scalar {c:e} simd {w:e}"));
        assert!(
            err <= lobe::EVAL_REL_TOL as f64,
            "eval {r:?} [row {i}]: scalar {c:e} simd {w:e}, error {err:e} > tolerance"
        );
        // Exact parts: beyond the horizon, and e = 0.
        let d = r.a - r.v;
        let t = 0.5 * (d.x * d.x + d.y * d.y + d.z * d.z);
        if t >= 1.0 || (r.e <= 0.0 && t < 1.0 && r.v.is_finite() && r.a.is_finite()) {
            assert!(same(c, w), "eval {r:?}: exact case differs: {c:e} vs {w:e}");
        }
        worst = worst.max(err);
    }
    // The batch API on the same rows.
    for (k, chunk) in rows.chunks(8).enumerate() {
        let lobes = LobeX8::new(
            Vec3x8::from_slice(&chunk.iter().map(|r| r.a).collect::<Vec<_>>()),
            f32x8::new(std::array::from_fn(|k| chunk.get(k).map_or(0.0, |r| r.s))),
            f32x8::new(std::array::from_fn(|k| chunk.get(k).map_or(0.0, |r| r.e))),
        );
        let v = Vec3x8::from_slice(&chunk.iter().map(|r| r.v).collect::<Vec<_>>());
        let batch = lobes.eval(v).to_array();
        let parts = lobe::eval_parts(lobes.axis, lobes.scale, lobes.exponent, v).to_array();
        for (j, r) in chunk.iter().enumerate() {
            assert!(same(batch[j], out[k * 8 + j]), "batch eval {r:?}");
            assert!(same(parts[j], batch[j]));
        }
    }
    worst
}

// ---------------------------------------------------------------------------------------
// Hemisphere map

fn special_dirs() -> Vec<Vec3> {
    let mut rows = vec![
        Vec3::Z,                        // pole
        -Vec3::Z,                       // lower pole
        Vec3::X,                        // horizon
        Vec3::new(0.0, -1.0, 0.0),      // horizon
        Vec3::new(0.6, 0.8, 1e-7),      // just above the horizon
        Vec3::new(0.6, 0.8, -1e-7),     // just below
        Vec3::ZERO,                     // zero vector → pole
        Vec3::new(3e38, 3e38, 3e38),    // would overflow |v|² unscaled
        Vec3::new(1e-30, 2e-30, 1e-30), // would underflow unscaled
        Vec3::new(f32::NAN, 0.0, 0.0),  // NaN-ignoring max: the scalar kernel maps this to 0
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
    ];
    for &x in &SPECIALS {
        for &y in &SPECIALS {
            for &z in &SPECIALS {
                rows.push(Vec3::new(x, y, z));
            }
        }
    }
    rows
}

#[test]
fn map_special_values_in_every_lane() {
    in_every_lane(&special_dirs(), Vec3::new(0.3, 0.4, 0.5), check_map);
}

#[test]
fn map_random_and_arbitrary_bits() {
    let mut rng = Rng(1);
    let mut rows: Vec<Vec3> = (0..100_000).map(|_| rng.dir()).collect();
    rows.extend((0..100_000).map(|_| rng.dir() * rng.log_range(1e-35, 1e35)));
    rows.extend((0..100_000).map(|_| Vec3::new(rng.bits(), rng.bits(), rng.bits())));
    rows.extend((0..100_000).map(|_| Vec3::new(rng.mixed(), rng.mixed(), rng.mixed())));
    check_map(&rows);
}

#[test]
fn map_slice_lengths() {
    let mut rng = Rng(2);
    for n in LENGTHS {
        let rows: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.mixed(), rng.mixed(), rng.mixed()))
            .collect();
        check_map(&rows);
    }
}

// ---------------------------------------------------------------------------------------
// Hemisphere unmap

fn special_points() -> Vec<Vec2> {
    let mut rows = vec![
        Vec2::ZERO,
        Vec2::X,
        Vec2::new(0.6, 0.8),
        Vec2::new(0.6, 0.8000001), // just outside
        Vec2::new(3.0, 4.0),
        Vec2::new(1e20, 1e20), // |p|² overflows: scaled by the larger component first
        Vec2::new(6.651431e29, -0.21083903),
        Vec2::new(f32::MAX, -f32::MAX),
        Vec2::new(1e-30, 1.0000001), // just outside, tiny other component
        Vec2::new(0.70710677, 0.70710677),
    ];
    for &x in &SPECIALS {
        for &y in &SPECIALS {
            rows.push(Vec2::new(x, y));
        }
    }
    rows
}

#[test]
fn unmap_special_values_in_every_lane() {
    in_every_lane(&special_points(), Vec2::new(0.1, -0.2), check_unmap);
    // a batch where no lane is outside the disk and one where all are
    check_unmap(&[Vec2::new(0.1, 0.2); 8]);
    check_unmap(&[Vec2::new(2.0, 0.2); 8]);
}

#[test]
fn unmap_random_and_arbitrary_bits() {
    let mut rng = Rng(3);
    let mut rows: Vec<Vec2> = (0..100_000)
        .map(|_| Vec2::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)))
        .collect();
    rows.extend((0..50_000).map(|_| Vec2::new(rng.range(-1.5, 1.5), rng.range(-1.5, 1.5))));
    rows.extend((0..100_000).map(|_| Vec2::new(rng.bits(), rng.bits())));
    rows.extend((0..100_000).map(|_| Vec2::new(rng.mixed(), rng.mixed())));
    check_unmap(&rows);
}

#[test]
fn unmap_slice_lengths() {
    let mut rng = Rng(4);
    for n in LENGTHS {
        let rows: Vec<Vec2> = (0..n)
            .map(|_| Vec2::new(rng.mixed(), rng.mixed()))
            .collect();
        check_unmap(&rows);
    }
}

// ---------------------------------------------------------------------------------------
// Lobe integral

fn special_integrals() -> Vec<(f32, f32)> {
    let mut rows = vec![(0.0, 1.0), (1e5, 1.0), (-5.0, 1.0), (f32::INFINITY, 1.0)];
    for &e in &SPECIALS {
        for &s in &SPECIALS {
            rows.push((e, s));
        }
    }
    rows
}

#[test]
fn integral_special_values_in_every_lane() {
    in_every_lane(&special_integrals(), (2.0, 1.0), check_integral);
}

#[test]
fn integral_random_and_arbitrary_bits() {
    let mut rng = Rng(5);
    let mut rows: Vec<(f32, f32)> = (0..100_000)
        .map(|_| (rng.log_range(1e-3, 1e6), rng.range(-10.0, 10.0)))
        .collect();
    rows.extend((0..100_000).map(|_| (rng.bits(), rng.bits())));
    rows.extend((0..100_000).map(|_| (rng.mixed(), rng.mixed())));
    check_integral(&rows);
}

#[test]
fn integral_slice_lengths() {
    let mut rng = Rng(6);
    for n in LENGTHS {
        let rows: Vec<(f32, f32)> = (0..n).map(|_| (rng.mixed(), rng.mixed())).collect();
        check_integral(&rows);
    }
}

// ---------------------------------------------------------------------------------------
// Cap exponent lookup

fn special_half_angles() -> Vec<f32> {
    use std::f32::consts::{FRAC_PI_2, PI};
    let mut rows = vec![
        1e-4,
        FRAC_PI_2,
        FRAC_PI_2.next_up(),
        FRAC_PI_2.next_down(),
        PI,
        2.0,
        -1.0,
        -1e-4,
        core_::lobe::cap::MIN_HALF_ANGLE,
        core_::lobe::cap::MIN_HALF_ANGLE.next_down(),
        1e-19,
    ];
    // every grid node (uniform in x = 1 − sqrt(1 − α/(π/2))) and its neighbours
    let last = (core_::lobe::cap::TABLE_LEN - 1) as f64;
    for i in 0..core_::lobe::cap::TABLE_LEN {
        let w = 1.0 - i as f64 / last;
        let a = ((1.0 - w * w) * std::f64::consts::FRAC_PI_2) as f32;
        rows.extend([a.next_down(), a, a.next_up()]);
    }
    rows.extend_from_slice(&SPECIALS);
    rows
}

#[test]
fn cap_special_values_in_every_lane() {
    in_every_lane(&special_half_angles(), 0.3, check_cap);
}

#[test]
fn cap_random_and_arbitrary_bits() {
    let mut rng = Rng(7);
    let mut rows: Vec<f32> = (0..200_000).map(|_| rng.range(0.0, 1.6)).collect();
    rows.extend((0..100_000).map(|_| rng.log_range(1e-20, 4.0)));
    rows.extend((0..200_000).map(|_| rng.bits()));
    rows.extend((0..100_000).map(|_| rng.mixed()));
    check_cap(&rows);
}

#[test]
fn cap_slice_lengths() {
    let mut rng = Rng(8);
    for n in LENGTHS {
        let rows: Vec<f32> = (0..n).map(|_| rng.mixed()).collect();
        check_cap(&rows);
    }
}

#[test]
fn cap_custom_tables() {
    let mut rng = Rng(9);
    let angles: Vec<f32> = (0..4000)
        .map(|_| rng.mixed().abs().min(2.0))
        .chain(SPECIALS)
        .collect();
    for len in [0usize, 1, 2, 3, 17, 512, 4097] {
        let table: Vec<f32> = (0..len).map(|i| (i as f32 * 0.37).sin() + 2.0).collect();
        let mut out = vec![0.0; angles.len()];
        cap::lookup_slices(&table, &angles, &mut out);
        for (a, w) in angles.iter().zip(&out) {
            let c = core_::lobe::cap::lookup(&table, *a);
            assert!(same(c, *w), "lookup(len {len}, {a:e}): {c:e} vs {w:e}");
        }
    }
}

/// Every `f32` bit pattern (release only: `cargo test --release -p steradian-simd -- --ignored`).
#[test]
#[ignore]
fn cap_exhaustive() {
    const CHUNK: usize = 1 << 20;
    let mut a = vec![0.0f32; CHUNK];
    let mut out = vec![0.0f32; CHUNK];
    for hi in 0..(1u64 << 32) / CHUNK as u64 {
        for (k, x) in a.iter_mut().enumerate() {
            *x = f32::from_bits((hi as u32) << 20 | k as u32);
        }
        cap::exponent_l2_slices(&a, &mut out);
        for (x, w) in a.iter().zip(&out) {
            let c = core_::lobe::cap::exponent_l2(*x);
            assert!(same(c, *w), "exponent_l2({x:e}): {c:e} vs {w:e}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Lobe evaluation

fn random_eval_rows(rng: &mut Rng, n: usize) -> Vec<EvalRow> {
    (0..n)
        .map(|_| {
            let a = rng.dir();
            // directions from the axis out to beyond the horizon, at every scale of angle
            let off = rng.dir() * rng.log_range(1e-6, 2.5);
            let v = (a + off).normalize();
            let e = match rng.next_u64() % 6 {
                0 => 0.0,
                1 => 1.0,
                2 => rng.range(0.0, 10.0),
                _ => rng.log_range(1e-3, 1e7),
            };
            let s = match rng.next_u64() % 8 {
                0 => 1.0,
                1 => rng.log_range(1e-30, 1e30),
                2 => -rng.log_range(1e-3, 1e3),
                _ => rng.range(-10.0, 10.0),
            };
            EvalRow { a, s, e, v }
        })
        .collect()
}

#[test]
fn eval_random_within_tolerance() {
    let mut rng = Rng(10);
    let rows = random_eval_rows(&mut rng, 300_000);
    let worst = check_eval(&rows);
    println!("lobe eval: worst relative error / (1 + |ln(c/s)|) = {worst:e}");
}

#[test]
fn eval_underflow_region() {
    // exponents that push exp(e·log1p(−t)) through the subnormal range and to zero
    let mut rng = Rng(11);
    let mut rows = vec![];
    for _ in 0..200_000 {
        let a = Vec3::Z;
        let v = (a + rng.dir() * rng.range(0.01, 1.0)).normalize();
        let d = a - v;
        let t = 0.5 * d.dot(d);
        if t >= 1.0 || t == 0.0 {
            continue;
        }
        // target y = e·log1p(−t) in [−110, −80]
        let y = rng.range(-110.0, -80.0);
        let e = y / (-t).ln_1p();
        let s = match rng.next_u64() % 3 {
            0 => 1.0,
            1 => rng.log_range(1e-3, 1e30),
            _ => -rng.log_range(1e-3, 1e3),
        };
        rows.push(EvalRow { a, s, e, v });
    }
    check_eval(&rows);
}

/// Exact zero-ness where the result underflows: `exp`'s argument next to its underflow
/// threshold `−150·ln 2`, and products `s·e^y` next to `2⁻¹⁵⁰`.
#[test]
fn eval_zero_boundary() {
    let mut rng = Rng(16);
    let mut rows = vec![];
    for i in 0..200_000 {
        let a = Vec3::Z;
        let v = (a + rng.dir() * rng.range(0.05, 1.0)).normalize();
        let d = a - v;
        let t = 0.5 * d.dot(d);
        if t >= 1.0 || t == 0.0 {
            continue;
        }
        let (y, s) = if i % 2 == 0 {
            // y within ±0.05 of −103.972
            let y = -103.972_08 + rng.range(-0.05, 0.05);
            let s = match rng.next_u64() % 3 {
                0 => 1.0,
                1 => rng.log_range(1.0, 1e30),
                _ => -rng.log_range(1e-3, 1e3),
            };
            (y, s)
        } else {
            // s·e^y within 1e-4 relative of 2^-150 (or of 2^-149, 3·2^-150)
            let y = rng.range(-60.0, 0.0);
            let target = [2f64.powi(-150), 2f64.powi(-149), 3.0 * 2f64.powi(-150)]
                [(rng.next_u64() % 3) as usize];
            let s = (target / (y as f64).exp() * (1.0 + 1e-4 * rng.range(-1.0, 1.0) as f64)) as f32;
            (y, s)
        };
        let e = y / (-t).ln_1p();
        rows.push(EvalRow { a, s, e, v });
    }
    check_eval(&rows);
}

#[test]
fn eval_special_values_in_every_lane() {
    use std::f32::consts::FRAC_1_SQRT_2;
    let a = Vec3::Z;
    let mut rows = vec![
        EvalRow {
            a,
            s: 2.0,
            e: 0.0,
            v: Vec3::new(0.6, 0.0, 0.8),
        }, // e = 0 → s exactly
        EvalRow {
            a,
            s: 2.0,
            e: -3.0,
            v: Vec3::new(0.6, 0.0, 0.8),
        }, // clamped
        EvalRow {
            a,
            s: 2.0,
            e: 1e5,
            v: a,
        }, // on the axis
        EvalRow {
            a,
            s: 2.0,
            e: 1e5,
            v: Vec3::new(1e-4, 0.0, 1.0).normalize(),
        },
        EvalRow {
            a,
            s: 2.0,
            e: 1.0,
            v: Vec3::X,
        }, // on the horizon
        EvalRow {
            a,
            s: -2.0,
            e: 1.0,
            v: Vec3::X,
        }, // −0
        EvalRow {
            a,
            s: 2.0,
            e: 1.0,
            v: -a,
        }, // antipode
        EvalRow {
            a,
            s: 2.0,
            e: 1.0,
            v: Vec3::new(FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2),
        },
        EvalRow {
            a,
            s: 2.0,
            e: 1.0,
            v: Vec3::new(1.0, 0.0, 1e-7).normalize(),
        },
        EvalRow {
            a,
            s: f32::NAN,
            e: 1.0,
            v: Vec3::X,
        }, // NaN scale beyond horizon
        EvalRow {
            a,
            s: f32::INFINITY,
            e: 1.0,
            v: -a,
        },
        EvalRow {
            a,
            s: 1.0,
            e: f32::NAN,
            v: a,
        },
        EvalRow {
            a,
            s: 1.0,
            e: f32::INFINITY,
            v: a,
        }, // ∞·0 = NaN
        EvalRow {
            a,
            s: 1.0,
            e: f32::INFINITY,
            v: Vec3::new(0.6, 0.0, 0.8),
        }, // → 0
        EvalRow {
            a,
            s: 1.0,
            e: f32::MAX,
            v: Vec3::new(1e-3, 0.0, 1.0).normalize(),
        },
        EvalRow {
            a,
            s: 1.0,
            e: 1.0,
            v: Vec3::new(f32::NAN, 0.0, 1.0),
        },
        EvalRow {
            a: Vec3::new(f32::NAN, 0.0, 1.0),
            s: 1.0,
            e: 1.0,
            v: a,
        },
    ];
    // every special in every field, the others ordinary
    let base = EvalRow {
        a,
        s: 1.5,
        e: 3.0,
        v: Vec3::new(0.6, 0.0, 0.8),
    };
    for &x in &SPECIALS {
        for field in 0..8 {
            let mut r = base;
            match field {
                0 => r.a.x = x,
                1 => r.a.y = x,
                2 => r.a.z = x,
                3 => r.s = x,
                4 => r.e = x,
                5 => r.v.x = x,
                6 => r.v.y = x,
                _ => r.v.z = x,
            }
            rows.push(r);
        }
    }
    let filler = EvalRow {
        a,
        s: 1.0,
        e: 2.0,
        v: Vec3::new(0.0, 0.6, 0.8),
    };
    in_every_lane(&rows, filler, |r| {
        check_eval(r);
    });
}

#[test]
fn eval_arbitrary_bits() {
    let mut rng = Rng(12);
    let rows: Vec<EvalRow> = (0..200_000)
        .map(|_| {
            if rng.unit() < 0.5 {
                EvalRow {
                    a: Vec3::new(rng.bits(), rng.bits(), rng.bits()),
                    s: rng.bits(),
                    e: rng.bits(),
                    v: Vec3::new(rng.bits(), rng.bits(), rng.bits()),
                }
            } else {
                EvalRow {
                    a: Vec3::new(rng.mixed(), rng.mixed(), rng.mixed()),
                    s: rng.mixed(),
                    e: rng.mixed(),
                    v: Vec3::new(rng.mixed(), rng.mixed(), rng.mixed()),
                }
            }
        })
        .collect();
    check_eval(&rows);
}

#[test]
fn eval_slice_lengths() {
    let mut rng = Rng(13);
    for n in LENGTHS {
        check_eval(&random_eval_rows(&mut rng, n));
    }
}

// ---------------------------------------------------------------------------------------
// The `cpu-simd` backend's logic: columns at `data[c·n .. (c+1)·n]`, split as the harness
// backend splits them, against the scalar kernels.

fn run_columns(kernel: &str, input: &[f32], n: usize, out: &mut [f32]) {
    let col = |c: usize| &input[c * n..(c + 1) * n];
    match kernel {
        "hemisphere-map" => {
            let (u, v) = out.split_at_mut(n);
            hemisphere::map_slices(col(0), col(1), col(2), u, v);
        }
        "hemisphere-unmap" => {
            let (x, rest) = out.split_at_mut(n);
            let (y, z) = rest.split_at_mut(n);
            hemisphere::unmap_slices(col(0), col(1), x, y, z);
        }
        "lobe-eval" => lobe::eval_slices(
            [col(0), col(1), col(2)],
            col(3),
            col(4),
            [col(5), col(6), col(7)],
            out,
        ),
        "lobe-integral" => lobe::integral_slices(col(0), col(1), out),
        "cap-exponent" => cap::exponent_l2_slices(col(0), out),
        _ => unreachable!(),
    }
}

#[test]
fn columns_layout_like_the_backend() {
    let mut rng = Rng(14);
    for n in LENGTHS {
        for (kernel, ins, outs) in [
            ("hemisphere-map", 3, 2),
            ("hemisphere-unmap", 2, 3),
            ("lobe-eval", 8, 1),
            ("lobe-integral", 2, 1),
            ("cap-exponent", 1, 1),
        ] {
            let input: Vec<f32> = (0..ins * n).map(|_| rng.mixed()).collect();
            let mut out = vec![f32::NAN; outs * n];
            run_columns(kernel, &input, n, &mut out);
            let at = |c: usize, r: usize| input[c * n + r];
            for r in 0..n {
                let got = |c: usize| out[c * n + r];
                match kernel {
                    "hemisphere-map" => {
                        let p =
                            core_::rsl::hemisphere::map(Vec3::new(at(0, r), at(1, r), at(2, r)));
                        assert!(same(p.x, got(0)) && same(p.y, got(1)));
                    }
                    "hemisphere-unmap" => {
                        let d = core_::rsl::hemisphere::unmap(Vec2::new(at(0, r), at(1, r)));
                        assert!(same(d.x, got(0)) && same(d.y, got(1)) && same(d.z, got(2)));
                    }
                    "lobe-eval" => {
                        let row = EvalRow {
                            a: Vec3::new(at(0, r), at(1, r), at(2, r)),
                            s: at(3, r),
                            e: at(4, r),
                            v: Vec3::new(at(5, r), at(6, r), at(7, r)),
                        };
                        let c = core_::lobe::eval(row.a, row.s, row.e, row.v);
                        let err = eval_error(&row, c, got(0)).expect("exact parts");
                        assert!(err <= lobe::EVAL_REL_TOL as f64);
                    }
                    "lobe-integral" => {
                        assert!(same(core_::lobe::integral(at(0, r), at(1, r)), got(0)));
                    }
                    _ => assert!(same(core_::lobe::cap::exponent_l2(at(0, r)), got(0))),
                }
            }
        }
    }
}

#[test]
fn isa_is_named() {
    let isa = steradian_simd::isa();
    assert!(
        [
            "avx512f", "avx2+fma", "avx2", "avx", "sse4.1", "sse2", "neon", "simd128", "scalar"
        ]
        .contains(&isa)
    );
    println!("steradian-simd f32x8 ISA: {isa}");
}

/// A larger survey of the eval error, printing the worst case per range of `|ln(c/s)|`
/// (release: `cargo test --release -p steradian-simd --test contract eval_survey -- --ignored --nocapture`).
#[test]
#[ignore]
fn eval_survey() {
    let mut rng = Rng(15);
    let mut worst = [(0.0f64, None::<EvalRow>); 6];
    for _ in 0..40 {
        let rows = random_eval_rows(&mut rng, 500_000);
        let n = rows.len();
        let col = |f: &dyn Fn(&EvalRow) -> f32| rows.iter().map(f).collect::<Vec<f32>>();
        let mut out = vec![0.0; n];
        lobe::eval_slices(
            [&col(&|r| r.a.x), &col(&|r| r.a.y), &col(&|r| r.a.z)],
            &col(&|r| r.s),
            &col(&|r| r.e),
            [&col(&|r| r.v.x), &col(&|r| r.v.y), &col(&|r| r.v.z)],
            &mut out,
        );
        for (r, w) in rows.iter().zip(&out) {
            let c = core_::lobe::eval(r.a, r.s, r.e, r.v);
            let err = eval_error(r, c, *w).expect("exact parts");
            let l = (c / r.s).abs().ln().abs();
            let b = match l {
                l if l < 1e-3 => 0,
                l if l < 0.1 => 1,
                l if l < 1.0 => 2,
                l if l < 10.0 => 3,
                l if l < 87.0 => 4,
                _ => 5,
            };
            if err > worst[b].0 {
                worst[b] = (err, Some(*r));
            }
        }
    }
    for (b, (e, r)) in worst.iter().enumerate() {
        println!("bucket {b}: worst {e:e} at {r:?}");
    }
}
