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

/// Directions with each special value in each component of `(0.3, 0.4)`-filled rows: three
/// rows per value, the special in x, in y and in z.
pub fn in_each_component() -> Vec<glam::Vec3> {
    SPECIALS
        .iter()
        .flat_map(|&s| {
            [
                glam::Vec3::new(s, 0.3, 0.4),
                glam::Vec3::new(0.3, s, 0.4),
                glam::Vec3::new(0.3, 0.4, s),
            ]
        })
        .collect()
}
