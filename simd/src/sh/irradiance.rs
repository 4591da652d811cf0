//! Irradiance from one radiance vector at four normals per pass (mirrors
//! `steradian_core::sh::irradiance::irradiance`): the basis at the four normals by
//! [`super::eval_x4`] (bit-identical to the scalar basis), then the scalar kernel's `f64`
//! sums on `wide::f64x4` lanes — each band's products in index order from `+0`, times the
//! band's clamped-cosine factor, the bands in order — so every lane is **bit-identical** to
//! the scalar kernel, NaN included. The use: an irradiance map, one environment's
//! coefficients at every texel's normal.

use steradian_core::sh::irradiance::clamped_cosine;
use steradian_core::sh::{bands_of, check_shape};
use steradian_core::{Error, Vec3};
use wide::f64x4;

/// `E(n) = ∫ L(ω)·max(n·ω, 0) dω` (not divided by π) of the radiance coefficients `radiance`
/// (`n²` values) at four normals, lane-wise `steradian_core::sh::irradiance::irradiance`.
/// `scratch` holds the basis (`n²` entries).
///
/// Errors: `radiance.len()` not a square of at most `MAX_BANDS²`, or `scratch` shorter.
pub fn irradiance_x4(
    radiance: &[f32],
    normals: [Vec3; 4],
    scratch: &mut [[f32; 4]],
) -> Result<[f32; 4], Error> {
    let bands = bands_of(radiance.len())?;
    super::eval_x4(normals, bands, scratch)?;
    let mut e = f64x4::ZERO;
    for l in 0..bands {
        let a = clamped_cosine(l);
        if a == 0.0 {
            continue;
        }
        let span = l * l..(l + 1) * (l + 1);
        let mut band = f64x4::ZERO;
        for (r, y) in radiance[span.clone()].iter().zip(&scratch[span]) {
            band += f64x4::splat(f64::from(*r)) * f64x4::new(y.map(f64::from));
        }
        e += f64x4::splat(a) * band;
    }
    let e = e.to_array();
    Ok([e[0] as f32, e[1] as f32, e[2] as f32, e[3] as f32])
}

/// [`irradiance_x4`] over structure-of-arrays normal columns: `out[i]` is the irradiance
/// at `(nx[i], ny[i], nz[i])`. Any length (the tail is padded with `+z` and not written).
///
/// Errors: as [`irradiance_x4`]; the columns and `out` of different lengths.
pub fn irradiance_slices(
    radiance: &[f32],
    nx: &[f32],
    ny: &[f32],
    nz: &[f32],
    scratch: &mut [[f32; 4]],
    out: &mut [f32],
) -> Result<(), Error> {
    let len = nx.len();
    let bands = bands_of(radiance.len())?;
    check_shape(bands, scratch.len())?;
    if ny.len() != len || nz.len() != len || out.len() != len {
        return Err(Error::OutOfRange {
            what: "SH irradiance column length",
            value: out.len() as f32,
            min: len as f32,
            max: len as f32,
        });
    }
    for i in (0..len).step_by(4) {
        let live = (len - i).min(4);
        let normals: [Vec3; 4] = core::array::from_fn(|k| {
            if k < live {
                Vec3::new(nx[i + k], ny[i + k], nz[i + k])
            } else {
                Vec3::Z
            }
        });
        let e = irradiance_x4(radiance, normals, scratch)?;
        out[i..i + live].copy_from_slice(&e[..live]);
    }
    Ok(())
}
