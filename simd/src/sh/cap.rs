//! SH coefficients of spherical caps, four caps per pass (mirrors
//! `steradian_core::sh::cap::coefficients_into`): the basis at the four axes on `f64` lanes
//! (the SH evaluation's twin, bit-identical), then each band scaled by the scalar kernel's
//! own `f64` factors (`steradian_core::sh::cap::band_scales`, per lane) with one product
//! and one rounding per coefficient on `wide::f64x4` lanes, so every lane is
//! **bit-identical** to the scalar kernel, NaN included.

use steradian_core::sh::MAX_BANDS;
use steradian_core::sh::cap::{band_scales, check_coefficients};
use steradian_core::{Error, Vec3};
use wide::f64x4;

/// `∫_cap Y_l^m dω` of four caps (axes `axes`, half-angles `half_angles`): `out[k][lane]` is
/// coefficient `k` of cap `lane`, lane-wise `steradian_core::sh::cap::coefficients_into`.
///
/// Errors: a half-angle outside `[0, π]` or NaN, `bands > MAX_BANDS`, `out` shorter than
/// `bands²` (nothing is written then).
pub fn coefficients_x4(
    axes: [Vec3; 4],
    half_angles: [f32; 4],
    bands: usize,
    out: &mut [[f32; 4]],
) -> Result<(), Error> {
    for a in half_angles {
        check_coefficients(a, bands, out.len())?;
    }
    super::eval_x4(axes, bands, out)?;
    let scales = scales(half_angles, bands);
    for (l, k) in scales.iter().enumerate().take(bands) {
        for v in &mut out[l * l..(l + 1) * (l + 1)] {
            *v = narrow(f64x4::new(v.map(f64::from)) * *k);
        }
    }
    Ok(())
}

/// [`coefficients_x4`] over structure-of-arrays columns: coefficient `k` of the cap around
/// `(ax[i], ay[i], az[i])` of half-angle `half_angle[i]` goes to `out[k·len + i]`
/// (`len = ax.len()`). Any length.
///
/// Errors: as [`coefficients_x4`] for any cap; the columns of different lengths or `out`
/// not of length `bands²·len` (nothing is written then).
pub fn coefficients_slices(
    ax: &[f32],
    ay: &[f32],
    az: &[f32],
    half_angle: &[f32],
    bands: usize,
    out: &mut [f32],
) -> Result<(), Error> {
    let len = ax.len();
    if half_angle.len() != len {
        return Err(Error::OutOfRange {
            what: "SH cap column length",
            value: half_angle.len() as f32,
            min: len as f32,
            max: len as f32,
        });
    }
    for &a in half_angle {
        check_coefficients(a, bands, usize::MAX)?;
    }
    // The basis (its own column checks), then each group of four scaled in place.
    super::eval_slices(ax, ay, az, bands, out)?;
    for i in (0..len).step_by(4) {
        let live = (len - i).min(4);
        let angles: [f32; 4] =
            core::array::from_fn(|k| if k < live { half_angle[i + k] } else { 0.0 });
        let scales = scales(angles, bands);
        for (l, k) in scales.iter().enumerate().take(bands) {
            for c in l * l..(l + 1) * (l + 1) {
                let at = c * len + i;
                let lanes = &mut out[at..at + live];
                let v: [f64; 4] =
                    core::array::from_fn(|j| lanes.get(j).map_or(0.0, |x| f64::from(*x)));
                lanes.copy_from_slice(&narrow(f64x4::new(v) * *k)[..live]);
            }
        }
    }
    Ok(())
}

/// Each band's factor `√(4π/(2l+1))·L̃_l` of the four half-angles, lanes side by side.
fn scales(half_angles: [f32; 4], bands: usize) -> [f64x4; MAX_BANDS] {
    let mut k = [[0.0f64; 4]; MAX_BANDS];
    for (lane, a) in half_angles.into_iter().enumerate() {
        band_scales(a, bands, |l, s| k[l][lane] = s);
    }
    k.map(f64x4::new)
}

/// The four lanes rounded to `f32`.
#[inline(always)]
fn narrow(v: f64x4) -> [f32; 4] {
    let a = v.to_array();
    [a[0] as f32, a[1] as f32, a[2] as f32, a[3] as f32]
}
