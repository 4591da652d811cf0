//! The error type of every validating constructor.

use core::fmt;

/// What was wrong with user data given to a validating constructor or table loader.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A field was NaN or infinite.
    NonFinite {
        /// Which field.
        what: &'static str,
    },
    /// A direction was the zero vector (or too small to normalise).
    ZeroVector {
        /// Which field.
        what: &'static str,
    },
    /// A value was outside its allowed range `[min, max]`.
    OutOfRange {
        /// Which field.
        what: &'static str,
        /// The value given.
        value: f32,
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
    /// The shading point lies inside (or on) the sphere that should be seen as a cap.
    InsideSphere {
        /// Distance from the point to the centre.
        distance: f32,
        /// Radius of the sphere.
        radius: f32,
    },
    /// A matrix given as a rotation is not one: `max |RᵀR − I|` above `1e-5`, or not
    /// orientation-preserving.
    NotRotation {
        /// `max |RᵀR − I|` over the entries.
        orthogonality: f32,
        /// `det R` (must be positive).
        determinant: f32,
    },
    /// Table bytes failed validation.
    Table(crate::table::TableError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NonFinite { what } => write!(f, "{what} must be finite"),
            Error::ZeroVector { what } => write!(f, "{what} must be a non-zero vector"),
            Error::OutOfRange {
                what,
                value,
                min,
                max,
            } => write!(f, "{what} = {value} is outside [{min}, {max}]"),
            Error::InsideSphere { distance, radius } => write!(
                f,
                "the point is inside the sphere (distance {distance} to the centre, radius {radius})"
            ),
            Error::NotRotation {
                orthogonality,
                determinant,
            } => write!(
                f,
                "not a proper rotation: max |RᵀR − I| = {orthogonality} (at most 1e-5), det = {determinant} (must be > 0)"
            ),
            Error::Table(e) => write!(f, "table: {e}"),
        }
    }
}

impl core::error::Error for Error {}

impl From<crate::table::TableError> for Error {
    fn from(e: crate::table::TableError) -> Self {
        Error::Table(e)
    }
}
