//! SH coefficients of spherical caps, four caps per pass (mirrors
//! `steradian_core::sh::cap::coefficients_into`): the basis at the four axes on `f64` lanes
//! (the SH evaluation's twin, bit-identical), then each band scaled by the scalar kernel's
//! `f64` factors (`steradian_core::sh::cap::band_scales`, its recurrence on `wide::f64x4`
//! lanes) with one product and one rounding per coefficient, so every lane is
//! **bit-identical** to the scalar kernel, NaN included.

use steradian_core::sh::MAX_BANDS;
use steradian_core::sh::cap::{cap_trig, check_coefficients};
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
    let mut k = [f64x4::ZERO; MAX_BANDS];
    scales(half_angles, bands, &mut k);
    for (l, k) in k.iter().enumerate().take(bands) {
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
    let mut k = [f64x4::ZERO; MAX_BANDS];
    for i in (0..len).step_by(4) {
        let live = (len - i).min(4);
        let angles: [f32; 4] =
            core::array::from_fn(|j| if j < live { half_angle[i + j] } else { 0.0 });
        scales(angles, bands, &mut k);
        for (l, k) in k.iter().enumerate().take(bands) {
            for c in l * l..(l + 1) * (l + 1) {
                let at = c * len + i;
                if live == 4 {
                    let v: [f32; 4] = [out[at], out[at + 1], out[at + 2], out[at + 3]];
                    out[at..at + 4].copy_from_slice(&narrow(f64x4::new(v.map(f64::from)) * *k));
                } else {
                    let lanes = &mut out[at..at + live];
                    let v: [f64; 4] =
                        core::array::from_fn(|j| lanes.get(j).map_or(0.0, |x| f64::from(*x)));
                    lanes.copy_from_slice(&narrow(f64x4::new(v) * *k)[..live]);
                }
            }
        }
    }
    Ok(())
}

/// Each band's factor `√(4π/(2l+1))·L̃_l` of the four half-angles into `k[..bands]`:
/// `steradian_core::sh::cap::band_scales` on `f64` lanes (the same operations in the same
/// order from each lane's `cap_trig`), bit-identical per lane.
fn scales(half_angles: [f32; 4], bands: usize, k: &mut [f64x4; MAX_BANDS]) {
    if bands == 0 {
        return;
    }
    let t = half_angles.map(cap_trig);
    let lane = |i: usize| f64x4::new(t.map(|v| v[i]));
    let (h2, s2, x) = (lane(0), lane(1), lane(2));
    let pi = core::f64::consts::PI;
    let sp = f64x4::splat;
    k[0] = sp(4.0 * pi) * h2;
    let (mut p_prev, mut p) = (sp(1.0), x);
    let (mut dp_prev, mut dp) = (sp(0.0), sp(1.0));
    for (l, k) in k.iter_mut().enumerate().take(bands).skip(1) {
        let lf = l as f64;
        *k = sp(2.0 * pi) * s2 * dp / sp(lf * (lf + 1.0));
        let p_next = (sp(2.0 * lf + 1.0) * x * p - sp(lf) * p_prev) / sp(lf + 1.0);
        let dp_next = dp_prev + sp(2.0 * lf + 1.0) * p;
        (p_prev, p) = (p, p_next);
        (dp_prev, dp) = (dp, dp_next);
    }
}

/// The four lanes rounded to `f32`.
#[inline(always)]
fn narrow(v: f64x4) -> [f32; 4] {
    let a = v.to_array();
    [a[0] as f32, a[1] as f32, a[2] as f32, a[3] as f32]
}
