//! Lane helpers: bit equality, every row in every lane position, slice lengths.

/// Bit-identical, or both NaN (payloads may differ).
pub fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Slice lengths the slice functions are run at.
pub const LENGTHS: [usize; 6] = [0, 1, 7, 8, 9, 1000];

/// Runs `check(rows)` on the rows with 0..8 filler rows in front, so every row lands in
/// every lane position (and in the padded tail).
pub fn in_every_lane<T: Copy>(rows: &[T], filler: T, mut check: impl FnMut(&[T])) {
    for shift in 0..8 {
        let mut r = vec![filler; shift];
        r.extend_from_slice(rows);
        check(&r);
    }
}
