//! `f64` references for the BRDF models of `steradian_core::lobe::brdf` and their integrals over
//! squares of the equal-area parametrisation (`steradian_core::rsl::brdf_sat`).
//!
//! The models are written again here in their textbook form (normalised half vector,
//! `powf`, `tan²θ_h`, `G₁` as a ratio), independently of the rearranged `f32` forms in core,
//! so the comparison checks the algebra as well as the rounding.
//!
//! Integrals are adaptive 4×4 Gauss–Legendre over the square's own coordinates (a square of
//! any orientation), with cells near the specular peak forced down to a fraction of the lobe
//! width so no lobe falls between nodes; `dω = 2·du·dv` on the disk, zero outside it.
//! Transcendental functions come from `libm` (same results on every machine).

use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// A BRDF model with `f64` parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// `a/π`.
    Lambert {
        /// Albedo.
        a: f64,
    },
    /// Modified Phong (Lewis 1994).
    Phong {
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Exponent.
        e: f64,
    },
    /// Blinn–Phong, `(e+8)/(8π)` normalisation.
    BlinnPhong {
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Exponent.
        e: f64,
    },
    /// Ward 1992 eq. 5a.
    Ward {
        /// Diffuse reflectance.
        rd: f64,
        /// Specular reflectance.
        rs: f64,
        /// Roughness along the tangent.
        ax: f64,
        /// Roughness along the bitangent.
        ay: f64,
    },
    /// Lafortune et al. 1997: `Σ ρ·max(C_x wᵢx wₒx + C_y wᵢy wₒy + C_z wᵢz wₒz, 0)^e`, two
    /// lobes `[C_x, C_y, C_z, e, ρ]`.
    Lafortune {
        /// The lobes.
        lobes: [[f64; 5]; 2],
    },
    /// Cook–Torrance with GGX, separable Smith and Schlick.
    Ggx {
        /// Diffuse weight.
        kd: f64,
        /// Normal-incidence reflectance.
        f0: f64,
        /// Roughness.
        alpha: f64,
    },
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = dot(v, v).sqrt();
    v.map(|c| c / l)
}

impl Model {
    /// `ρ(wᵢ, wₒ)` (no cosine) for unit directions above the horizon; 0 otherwise.
    pub fn rho(&self, wi: [f64; 3], wo: [f64; 3]) -> f64 {
        if wi[2] <= 0.0 || wo[2] <= 0.0 {
            return 0.0;
        }
        // The half vector only where a model reads it (the quadratures call this millions
        // of times).
        let h = || unit([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]);
        match *self {
            Model::Lambert { a } => a / PI,
            Model::Phong { kd, ks, e } => {
                let r = [-wo[0], -wo[1], wo[2]];
                let c = dot(r, wi).max(0.0);
                // `pow(0, e) = 0` for `e > 0`: skipped, the same value.
                let p = if c > 0.0 || e == 0.0 {
                    libm::pow(c, e)
                } else {
                    0.0
                };
                kd / PI + ks * (e + 2.0) / (2.0 * PI) * p
            }
            Model::BlinnPhong { kd, ks, e } => {
                kd / PI + ks * (e + 8.0) / (8.0 * PI) * libm::pow(h()[2], e)
            }
            Model::Ward { rd, rs, ax, ay } => {
                let h = h();
                let tan2 = (1.0 - h[2] * h[2]) / (h[2] * h[2]);
                let sin2 = h[0] * h[0] + h[1] * h[1];
                let (c2, s2) = if sin2 > 0.0 {
                    (h[0] * h[0] / sin2, h[1] * h[1] / sin2)
                } else {
                    (1.0, 0.0)
                };
                let k = tan2 * (c2 / (ax * ax) + s2 / (ay * ay));
                rd / PI + rs * libm::exp(-k) / (4.0 * PI * ax * ay * (wi[2] * wo[2]).sqrt())
            }
            Model::Lafortune { lobes } => lobes
                .iter()
                .map(|&[cx, cy, cz, e, rho]| {
                    let d = cx * wi[0] * wo[0] + cy * wi[1] * wo[1] + cz * wi[2] * wo[2];
                    if d > 0.0 { rho * libm::pow(d, e) } else { 0.0 }
                })
                .sum(),
            Model::Ggx { kd, f0, alpha } => {
                let h = h();
                let a2 = alpha * alpha;
                let ch = h[2];
                let d = a2 / (PI * (ch * ch * (a2 - 1.0) + 1.0).powi(2));
                let g1 = |c: f64| 2.0 * c / (c + (a2 + (1.0 - a2) * c * c).sqrt());
                let f = f0 + (1.0 - f0) * (1.0 - dot(wi, h)).powi(5);
                kd / PI + d * g1(wi[2]) * g1(wo[2]) * f / (4.0 * wi[2] * wo[2])
            }
        }
    }

    /// `ρ(wᵢ, wₒ)·cos θᵢ`.
    pub fn rho_cos(&self, wi: [f64; 3], wo: [f64; 3]) -> f64 {
        self.rho(wi, wo) * wi[2].max(0.0)
    }

    /// Angular width of the narrowest feature (radians), as `Brdf::feature_angle`.
    pub fn feature_angle(&self) -> f64 {
        match *self {
            Model::Lambert { .. } => 1.0,
            Model::Phong { e, .. } => (1.0 / (e + 1.0).sqrt()).min(1.0),
            Model::BlinnPhong { e, .. } => (2.0 / (e + 1.0).sqrt()).min(1.0),
            Model::Ward { ax, ay, .. } => ax.min(ay),
            Model::Lafortune { lobes } => lobes
                .iter()
                .filter(|l| l[3] > 0.0)
                .map(|l| 1.0 / (l[3] + 1.0).sqrt())
                .fold(1.0, f64::min),
            Model::Ggx { alpha, .. } => alpha,
        }
    }
}

/// Exact inverse equal-area map of a disk point (the caller keeps `|p| < 1`).
pub fn unmap(p: [f64; 2]) -> [f64; 3] {
    let r2 = p[0] * p[0] + p[1] * p[1];
    let s = (2.0 - r2).sqrt();
    [p[0] * s, p[1] * s, 1.0 - r2]
}

/// Exact equal-area map of a unit direction in the upper hemisphere.
pub fn map(d: [f64; 3]) -> [f64; 2] {
    let s = 1.0 / (1.0 + d[2]).sqrt();
    [d[0] * s, d[1] * s]
}

/// 4-point Gauss–Legendre nodes and weights on `[0, 1]`.
const GX: [f64; 4] = [
    0.069_431_844_202_973_71,
    0.330_009_478_207_571_9,
    0.669_990_521_792_428_1,
    0.930_568_155_797_026_3,
];
const GW: [f64; 4] = [
    0.173_927_422_568_726_9,
    0.326_072_577_431_273_1,
    0.326_072_577_431_273_1,
    0.173_927_422_568_726_9,
];

/// Adaptive 4×4 Gauss–Legendre over rectangles of `(a, b)`: each cell is split in four
/// until the children's sum agrees with the parent's estimate within the cell's tolerance,
/// or while `force(cell)` asks for a split (cells near a lobe wider than a fraction of
/// it, cells cut by the horizon circle).
struct Adaptive<F, G> {
    f: F,
    force: G,
}

impl<F: Fn(f64, f64) -> f64, G: Fn([f64; 4]) -> bool> Adaptive<F, G> {
    fn gl(&self, r: [f64; 4]) -> f64 {
        let (dx, dy) = (r[2] - r[0], r[3] - r[1]);
        let mut s = 0.0;
        for (y, wy) in GX.iter().zip(GW) {
            for (x, wx) in GX.iter().zip(GW) {
                s += wx * wy * (self.f)(r[0] + dx * x, r[1] + dy * y);
            }
        }
        s * dx * dy
    }

    fn adapt(&self, r: [f64; 4], whole: f64, tol: f64, depth: u32) -> f64 {
        let (xm, ym) = (0.5 * (r[0] + r[2]), 0.5 * (r[1] + r[3]));
        let kids = [
            [r[0], r[1], xm, ym],
            [xm, r[1], r[2], ym],
            [r[0], ym, xm, r[3]],
            [xm, ym, r[2], r[3]],
        ];
        let est = kids.map(|k| self.gl(k));
        let sum: f64 = est.iter().sum();
        if depth >= 24 || (!(self.force)(r) && (sum - whole).abs() <= tol) {
            return sum;
        }
        kids.iter()
            .zip(est)
            .map(|(k, e)| self.adapt(*k, e, 0.5 * tol, depth + 1))
            .sum()
    }

    /// Integral over `rect` split into `n × n` starting cells, absolute tolerance `tol`.
    fn run(&self, rect: [f64; 4], n: usize, tol: f64) -> f64 {
        let (dx, dy) = (
            (rect[2] - rect[0]) / n as f64,
            (rect[3] - rect[1]) / n as f64,
        );
        let mut s = 0.0;
        for b in 0..n {
            for a in 0..n {
                let cell = [
                    rect[0] + dx * a as f64,
                    rect[1] + dy * b as f64,
                    rect[0] + dx * (a + 1) as f64,
                    rect[1] + dy * (b + 1) as f64,
                ];
                s += self.adapt(cell, self.gl(cell), tol / (n * n) as f64, 0);
            }
        }
        s
    }
}

/// `∫ ρ(wᵢ, wₒ)·cos θᵢ dωᵢ` over the square of the parametrisation plane with centre `c`,
/// half-diagonal `r`, turned by `angle` (radians, counter-clockwise) about its centre; to
/// an absolute tolerance `tol` (the adaptive estimate). Cells within six half-widths of the
/// specular peak are refined to half a lobe width, cells cut by the horizon circle to
/// `4e-3`.
pub fn square_integral(
    model: &Model,
    wo: [f64; 3],
    c: [f64; 2],
    r: f64,
    angle: f64,
    tol: f64,
) -> f64 {
    if wo[2] <= 0.0 || r <= 0.0 {
        return 0.0;
    }
    let h = r * FRAC_1_SQRT_2;
    let (sin, cos) = libm::sincos(angle);
    let pw = map(wo);
    let peak = [-pw[0], -pw[1]];
    let feature = 0.5 * model.feature_angle();
    let to_disk = |s: f64, t: f64| [c[0] + cos * s - sin * t, c[1] + sin * s + cos * t];
    let f = |s: f64, t: f64| {
        let p = to_disk(s, t);
        if p[0] * p[0] + p[1] * p[1] >= 1.0 {
            return 0.0;
        }
        2.0 * model.rho_cos(unmap(p), wo)
    };
    let force = |cell: [f64; 4]| {
        let size = (cell[2] - cell[0]).max(cell[3] - cell[1]);
        let m = to_disk(0.5 * (cell[0] + cell[2]), 0.5 * (cell[1] + cell[3]));
        let half_diag = 0.5 * size * std::f64::consts::SQRT_2;
        let d_peak = libm::hypot(m[0] - peak[0], m[1] - peak[1]) - half_diag;
        let rm = libm::hypot(m[0], m[1]);
        (size > 0.5 * feature && d_peak < 6.0 * feature)
            || (size > 4e-3 && (rm - 1.0).abs() < half_diag)
    };
    Adaptive { f, force }.run([-h, -h, h, h], 4, tol)
}

/// Directional albedo `∫_Ω ρ(wᵢ, wₒ)·cos θᵢ dωᵢ`, integrated in polar coordinates
/// `(ρ, φ)` of the disk (no kink at the horizon), to an absolute tolerance `tol`.
pub fn albedo(model: &Model, wo: [f64; 3], tol: f64) -> f64 {
    if wo[2] <= 0.0 {
        return 0.0;
    }
    let pw = map(wo);
    let peak = [-pw[0], -pw[1]];
    let feature = 0.5 * model.feature_angle();
    let f = |rho: f64, phi: f64| {
        let (s, c) = libm::sincos(phi);
        2.0 * rho * model.rho_cos(unmap([rho * c, rho * s]), wo)
    };
    let force = |cell: [f64; 4]| {
        let (rm, pm) = (0.5 * (cell[0] + cell[2]), 0.5 * (cell[1] + cell[3]));
        let (s, c) = libm::sincos(pm);
        let size = (cell[2] - cell[0]).max(cell[2] * (cell[3] - cell[1]));
        let d_peak = libm::hypot(rm * c - peak[0], rm * s - peak[1]) - size;
        size > 0.5 * feature && d_peak < 6.0 * feature
    };
    Adaptive { f, force }.run([0.0, 0.0, 1.0, 2.0 * PI], 8, tol)
}

/// The error metric of `steradian_core::rsl::brdf_sat`: `|got − exact| / max(exact, A·4r²/(2π))`
/// with `A` the directional albedo.
pub fn table_error(got: f64, exact: f64, albedo: f64, r: f64) -> f64 {
    let floor = albedo * 4.0 * r * r / (2.0 * PI);
    (got - exact).abs() / exact.max(floor)
}
