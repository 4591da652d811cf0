//! HVL contributions, four HVLs to one receiver per pass (mirrors
//! `steradian_core::sh::hvl::contribution`): each HVL's geometry by the scalar kernel's own
//! `prepare` (lane by lane), the emission basis and the cap coefficients of the four on
//! `f64` lanes (the twins of `sh::eval_into` and `sh::cap::coefficients_into`,
//! bit-identical), the two dot products on `wide::f32x4` lanes in index order from `+0`,
//! and `P·e·G·s` left to right, so every lane is **bit-identical** to the scalar kernel.
//! The use: a shading point summing hundreds of HVLs (the paper's Table 1).

use steradian_core::sh::hvl::{Horizon, Hvl, Prepared, Receiver, prepare};
use steradian_core::sh::{bands_of, check_shape};
use steradian_core::{Error, Vec3};
use wide::f32x4;

/// The contributions of four HVLs to the receiver `rx`, lane-wise
/// `steradian_core::sh::hvl::contribution` with the same `emission` (the HVLs' material's
/// `F′`, shared) and `horizon`; `scratch` at least `max(n², n_e²)` entries.
///
/// Errors: coefficient counts that are not squares, a short `scratch`.
pub fn contributions_x4(
    hvls: [&Hvl; 4],
    emission: &[f32],
    rx: &Receiver<'_>,
    horizon: Horizon,
    scratch: &mut [[f32; 4]],
) -> Result<[f32; 4], Error> {
    let n = bands_of(rx.coeffs.len())?;
    let ne = bands_of(emission.len())?;
    check_shape(n.max(ne), scratch.len())?;
    // Each lane's geometry; settled lanes keep their value and run the SH part on a harmless
    // stand-in (+z, a zero cap, zero power), whose result is not used.
    let mut value: [Option<f32>; 4] = [None; 4];
    let (mut emit, mut axis) = ([Vec3::Z; 4], [Vec3::Z; 4]);
    let (mut angle, mut power, mut g) = ([0.0f32; 4], [0.0f32; 4], [0.0f32; 4]);
    for (k, h) in hvls.iter().enumerate() {
        match prepare(h, rx.point, &rx.frame, horizon) {
            Prepared::Value(v) => value[k] = Some(v),
            Prepared::Lit {
                emit_dir,
                cap_axis,
                half_angle,
                power: p,
                g: gk,
            } => {
                (emit[k], axis[k], angle[k], power[k], g[k]) =
                    (emit_dir, cap_axis, half_angle, p, gk);
            }
        }
    }
    if value.iter().all(Option::is_some) {
        return Ok(value.map(|v| v.unwrap_or(0.0)));
    }
    super::eval_x4(emit, ne, scratch)?;
    let mut e = f32x4::ZERO;
    for (a, y) in emission.iter().zip(scratch.iter()) {
        e += f32x4::splat(*a) * f32x4::new(*y);
    }
    super::cap::coefficients_x4(axis, angle, n, scratch)?;
    let mut s = f32x4::ZERO;
    for (f, c) in rx.coeffs.iter().zip(scratch.iter()) {
        s += f32x4::splat(*f) * f32x4::new(*c);
    }
    let r = (f32x4::new(power) * e * f32x4::new(g) * s).to_array();
    Ok(core::array::from_fn(|k| value[k].unwrap_or(r[k])))
}

/// [`contributions_x4`] over a slice of HVLs: `out[j]` is HVL `j`'s contribution to `rx`.
/// Any length (the tail repeats the last HVL and is not written).
///
/// Errors: as [`contributions_x4`]; `out` of another length than `hvls`.
pub fn contributions(
    hvls: &[Hvl],
    emission: &[f32],
    rx: &Receiver<'_>,
    horizon: Horizon,
    scratch: &mut [[f32; 4]],
    out: &mut [f32],
) -> Result<(), Error> {
    if out.len() != hvls.len() {
        return Err(Error::OutOfRange {
            what: "HVL output length",
            value: out.len() as f32,
            min: hvls.len() as f32,
            max: hvls.len() as f32,
        });
    }
    for (group, out) in hvls.chunks(4).zip(out.chunks_mut(4)) {
        let four: [&Hvl; 4] = core::array::from_fn(|k| &group[k.min(group.len() - 1)]);
        let c = contributions_x4(four, emission, rx, horizon, scratch)?;
        out.copy_from_slice(&c[..out.len()]);
    }
    Ok(())
}
