//! Rotatable square lights (RSL): one region of a decomposed environment map, and its
//! projection into a shading point's equal-area hemisphere parametrisation (rotatable
//! square lights paper, sections 3 and 4.1.1, Figures 3–4, eq. 5–6).
//!
//! ## Representation
//!
//! The paper writes an RSL as `⟨c, r, I⟩`: centre direction `c`, half-diagonal `r` and
//! average intensity `I`, with light integral `2r²·I`. We keep the same information in
//! units that need no convention to read:
//!
//! - [`Rsl::centre`]: unit centre direction `c` in world space;
//! - [`Rsl::tangent`]: unit tangent at `c` (orthogonal to it) giving the orientation of the
//!   fitted square. The paper's fit averages its error over the square's rotation (that is
//!   what makes the light *rotatable*), so the shading step does not need it; it is kept
//!   for drawing and for the decomposition's best-fitting rotation;
//! - [`Rsl::solid_angle`]: the solid angle `Ω` of the square, in steradians;
//! - [`Rsl::energy`]: the light integral `∫_S L dω` over the region, RGB (the paper's
//!   `2r²·I`; the decomposition makes it exactly the region's integral, so the energy of the
//!   environment is preserved). [`Rsl::radiance`] gives the paper's average `I = energy/Ω`;
//! - [`Rsl::gradient`] (an extension, zero by default): a radiance gradient per channel,
//!   a world-space vector orthogonal to `c`, for the linear light model
//!   `L(ω) = energy/Ω + G·(ω − c)` over the square that the moments kernel
//!   ([`crate::rsl::shade::light_moments`]) evaluates. The paper's lights are uniform
//!   (`G = 0`); the harness's decomposition sets `G` by matching the square's first moment
//!   of radiance to the region's ([`crate::rsl::decompose`], "Radiance gradient").
//!
//! ## Projection (paper Figure 3 and eq. 6)
//!
//! At a shading point with frame `F` the centre becomes `c' = F⁻¹·c` and the region is
//! approximated by a square in the equal-area parametrisation of
//! [`crate::rsl::hemisphere`] with centre `p = map(c')` and half-diagonal `r`:
//!
//! ```text
//!   p = (c'x, c'y)/sqrt(1 + c'z)          (|p|² = 1 − c'z)
//!   r = sqrt(Ω)/2                          (area 2r² of the square = Ω/2, since dω = 2·du·dv)
//! ```
//!
//! The map is equal-area, so the square always carries exactly the light's solid angle
//! wherever it lies: this is what lets the paper use one `r` for every shading point.
//! For a centre **below the horizon** (`c'z < 0`) the same formula is the Lambert azimuthal
//! equal-area map extended to the whole sphere (radius `sqrt(1 − z)` up to `√2` at the
//! antipode, still `dω = 2·du·dv`), so a light straddling the horizon becomes a square
//! straddling the unit circle and the part outside the disk, below the horizon, falls on
//! texels where the cosine-weighted BRDF table is zero. [`map_extended`] is that map;
//! [`ProjectedSquare::is_below_horizon`] tells when the whole square is outside the disk.
//!
//! ## Accuracy
//!
//! - The centre is within [`crate::rsl::hemisphere::MAP_ABS_ERROR`] of the exact map, and
//!   `2·area(R) = Ω` up to one f32 rounding (by construction).
//! - The *shape* is the paper's approximation (section 6.2): to first order in the light's
//!   size the map at polar angle `γ` of `c'` scales radial lengths by `k/√2` and tangential
//!   ones by `1/(√2·k)`, `k = cos(γ/2) = sqrt((1 + c'z)/2)`, so a square on the sphere
//!   becomes a rectangle of aspect `1/k²` (1 at the normal, 2 at the horizon). The
//!   axis-aligned square `R` of the paper then mismatches the exact projected region. The
//!   harness test `projection_mismatch_square_and_box` measures the symmetric difference
//!   as a fraction of `R`'s area, averaged over the square's four fitted rotations (an RSL's
//!   orientation is free, so this includes the mismatch between a square and its own
//!   rotations: 22 % at the normal, where the projection itself is exact), for a light of
//!   0.01 sr (the test asserts these plus one point):
//!
//!   | polar angle / azimuth of `c'` | 0° | 30°/30° | 60°/30° | 80°/30° | 60°/0° | 80°/0° |
//!   |---|---|---|---|---|---|---|
//!   | square `R` ([`project`], paper) | 21.8 % | 24.3 % | 28.4 % | 37.7 % | 31.1 % | 43.4 % |
//!   | box ([`project_box`]) | 21.8 % | 24.0 % | 26.1 % | 32.5 % | 22.4 % | 22.7 % |
//!
//! - [`project_box`] is our improvement: the same summed-area-table cost (4 lookups) with
//!   an axis-aligned box whose half-extents follow the projected region's second moments,
//!   `hx ∝ sqrt(k²cos²φ + k⁻²sin²φ)`, `hy ∝ sqrt(k²sin²φ + k⁻²cos²φ)` (`φ` the azimuth of
//!   `c'`), scaled so that `4·hx·hy = Ω/2`. A visibility distance table needs a square;
//!   use [`project`] there.
//!
//! ## Bad input
//!
//! [`Rsl::new`] validates and returns [`Error`]. The projections never panic: NaN in any
//! component gives NaN out; a zero local direction maps to the pole.
//!
//! # References
//!
//! - K. Xu, Y.-T. Jia, S.-M. Hu, C.-L. Tai, "All-frequency environment light rendering
//!   using rotatable square light and multiple product approximation", 2006 (the text
//!   this folder implements; no DOI is known to us). Section, figure and equation numbers
//!   in this folder are its.
//! - F. C. Crow, "Summed-area tables for texture mapping", *SIGGRAPH '84 Proceedings*
//!   (Computer Graphics 18(3)), pp. 207–212, 1984 (the summed-area table, [`sat`]).

#[cfg(feature = "alloc")]
pub mod brdf_sat;
#[cfg(feature = "alloc")]
pub mod cubemap;
#[cfg(feature = "alloc")]
pub mod decompose;
pub mod hemisphere;
pub mod sat;
pub mod shade;
pub mod vdt;
pub mod vis_moments;
pub mod visibility;

use crate::frame::{Frame, check_dir, normalize_or_zero};
use crate::math;
use crate::{Error, Vec2, Vec3};

/// Rec. 709 / sRGB luminance weights, used to reduce an RGB light to one value.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Luminance of an RGB triple ([`LUMINANCE`] weights).
#[inline]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    LUMINANCE[0] * rgb[0] + LUMINANCE[1] * rgb[1] + LUMINANCE[2] * rgb[2]
}

/// Largest solid angle an RSL may have: the whole sphere, `4π` sr.
pub const MAX_SOLID_ANGLE: f32 = 4.0 * crate::PI;

/// A rotatable square light: centre direction, orientation, solid angle and light integral.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
#[cfg_attr(feature = "bytemuck", derive(bytemuck::Pod, bytemuck::Zeroable))]
pub struct Rsl {
    centre: Vec3,
    tangent: Vec3,
    solid_angle: f32,
    energy: [f32; 3],
    gradient: [Vec3; 3],
}

impl Rsl {
    /// The byte layout of the `#[repr(C)]` type, which `wgsl::TYPES` declares as `Rsl`.
    pub const LAYOUT: crate::wgsl::Layout = crate::wgsl::Layout {
        name: "Rsl",
        size: core::mem::size_of::<Rsl>(),
        fields: &[
            ("centre", core::mem::offset_of!(Rsl, centre)),
            ("tangent", core::mem::offset_of!(Rsl, tangent)),
            ("solid_angle", core::mem::offset_of!(Rsl, solid_angle)),
            ("energy", core::mem::offset_of!(Rsl, energy)),
            ("gradient", core::mem::offset_of!(Rsl, gradient)),
        ],
    };

    /// A validated RSL. `centre` is normalised; `tangent` is made orthogonal to it
    /// (Gram–Schmidt) and normalised; `solid_angle` must lie in `[f32::MIN_POSITIVE, 4π]`
    /// (a subnormal one has no finite reciprocal); each `energy` channel (the light
    /// integral `∫_S L dω`) must be finite and non-negative.
    pub fn new(
        centre: Vec3,
        tangent: Vec3,
        solid_angle: f32,
        energy: [f32; 3],
    ) -> Result<Rsl, Error> {
        let c = check_dir(centre, "RSL centre")?;
        let t0 = check_dir(tangent, "RSL tangent")?;
        let t = normalize_or_zero(t0 - c * c.dot(t0));
        if t == Vec3::ZERO || !t.is_finite() || t.dot(c).abs() > 1e-3 {
            return Err(Error::ZeroVector {
                what: "RSL tangent orthogonal to the centre",
            });
        }
        if !solid_angle.is_finite() {
            return Err(Error::NonFinite {
                what: "RSL solid angle",
            });
        }
        // Subnormal solid angles are rejected too: their reciprocal overflows.
        if !(f32::MIN_POSITIVE..=MAX_SOLID_ANGLE).contains(&solid_angle) {
            return Err(Error::OutOfRange {
                what: "RSL solid angle",
                value: solid_angle,
                min: f32::MIN_POSITIVE,
                max: MAX_SOLID_ANGLE,
            });
        }
        for e in energy {
            if !e.is_finite() {
                return Err(Error::NonFinite { what: "RSL energy" });
            }
            if e < 0.0 {
                return Err(Error::OutOfRange {
                    what: "RSL energy",
                    value: e,
                    min: 0.0,
                    max: f32::MAX,
                });
            }
        }
        Ok(Rsl {
            centre: c,
            tangent: t,
            solid_angle,
            energy,
            gradient: [Vec3::ZERO; 3],
        })
    }

    /// The same light with the radiance gradient `G` per channel (module docs): the
    /// component of each vector along the centre is removed (the model is first order in
    /// the tangent plane). Errors: a non-finite component, before or after that projection
    /// (which overflows only for components near `f32::MAX`).
    pub fn with_gradient(mut self, gradient: [Vec3; 3]) -> Result<Rsl, Error> {
        for (g, out) in gradient.iter().zip(&mut self.gradient) {
            let t = *g - self.centre * self.centre.dot(*g);
            if !g.is_finite() || !t.is_finite() {
                return Err(Error::NonFinite {
                    what: "RSL radiance gradient",
                });
            }
            *out = t;
        }
        Ok(self)
    }

    /// Unit centre direction `c` (world space).
    #[inline]
    pub fn centre(&self) -> Vec3 {
        self.centre
    }
    /// Unit tangent at the centre: the direction of the fitted square's first side.
    #[inline]
    pub fn tangent(&self) -> Vec3 {
        self.tangent
    }
    /// Solid angle `Ω` of the square, steradians.
    #[inline]
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }
    /// Light integral `∫_S L dω` over the region, RGB (the paper's `2r²·I`).
    #[inline]
    pub fn energy(&self) -> [f32; 3] {
        self.energy
    }
    /// Radiance gradient per channel, world space, orthogonal to the centre (zero unless
    /// set by [`Rsl::with_gradient`]; module docs).
    #[inline]
    pub fn gradient(&self) -> [Vec3; 3] {
        self.gradient
    }
    /// Luminance of [`Rsl::energy`].
    #[inline]
    pub fn luminance(&self) -> f32 {
        luminance(self.energy)
    }
    /// Average radiance over the square, `energy/Ω` (the paper's `I`).
    #[inline]
    pub fn radiance(&self) -> [f32; 3] {
        let inv = 1.0 / self.solid_angle;
        [
            self.energy[0] * inv,
            self.energy[1] * inv,
            self.energy[2] * inv,
        ]
    }
    /// Half-diagonal of the square in the hemisphere parametrisation's disk units:
    /// `r = sqrt(Ω)/2` (the paper's `r`).
    #[inline]
    pub fn half_diagonal(&self) -> f32 {
        half_diagonal(self.solid_angle)
    }
    /// The paper's square in the local parametrisation of `frame` (see the module docs).
    #[inline]
    pub fn project(&self, frame: &Frame) -> ProjectedSquare {
        project(frame.to_local(self.centre), self.solid_angle)
    }
    /// The moment-matched axis-aligned box in the local parametrisation of `frame`.
    #[inline]
    pub fn project_box(&self, frame: &Frame) -> ProjectedBox {
        project_box(frame.to_local(self.centre), self.solid_angle)
    }
}

/// Half-diagonal in disk units of a square of solid angle `omega`: `sqrt(Ω)/2`.
#[inline]
pub fn half_diagonal(omega: f32) -> f32 {
    0.5 * math::sqrtf(omega)
}

/// The equal-area map of [`crate::rsl::hemisphere::map`] extended to the whole sphere (Lambert
/// azimuthal equal-area, scaled by `1/√2`): `p = (x, y)/sqrt(1 + z)` of the normalised
/// input, `|p| = sqrt(1 − z) ∈ [0, √2]`, `dω = 2·du·dv` everywhere. For `z ≥ 0` it equals
/// [`crate::rsl::hemisphere::map`]. The antipode `−z`, whose image is the whole circle of radius
/// `√2`, maps to `(√2, 0)`. NaN in gives NaN; the zero vector gives the pole.
#[inline]
pub fn map_extended(dir: Vec3) -> Vec2 {
    let d = normalize_or_zero(dir);
    if d.z >= 0.0 || d.z.is_nan() || d == Vec3::ZERO {
        return crate::rsl::hemisphere::map(dir);
    }
    let s2 = d.x * d.x + d.y * d.y;
    let rho = math::sqrtf(1.0 - d.z);
    if s2 > 0.0 {
        let k = rho / math::sqrtf(s2);
        Vec2::new(d.x * k, d.y * k)
    } else {
        Vec2::new(core::f32::consts::SQRT_2, 0.0)
    }
}

/// A square in the disk units of the hemisphere parametrisation (`[-1, 1]²`, the unit disk
/// being the upper hemisphere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectedSquare {
    /// Centre `p`.
    pub centre: Vec2,
    /// Half-diagonal `r` (the square's side is `√2·r`).
    pub half_diagonal: f32,
}

impl ProjectedSquare {
    /// Area in disk units, `2r²` (solid angle `4r²`).
    #[inline]
    pub fn area(&self) -> f32 {
        2.0 * self.half_diagonal * self.half_diagonal
    }
    /// Whether the whole square lies outside the unit disk, i.e. below the horizon
    /// (conservative: tested on the square's circumscribed circle).
    #[inline]
    pub fn is_below_horizon(&self) -> bool {
        math::sqrtf(self.centre.length_squared()) - self.half_diagonal >= 1.0
    }
    /// Centre and half-diagonal in texel units of an `n × n` grid over `[-1, 1]²` (texel
    /// `(i, j)` covers `[i, i+1] × [j, j+1]`), as the summed-area and visibility distance
    /// tables take them: `((p + 1)·n/2, r·n/2)`.
    #[inline]
    pub fn to_texels(&self, n: u32) -> (Vec2, f32) {
        let h = 0.5 * n as f32;
        ((self.centre + Vec2::ONE) * h, self.half_diagonal * h)
    }
}

/// An axis-aligned box in disk units of the hemisphere parametrisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectedBox {
    /// Centre `p`.
    pub centre: Vec2,
    /// Half-extents `(hx, hy)`; `4·hx·hy` is the area in disk units.
    pub half_extent: Vec2,
}

impl ProjectedBox {
    /// Area in disk units, `4·hx·hy`.
    #[inline]
    pub fn area(&self) -> f32 {
        4.0 * self.half_extent.x * self.half_extent.y
    }
    /// Whether the whole box lies outside the unit disk (below the horizon).
    #[inline]
    pub fn is_below_horizon(&self) -> bool {
        let near = Vec2::new(
            (self.centre.x.abs() - self.half_extent.x).max(0.0),
            (self.centre.y.abs() - self.half_extent.y).max(0.0),
        );
        near.length_squared() >= 1.0
    }
    /// Corners `(u0, v0, u1, v1)` in texel units of an `n × n` grid over `[-1, 1]²`.
    #[inline]
    pub fn to_texels(&self, n: u32) -> [f32; 4] {
        let h = 0.5 * n as f32;
        let lo = (self.centre - self.half_extent + Vec2::ONE) * h;
        let hi = (self.centre + self.half_extent + Vec2::ONE) * h;
        [lo.x, lo.y, hi.x, hi.y]
    }
}

/// The paper's square for a light of solid angle `omega` centred on the local direction
/// `local_centre` (need not be unit): centre [`map_extended`], half-diagonal
/// [`half_diagonal`]. A negative or NaN `omega` gives a NaN half-diagonal.
#[inline]
pub fn project(local_centre: Vec3, omega: f32) -> ProjectedSquare {
    ProjectedSquare {
        centre: map_extended(local_centre),
        half_diagonal: half_diagonal(omega),
    }
}

/// The moment-matched axis-aligned box for a light of solid angle `omega` centred on
/// `local_centre` (see the module docs): same centre and area as [`project`], half-extents
/// proportional to the projected region's extents along u and v.
#[inline]
pub fn project_box(local_centre: Vec3, omega: f32) -> ProjectedBox {
    let d = normalize_or_zero(local_centre);
    let centre = map_extended(local_centre);
    // k² = cos²(γ/2) = (1 + z)/2, kept away from 0 at the antipode (below the horizon).
    let k2 = (0.5 * (1.0 + d.z)).max(1e-6);
    let s2 = d.x * d.x + d.y * d.y;
    let (c2, sn2) = if s2 > 0.0 {
        (d.x * d.x / s2, d.y * d.y / s2)
    } else {
        (0.5, 0.5)
    };
    let inv_k2 = 1.0 / k2;
    let sx = math::sqrtf(k2 * c2 + inv_k2 * sn2);
    let sy = math::sqrtf(k2 * sn2 + inv_k2 * c2);
    // hx/hy = sqrt(sx/sy)² … i.e. hx = sqrt(Ω/8·sx/sy), hy = sqrt(Ω/8·sy/sx).
    let a = 0.125 * omega;
    let ratio = sx / sy;
    let hx = math::sqrtf(a * ratio);
    let hy = math::sqrtf(a / ratio);
    let nan = d.x + d.y + d.z + omega - omega;
    if nan.is_nan() {
        return ProjectedBox {
            centre,
            half_extent: Vec2::new(f32::NAN, f32::NAN),
        };
    }
    ProjectedBox {
        centre,
        half_extent: Vec2::new(hx, hy),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_validates() {
        let ok = Rsl::new(
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 0.3),
            0.1,
            [1.0; 3],
        );
        let r = ok.unwrap();
        assert!((r.centre() - Vec3::Z).length() < 1e-6);
        assert!((r.tangent() - Vec3::X).length() < 1e-6);
        assert!((r.radiance()[0] - 10.0).abs() < 1e-5);
        assert!((r.luminance() - 1.0).abs() < 1e-6);
        assert!((r.half_diagonal() - 0.5 * 0.1f32.sqrt()).abs() < 1e-7);
        let bad = [
            Rsl::new(Vec3::ZERO, Vec3::X, 0.1, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::Z, 0.1, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::new(f32::NAN, 0.0, 0.0), 0.1, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::X, 0.0, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::X, 1e-40, [1.0; 3]), // subnormal: 1/Ω overflows
            Rsl::new(Vec3::Z, Vec3::X, 13.0, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::X, f32::NAN, [1.0; 3]),
            Rsl::new(Vec3::Z, Vec3::X, 0.1, [1.0, -1.0, 0.0]),
            Rsl::new(Vec3::Z, Vec3::X, 0.1, [1.0, f32::INFINITY, 0.0]),
        ];
        for b in bad {
            assert!(b.is_err(), "{b:?}");
        }
        // The gradient: zero by default, projected onto the tangent plane, finite only.
        assert_eq!(r.gradient(), [Vec3::ZERO; 3]);
        let g = r
            .with_gradient([Vec3::new(1.0, 2.0, 3.0), Vec3::Z, Vec3::ZERO])
            .unwrap()
            .gradient();
        assert_eq!(g, [Vec3::new(1.0, 2.0, 0.0), Vec3::ZERO, Vec3::ZERO]);
        assert!(r.with_gradient([Vec3::X, Vec3::NAN, Vec3::X]).is_err());
        assert!(
            r.with_gradient([Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::X, Vec3::X])
                .is_err()
        );
    }

    #[test]
    fn extended_map_matches_hemisphere_and_is_continuous() {
        for d in [
            Vec3::Z,
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::X,
            Vec3::new(0.0, 1.0, 1e-7),
        ] {
            assert_eq!(map_extended(d), crate::rsl::hemisphere::map(d));
        }
        // across the horizon: continuous, radius sqrt(1 − z)
        let a = map_extended(Vec3::new(0.6, 0.8, 1e-6));
        let b = map_extended(Vec3::new(0.6, 0.8, -1e-6));
        assert!((a - b).length() < 1e-5, "{a} {b}");
        let d = Vec3::new(0.3, 0.4, -0.5).normalize();
        let p = map_extended(d);
        assert!((p.length() - (1.0 - d.z).sqrt()).abs() < 1e-6);
        assert!((p.normalize() - Vec2::new(0.6, 0.8)).length() < 1e-6);
        assert_eq!(
            map_extended(-Vec3::Z),
            Vec2::new(core::f32::consts::SQRT_2, 0.0)
        );
        assert!(map_extended(Vec3::new(f32::NAN, 0.0, -1.0)).is_nan());
        assert_eq!(map_extended(Vec3::ZERO), Vec2::ZERO);
    }

    #[test]
    fn projection_area_texels_and_horizon() {
        let f = Frame::from_normal(Vec3::Z).unwrap();
        let l = Rsl::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X, 0.02, [1.0; 3]).unwrap();
        let s = l.project(&f);
        assert_eq!(s.centre, Vec2::ZERO);
        assert!((2.0 * s.area() - 0.02).abs() < 1e-8);
        let (c, r) = s.to_texels(32);
        assert_eq!(c, Vec2::splat(16.0));
        assert!((r - 16.0 * s.half_diagonal).abs() < 1e-6);
        assert!(!s.is_below_horizon());
        let b = l.project_box(&f);
        assert!((2.0 * b.area() - 0.02).abs() < 1e-8);
        assert!((b.half_extent.x - b.half_extent.y).abs() < 1e-7);
        let [u0, v0, u1, v1] = b.to_texels(32);
        assert!((u1 - u0 - (v1 - v0)).abs() < 1e-5 && (u0 + u1 - 32.0).abs() < 1e-5);
        // a light straight below is culled, one on the horizon is not
        let down = Rsl::new(-Vec3::Z, Vec3::X, 0.02, [1.0; 3]).unwrap();
        assert!(down.project(&f).is_below_horizon());
        assert!(down.project_box(&f).is_below_horizon());
        let side = Rsl::new(Vec3::X, Vec3::Y, 0.02, [1.0; 3]).unwrap();
        assert!(!side.project(&f).is_below_horizon());
        assert!(!side.project_box(&f).is_below_horizon());
        // at the horizon, radial (x) extent shrinks by k = cos 45°, tangential grows
        let bx = side.project_box(&f);
        assert!((bx.half_extent.y / bx.half_extent.x - 2.0).abs() < 1e-5);
        // bad values propagate as NaN, no panic
        assert!(
            project_box(Vec3::new(f32::NAN, 0.0, 1.0), 0.1)
                .half_extent
                .is_nan()
        );
        assert!(project(Vec3::Z, f32::NAN).half_diagonal.is_nan());
    }
}
