//! The scene file format (JSON), validated while it is read.
//!
//! Every number is checked by the type it is read into ([`Positive`], [`Color`],
//! [`Direction`], …), so a bad value fails *inside* the deserializer and
//! `serde_path_to_error` names the field: `lights[1].sphere.radius: must be > 0 (got -1)`.
//! Checks that involve two fields (a material name that must exist, a camera whose `up` is
//! parallel to its view direction) are made afterwards, in [`super::Scene::from_file`],
//! with the same path style. Unknown fields are errors, so a typo is not silently ignored.
//! The format is documented in the README ("Scene files").

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer};

/// A whole scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The pinhole camera.
    pub camera: CameraFile,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialFile>,
    /// Spheres (surfaces with a material).
    #[serde(default)]
    pub spheres: Vec<SphereFile>,
    /// Infinite planes (surfaces with a material).
    #[serde(default)]
    pub planes: Vec<PlaneFile>,
    /// Lights: spherical lights and at most one environment.
    #[serde(default)]
    pub lights: Vec<LightFile>,
}

/// `camera`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    /// Eye position.
    pub eye: Point,
    /// Point looked at (must differ from `eye`).
    pub target: Point,
    /// Up direction (not parallel to `target − eye`).
    pub up: Direction,
    /// Vertical field of view in degrees, in `(0, 180)`.
    pub fov_y: FovDegrees,
    /// Image width in pixels, `1 ..= 16384`.
    pub width: Pixels,
    /// Image height in pixels, `1 ..= 16384`.
    pub height: Pixels,
}

/// One material: exactly one of the keys.
#[derive(Clone, Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialFile {
    /// `albedo/π`.
    Lambert {
        /// RGB albedo, each in `[0, 1]`.
        albedo: Albedo,
    },
    /// Energy-normalised modified Phong: `diffuse/π + specular·(n+2)/(2π)·max(r·ωi, 0)^n`.
    Phong {
        /// RGB diffuse albedo.
        diffuse: Albedo,
        /// RGB specular albedo.
        specular: Albedo,
        /// Exponent `n`, `0 ..= 1e5`.
        exponent: Exponent,
    },
    /// GGX microfacet: `diffuse/π + specular·D·G₂·F/(4 cos θi cos θo)` with the GGX `D` of
    /// roughness `α`, separable Smith `G₂` and Schlick's `F` from `f0` (core's `Ggx`).
    Ggx {
        /// RGB diffuse albedo.
        diffuse: Albedo,
        /// RGB tint of the specular term.
        specular: Albedo,
        /// Reflectance at normal incidence, `[0, 1]`.
        f0: UnitInterval,
        /// GGX `α` (perceptual roughness squared), `[1e-3, 1]`.
        roughness: Roughness,
    },
    /// Lafortune: `diffuse/π + Σ ρ_i·max(ωi·M_i·ωo, 0)^{e_i}` in the shading frame.
    Lafortune {
        /// RGB diffuse albedo.
        diffuse: Albedo,
        /// The lobes (1 to 4).
        lobes: Vec<LafortuneLobeFile>,
    },
}

/// One Lafortune lobe.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LafortuneLobeFile {
    /// Diagonal of `M` in the shading frame (`[-1, -1, 1]` is a lobe about the mirror
    /// direction).
    pub c: Point,
    /// Exponent `e`, `0 ..= 1e5`.
    pub exponent: Exponent,
    /// RGB scale `ρ` (non-negative).
    pub rho: Color,
}

/// A sphere with a material.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereFile {
    /// Centre.
    pub center: Point,
    /// Radius, `> 0`.
    pub radius: Positive,
    /// Material name (a key of `materials`).
    pub material: String,
}

/// An infinite plane with a material, lit on both sides.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneFile {
    /// A point of the plane.
    pub point: Point,
    /// Its normal (non-zero; normalised).
    pub normal: Direction,
    /// Material name (a key of `materials`).
    pub material: String,
}

/// One light: exactly one of the keys.
#[derive(Clone, Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum LightFile {
    /// A sphere emitting `radiance` uniformly from its surface.
    Sphere {
        /// Centre.
        center: Point,
        /// Radius, `> 0`.
        radius: Positive,
        /// RGB radiance (non-negative).
        radiance: Color,
    },
    /// An equirectangular environment.
    Environment {
        /// A `.exr`/`.hdr` path relative to the scene file's folder (or absolute), or
        /// `builtin:sky`.
        file: String,
        /// Factor on every texel, `≥ 0` (default 1).
        #[serde(default = "one")]
        scale: NonNegative,
    },
}

fn one() -> NonNegative {
    NonNegative(1.0)
}

/// Defines a validated number type read from JSON.
macro_rules! checked {
    ($(#[$m:meta])* $name:ident($t:ty), $ok:expr, $what:expr) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name(pub $t);

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let v = <$t>::deserialize(d)?;
                let ok: fn(&$t) -> bool = $ok;
                if ok(&v) {
                    Ok($name(v))
                } else {
                    Err(de::Error::custom(format_args!("{} (got {})", $what, Shown(&v))))
                }
            }
        }
    };
}

/// Formats a number or a triple for an error message.
struct Shown<'a, T>(&'a T);

impl fmt::Display for Shown<'_, f64> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}
impl fmt::Display for Shown<'_, u32> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}
impl fmt::Display for Shown<'_, [f64; 3]> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.0)
    }
}

const COORD_MAX: f64 = 1e6;

checked!(
    /// A finite point with coordinates within `±1e6`.
    Point([f64; 3]),
    |v| v.iter().all(|x| x.is_finite() && x.abs() <= COORD_MAX),
    "must be three finite numbers within ±1e6"
);
checked!(
    /// A non-zero finite direction.
    Direction([f64; 3]),
    |v| v.iter().all(|x| x.is_finite() && x.abs() <= COORD_MAX) && v.iter().any(|x| *x != 0.0),
    "must be a non-zero direction of finite numbers within ±1e6"
);
checked!(
    /// RGB, each finite and `≥ 0`.
    Color([f64; 3]),
    |v| v.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1e9),
    "must be three numbers in [0, 1e9]"
);
checked!(
    /// RGB albedo, each in `[0, 1]`.
    Albedo([f64; 3]),
    |v| v.iter().all(|x| (0.0..=1.0).contains(x)),
    "must be three numbers in [0, 1]"
);
checked!(
    /// A finite number `> 0` and `≤ 1e6`.
    Positive(f64),
    |v| *v > 0.0 && *v <= COORD_MAX,
    "must be > 0 and ≤ 1e6"
);
checked!(
    /// A finite number `≥ 0` and `≤ 1e9`.
    NonNegative(f64),
    |v| (0.0..=1e9).contains(v),
    "must be in [0, 1e9]"
);
checked!(
    /// A field of view in degrees, in `(0, 180)`.
    FovDegrees(f64),
    |v| *v > 0.0 && *v < 180.0,
    "must be in (0, 180) degrees"
);
checked!(
    /// A number in `[0, 1]`.
    UnitInterval(f64),
    |v| (0.0..=1.0).contains(v),
    "must be in [0, 1]"
);
checked!(
    /// A GGX roughness `α` in `[1e-3, 1]` (the range of core's `Ggx`).
    Roughness(f64),
    |v| (1e-3..=1.0).contains(v),
    "must be in [0.001, 1]"
);
checked!(
    /// An exponent in `[0, 1e5]`.
    Exponent(f64),
    |v| (0.0..=1e5).contains(v),
    "must be in [0, 1e5]"
);
checked!(
    /// An image dimension, `1 ..= 16384`.
    Pixels(u32),
    |v| (1..=16384).contains(v),
    "must be in 1..=16384"
);

/// Reads a scene file from JSON text; the error names the field.
pub fn parse(text: &str) -> Result<SceneFile, String> {
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." {
            inner.to_string()
        } else {
            format!("{path}: {inner}")
        }
    })
}
