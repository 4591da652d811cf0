//! Named special values the SIMD tests put in every field and lane position.

/// Non-finite, signed zeros, subnormals, the ends of the range and ordinary values.
pub const SPECIALS: [f32; 27] = [
    f32::NAN,
    -f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.0,
    -0.0,
    1e-40,   // subnormal
    -1e-40,  // subnormal
    1.0e-45, // smallest subnormal
    f32::MIN_POSITIVE,
    f32::MAX,
    -f32::MAX,
    3e38,
    1e30,
    -1e30,
    1e-30,
    -1e-30,
    1.0,
    -1.0,
    1e-7,
    -1e-7,
    1e-3,
    0.5,
    0.70710677,
    2.0,
    3.0,
    1e5,
];
