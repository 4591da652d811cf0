//! Tabulated SH coefficients of isotropic BRDFs (HVL paper section 4.2, eq. 16–18).
//!
//! For a fixed view `ωₒ` a BRDF is a spherical function of the light direction; its SH
//! coefficients, tabulated over views, turn shading into dot products:
//!
//! ```text
//!   F_l^m(ωₒ)  = ∫ f_s(ωᵢ, ωₒ)·max(cos θᵢ, 0)·Y_l^m(ωᵢ) dωᵢ     (with the cosine, "F")
//!   F′_l^m(ωₒ) = ∫ f_s(ωᵢ, ωₒ)·[cos θᵢ > 0]·Y_l^m(ωᵢ) dωᵢ       (without it, "F′")
//! ```
//!
//! in the **view frame**: `z` the normal, `x` the tangent toward the view, so that
//! `ωₒ = (sin θₒ, 0, cos θₒ)` ([`view_frame`]). An isotropic BRDF then depends on the view
//! through `θₒ` alone (eq. 17–18: one 1-D table per material instead of a 2-D one), and it is
//! even in `φᵢ` (the plane of incidence is a mirror plane), so every `m < 0` (`sin mφ`)
//! coefficient vanishes: a table stores the `n(n+1)/2` coefficients with `m ≥ 0` per view.
//! By reciprocity the same `F′` table gives the emission of a surface lit from `ω_l`
//! toward any `ω` (`f_s(ω_l, ω) = f_s(ω, ω_l)`), which is how a Harmonics Virtual Light
//! re-emits ([`crate::sh::hvl`]).
//!
//! **Samples.** `T` views at the cell centres `θ_k = (k + ½)·(π/2)/T` (the paper: `T = 90`,
//! one degree), linearly interpolated in `θₒ` and clamped to the first and last sample
//! outside `[θ_0, θ_{T−1}]` (at grazing `θₒ = π/2` every BRDF of
//! [`crate::lobe::brdf`] is 0 by definition, a sample there would carry nothing).
//!
//! **File** ([`crate::table`] format): name [`TABLE_NAME`], rank 2, dims `[T, 2]` (part `0`
//! is `F`, part `1` is `F′`), `n(n+1)/2` channels in the order `l = 0..n−1`, `m = 0..l`;
//! domain `θₒ ∈ [0, π/2]`. The generator (quadrature in `f64`, the band count and `T` chosen
//! from a target error) is `steradian_harness::generate::brdf_sh`; the built-in tables are
//! [`lambert`], [`phong`], [`lafortune`] and [`ggx`] (materials named there), each checked
//! by `steradian tables --check`. For a 5 % truncation target at `θₒ = 45°` the generator
//! chose 5 bands × 16 views for Lambert, 14 × 90 for Phong 30, and 11 × 45 for the
//! Lafortune and GGX materials (2–76 KB each). Tables are stored unwindowed; apply a
//! [`crate::sh::window::Window`] to the looked-up coefficients.
//!
//! **Accuracy.** The table's own error (quadrature and the `f32` rounding) is below `1e-6`
//! of `F_0^0`; the interpolation in `θₒ` and the truncation at `n` bands are measured per
//! material in the report (section "BRDF SH tables") against the BRDF itself.

use crate::frame::Frame;
use crate::sh::check_shape;
use crate::table::{HEADER_LEN, Header, TableError};
use crate::{Error, Vec3};

/// Name of every BRDF SH table.
pub const TABLE_NAME: &str = "sh-brdf";

/// Which of the two tabulated functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// `F`: the BRDF times the clamped cosine (for shading by a dot product with incident
    /// radiance).
    WithCosine = 0,
    /// `F′`: the BRDF alone on the upper hemisphere (for emission).
    WithoutCosine = 1,
}

/// The view frame of module docs: `z = normal`, `x` toward the view's tangential part
/// (any tangent when the view is along the normal or below the horizon).
///
/// Errors: a zero or non-finite normal.
pub fn view_frame(normal: Vec3, view: Vec3) -> Result<Frame, Error> {
    match Frame::from_normal_tangent(normal, view) {
        Ok(f) => Ok(f),
        Err(_) => Frame::from_normal(normal),
    }
}

/// `n(n+1)/2`, the stored coefficients of `n` bands.
pub const fn stored(bands: usize) -> usize {
    bands * (bands + 1) / 2
}

/// A BRDF SH table over table-file bytes (module docs).
#[derive(Clone, Copy, Debug)]
pub struct BrdfSh<'a> {
    bands: usize,
    samples: usize,
    payload: &'a [u8],
}

impl<'a> BrdfSh<'a> {
    /// A table from table-file bytes, fully validated (checksum, name, shape, and every
    /// value finite).
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, Error> {
        let h = Header::parse(bytes)?;
        Self::from_header(&h, bytes)?.check_finite()
    }

    fn from_header(h: &Header, bytes: &'a [u8]) -> Result<Self, Error> {
        if !h.has_name(TABLE_NAME) {
            return Err(TableError::WrongName.into());
        }
        let c = h.channels as usize;
        let mut bands = 0;
        while stored(bands) < c {
            bands += 1;
        }
        if h.rank != 2 || h.dims[1] != 2 || h.dims[0] == 0 || stored(bands) != c {
            return Err(TableError::WrongShape.into());
        }
        check_shape(bands, usize::MAX)?;
        Ok(BrdfSh {
            bands,
            samples: h.dims[0] as usize,
            payload: bytes.split_at(HEADER_LEN).1,
        })
    }

    fn check_finite(self) -> Result<Self, Error> {
        let n = self.samples * 2 * stored(self.bands);
        if (0..n).any(|i| !self.value(i).is_finite()) {
            return Err(Error::NonFinite {
                what: "BRDF SH table value",
            });
        }
        Ok(self)
    }

    /// The built-in table `bytes` (validated by the caller's constant and by tests).
    const fn builtin(bytes: &'static [u8], bands: usize, samples: usize) -> BrdfSh<'static> {
        BrdfSh {
            bands,
            samples,
            payload: bytes.split_at(HEADER_LEN).1,
        }
    }

    /// The band count `n`.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The number of views `T`.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// `θ_k = (k + ½)·(π/2)/T`, the view of sample `k`.
    pub fn theta(&self, k: usize) -> f32 {
        (k as f32 + 0.5) * core::f32::consts::FRAC_PI_2 / self.samples as f32
    }

    #[inline]
    fn value(&self, i: usize) -> f32 {
        let b = &self.payload[4 * i..4 * i + 4];
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }

    /// Stored coefficient `j` (`l(l+1)/2 + m`, `m ≥ 0`) of `part` at sample `k`.
    pub fn stored_value(&self, part: Part, k: usize, j: usize) -> f32 {
        self.value((k * 2 + part as usize) * stored(self.bands) + j)
    }

    /// The `n²` coefficients of `part` at the view angle `theta_o` (radians, clamped to
    /// `[0, π/2]`; NaN gives NaN) in the view frame, interpolated (module docs), into
    /// `out[..n²]` (`m < 0` entries are 0). `bands ≤ n` takes the first bands only.
    ///
    /// Errors: `bands` above the table's, `out` shorter than `bands²`.
    pub fn lookup_into(
        &self,
        part: Part,
        theta_o: f32,
        bands: usize,
        out: &mut [f32],
    ) -> Result<(), Error> {
        check_shape(bands, out.len())?;
        if bands > self.bands {
            return Err(Error::OutOfRange {
                what: "SH bands of a BRDF table lookup",
                value: bands as f32,
                min: 0.0,
                max: self.bands as f32,
            });
        }
        let t = self.samples as f32 * theta_o / core::f32::consts::FRAC_PI_2 - 0.5;
        let t = t.clamp(0.0, (self.samples - 1) as f32);
        let (k0, w) = if t.is_nan() {
            (0, f32::NAN)
        } else {
            let k = (t as usize).min(self.samples.saturating_sub(2));
            (k, t - k as f32)
        };
        let k1 = (k0 + 1).min(self.samples - 1);
        for l in 0..bands {
            let c = l * l + l;
            for m in 0..=l {
                let j = stored(l) + m;
                let a = self.stored_value(part, k0, j);
                let b = self.stored_value(part, k1, j);
                out[c + m] = a + w * (b - a);
                if m > 0 {
                    out[c - m] = 0.0;
                }
            }
        }
        Ok(())
    }
}

macro_rules! builtin {
    ($(#[$doc:meta])* $name:ident, $file:literal) => {
        $(#[$doc])*
        pub fn $name() -> BrdfSh<'static> {
            const BYTES: &[u8] = include_bytes!($file);
            const SHAPE: (usize, usize) = match Header::parse_shape(BYTES) {
                Ok(h) if h.has_name(TABLE_NAME) && h.rank == 2 && h.dims[1] == 2 => {
                    let c = h.channels as usize;
                    let mut n = 0;
                    while stored(n) < c {
                        n += 1;
                    }
                    if stored(n) != c {
                        panic!("built-in BRDF SH table has a bad channel count");
                    }
                    (n, h.dims[0] as usize)
                }
                _ => panic!("built-in BRDF SH table failed validation"),
            };
            BrdfSh::builtin(BYTES, SHAPE.0, SHAPE.1)
        }
    };
}

builtin!(
    /// Lambert, albedo 1 (`f_s = 1/π`).
    lambert,
    "tables/brdf_lambert.bin"
);
builtin!(
    /// Modified Phong, specular only: `k_d = 0`, `k_s = 1`, exponent 30
    /// ([`crate::lobe::brdf::Phong`]).
    phong,
    "tables/brdf_phong30.bin"
);
builtin!(
    /// Lafortune: a diffuse lobe `0.3/π` (`C = (0, 0, 1)`, exponent 0) and a lobe
    /// `C = (−0.9, −0.9, 1)`, exponent 20, `ρ = 0.5·22/(2π)` (slightly off-specular, toward
    /// the normal) ([`crate::lobe::Lafortune`]).
    lafortune,
    "tables/brdf_lafortune.bin"
);
builtin!(
    /// GGX with Schlick's Fresnel, a dielectric: `k_d = 0`, `F₀ = 0.04`, `α = 0.3`
    /// ([`crate::lobe::brdf::Ggx`]).
    ggx,
    "tables/brdf_ggx.bin"
);

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;
    use alloc::vec;

    #[test]
    fn builtin_tables_are_valid_and_even_in_phi() {
        // The shapes the generator chose (module docs): bands × views.
        let shapes = [(5, 16), (14, 90), (11, 45), (11, 45)];
        for (t, shape) in [lambert(), phong(), lafortune(), ggx()]
            .into_iter()
            .zip(shapes)
        {
            let n = t.bands();
            assert_eq!((n, t.samples()), shape);
            let mut out = vec![0.0; n * n];
            for th in [0.0, 0.3, 1.0, 1.5707964] {
                t.lookup_into(Part::WithCosine, th, n, &mut out).unwrap();
                assert!(out.iter().all(|v| v.is_finite()));
                for l in 0..n {
                    for m in 1..=l {
                        assert_eq!(out[l * l + l - m], 0.0);
                    }
                }
            }
        }
        // The bytes pass the full run-time validation as well (checksum included).
        for bytes in [
            include_bytes!("tables/brdf_lambert.bin").as_slice(),
            include_bytes!("tables/brdf_phong30.bin"),
            include_bytes!("tables/brdf_lafortune.bin"),
            include_bytes!("tables/brdf_ggx.bin"),
        ] {
            BrdfSh::from_bytes(bytes).unwrap();
        }
    }

    #[test]
    fn lambert_is_the_clamped_cosine_over_pi_and_f_prime_the_hemisphere() {
        // F of 1/π·max(cos, 0) has zonal coefficients A_l/(π·√(4π/(2l+1))) at every view.
        let t = lambert();
        let n = t.bands();
        let mut out = vec![0.0; n * n];
        for th in [0.0f32, 0.7, 1.4] {
            t.lookup_into(Part::WithCosine, th, n, &mut out).unwrap();
            for l in 0..n {
                let want = crate::sh::irradiance::clamped_cosine(l)
                    / crate::sh::convolve::funk_hecke(l)
                    / core::f64::consts::PI;
                for m in -(l as isize)..=l as isize {
                    let v = f64::from(out[crate::sh::index(l, m)]);
                    let w = if m == 0 { want } else { 0.0 };
                    assert!((v - w).abs() < 1e-6, "l {l} m {m}: {v} vs {w}");
                }
            }
            // F′ = [cos > 0]/π: the hemisphere cap of half-angle π/2, over π.
            t.lookup_into(Part::WithoutCosine, th, n, &mut out).unwrap();
            let mut z = vec![0.0f32; n];
            crate::sh::cap::zonal_into(core::f32::consts::FRAC_PI_2, n, &mut z).unwrap();
            for l in 0..n {
                let want = f64::from(z[l]) / core::f64::consts::PI;
                let v = f64::from(out[l * l + l]);
                assert!((v - want).abs() < 1e-6, "F′ l {l}: {v} vs {want}");
            }
        }
    }

    #[test]
    fn lookups_interpolate_and_clamp() {
        let t = phong();
        let n = t.bands();
        let (mut a, mut b, mut c) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        // At a sample: the stored value.
        t.lookup_into(Part::WithCosine, t.theta(5), n, &mut a)
            .unwrap();
        assert_eq!(a[0], t.stored_value(Part::WithCosine, 5, 0));
        // Half-way: the mean.
        t.lookup_into(Part::WithCosine, t.theta(6), n, &mut b)
            .unwrap();
        let mid = 0.5 * (t.theta(5) + t.theta(6));
        t.lookup_into(Part::WithCosine, mid, n, &mut c).unwrap();
        assert!((c[2] - 0.5 * (a[2] + b[2])).abs() < 1e-6 * a[2].abs().max(1.0));
        // Below the first and beyond the last sample: clamped; NaN → NaN.
        t.lookup_into(Part::WithCosine, -1.0, n, &mut a).unwrap();
        t.lookup_into(Part::WithCosine, 0.0, n, &mut b).unwrap();
        assert_eq!(a, b);
        t.lookup_into(Part::WithCosine, f32::NAN, n, &mut a)
            .unwrap();
        assert!(a[0].is_nan());
        assert!(
            t.lookup_into(Part::WithCosine, 0.0, n + 1, &mut vec![0.0; 1000])
                .is_err()
        );
        assert!(
            t.lookup_into(Part::WithCosine, 0.0, n, &mut a[..n * n - 1])
                .is_err()
        );
        // Fewer bands: a prefix.
        t.lookup_into(Part::WithCosine, 0.4, 2, &mut a).unwrap();
        t.lookup_into(Part::WithCosine, 0.4, n, &mut b).unwrap();
        assert_eq!(a[..4], b[..4]);
    }

    #[test]
    fn bad_bytes_are_errors() {
        let bytes = include_bytes!("tables/brdf_phong30.bin");
        let mut v = bytes.to_vec();
        v[HEADER_LEN + 8] ^= 1;
        assert!(BrdfSh::from_bytes(&v).is_err());
        assert!(BrdfSh::from_bytes(&bytes[..100]).is_err());
        assert!(BrdfSh::from_bytes(crate::lobe::cap::TABLE_BYTES).is_err());
    }

    #[test]
    fn the_view_frame_puts_the_view_in_the_xz_plane() {
        let n = Vec3::new(0.2, 0.3, 0.9).normalize();
        let v = Vec3::new(-0.5, 0.1, 0.6).normalize();
        let f = view_frame(n, v).unwrap();
        let l = f.to_local(v);
        assert!(l.y.abs() < 1e-6 && l.x > 0.0, "{l}");
        // Along the normal: any tangent, no error.
        assert!(view_frame(n, n).is_ok());
        assert!(view_frame(Vec3::ZERO, v).is_err());
    }
}
