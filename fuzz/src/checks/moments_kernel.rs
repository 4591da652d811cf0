//! The moments kernel: visibility moment tables of arbitrary small coverage maps (up to
//! 12 × 12; coverage from bytes, or raw `f32` bits that the builder must reject outside
//! `[0, 1]`) against a texel-by-texel brute force for moderate squares, `f ∈ [0, 1]` and
//! `|m| ≤ half-side` for any square (raw `f32` bits included, NaN only for NaN input); and
//! `light_moments` with arbitrary lights (radiance gradients included), frames and views
//! never panics and gives per channel either NaN (for NaN input) or a finite value ≥ 0.

use steradian_core::frame::Frame;
use steradian_core::rsl::Rsl;
use steradian_core::rsl::shade::{BrdfIntegral, ShadeLight, light_moments};
use steradian_core::rsl::vis_moments::VisMoments;
use steradian_core::{Vec2, Vec3};

fn f32_at(d: &[u8], at: usize) -> f32 {
    let b: [u8; 4] = core::array::from_fn(|k| d.get(at + k).copied().unwrap_or(0));
    f32::from_le_bytes(b)
}

/// A BRDF density that is a plane over every square: value `a` at the pole, slope `g`.
struct Plane {
    a: f32,
    g: Vec2,
}
impl BrdfIntegral for Plane {
    fn integral(&self, _wo: Vec3, c: Vec2, r: f32) -> f32 {
        ((self.a + self.g.dot(c)) * 2.0 * r * r).max(0.0)
    }
    fn integral_gradient(&self, wo: Vec3, c: Vec2, r: f32) -> (f32, Vec2) {
        (self.integral(wo, c, r), self.g)
    }
}

/// `(f, m)` by the f64 brute force of `steradian-reference`.
fn brute(n: usize, cov: &[f32], c: Vec2, r: f32) -> (f64, f64, f64) {
    steradian_reference::rsl::moments::square_moments(n, cov, c.to_array(), r)
}

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    if data.len() < 2 {
        return;
    }
    let n = 1 + (data[0] % 12) as usize;
    let raw = data[1].is_multiple_of(4);
    let rest = &data[2..];
    let cov: Vec<f32> = (0..n * n)
        .map(|k| {
            if raw {
                f32_at(rest, 4 * k)
            } else {
                f32::from(rest.get(k).copied().unwrap_or(255)) / 255.0
            }
        })
        .collect();
    let used = if raw { 4 * n * n } else { n * n };
    let q = rest.get(used..).unwrap_or(&[]);
    let t = match VisMoments::build_coverage(n, &cov) {
        Ok(t) => t,
        Err(_) => {
            assert!(
                cov.iter().any(|c| !(0.0..=1.0).contains(c)),
                "a valid coverage map was rejected"
            );
            return;
        }
    };
    assert!(cov.iter().all(|c| (0.0..=1.0).contains(c)));

    // Squares: raw f32 bits (centre x, y, half-diagonal).
    for s in q.chunks(12).take(8) {
        let (c, r) = (Vec2::new(f32_at(s, 0), f32_at(s, 4)), f32_at(s, 8));
        let (f, m) = t.moments(c, r);
        if c.is_nan() || r.is_nan() {
            assert!(f.is_nan() && m.is_nan(), "{c} {r}: {f} {m}");
            continue;
        }
        if !(c.is_finite() && r.is_finite()) {
            continue; // infinite squares: no claim beyond "no panic"
        }
        if r <= 0.0 {
            assert_eq!((f, m), (1.0, Vec2::ZERO));
            continue;
        }
        assert!((0.0..=1.0).contains(&f), "{c} {r}: f {f}");
        let h = r * core::f32::consts::FRAC_1_SQRT_2;
        if h.is_finite() {
            assert!(
                m.x.abs() <= h * 1.0001 && m.y.abs() <= h * 1.0001,
                "{c} {r}: m {m} > {h}"
            );
        }
        // Moderate squares (a few texels of f32 corner rounding): the brute force.
        if c.abs().max_element() <= 2.0 && (0.05..=2.0).contains(&r) {
            let (bf, bx, by) = brute(n, &cov, c, r);
            let h = f64::from(h);
            // f32 corners move by an ulp (≤ 2.4e-7 texel here) on each side of a square of
            // half-side h·n/2 texels.
            let tol = 1e-5 + 1e-6 / (h * 0.5 * n as f64);
            assert!((f64::from(f) - bf).abs() < tol, "{c} {r}: f {f} vs {bf}");
            assert!(
                (f64::from(m.x) - bx).abs() < tol * h,
                "{c} {r}: {m} vs {bx}"
            );
            assert!(
                (f64::from(m.y) - by).abs() < tol * h,
                "{c} {r}: {m} vs {by}"
            );
        }
    }

    // The kernel: a light (centre, solid angle, energy, gradients), a frame, a view and a
    // plane BRDF from raw bits; invalid lights and frames are rejected by their builders.
    let k = q.get(96..).unwrap_or(&[]);
    let v3 = |at: usize| Vec3::new(f32_at(k, at), f32_at(k, at + 4), f32_at(k, at + 8));
    let Ok(light) = Rsl::new(v3(0), v3(12), f32_at(k, 24).abs(), [1.0, 0.5, 2.0]) else {
        return;
    };
    let Ok(light) = light.with_gradient([v3(28), v3(40), v3(52)]) else {
        return;
    };
    let Ok(frame) = Frame::from_normal_tangent(v3(64), v3(76)) else {
        return;
    };
    let brdf = Plane {
        a: f32_at(k, 88).abs(),
        g: Vec2::new(f32_at(k, 92), f32_at(k, 96)),
    };
    let wo = v3(100);
    let out = light_moments(
        &frame,
        frame.to_local(wo),
        &brdf,
        &t,
        &ShadeLight::from(&light),
    );
    // Moderate magnitudes (no overflow in the products): never NaN.
    let moderate = |x: f32| x.is_finite() && x.abs() < 1e15;
    let finite_in = wo.is_finite()
        && moderate(brdf.a)
        && moderate(brdf.g.x)
        && moderate(brdf.g.y)
        && light
            .gradient()
            .iter()
            .all(|g| g.to_array().into_iter().all(moderate));
    for o in out {
        assert!(o.is_nan() || o >= 0.0, "{out:?}");
        if finite_in {
            assert!(
                !o.is_nan(),
                "NaN from finite input: {out:?} {light:?} {frame:?} {} {} {wo}",
                brdf.a,
                brdf.g
            );
        }
    }
}
