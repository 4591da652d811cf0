//! The cap-exponent lookup is finite, non-negative and monotone non-increasing in the
//! half-angle for every non-NaN input, and the table loader rejects every corruption of the
//! committed bytes without panicking.

use steradian_core::{lobe::cap, table::TableView};

/// The target's checks on one input.
pub fn check(data: &[u8]) {
    if data.len() >= 8 {
        let a = f32::from_le_bytes([data[0], data[1], data[2], data[3]]);
        let b = f32::from_le_bytes([data[4], data[5], data[6], data[7]]);
        let (ea, eb) = (cap::exponent_l2(a), cap::exponent_l2(b));
        for (x, e) in [(a, ea), (b, eb)] {
            if x.is_nan() {
                assert!(e.is_nan());
            } else {
                assert!(e.is_finite() && e >= 0.0, "exponent_l2({x}) = {e}");
            }
        }
        if a <= b {
            assert!(ea >= eb, "not monotone: e({a}) = {ea} < e({b}) = {eb}");
        }
    }
    // Arbitrary bytes never panic the loader.
    let _ = TableView::parse(data);
    // Any edit of the committed table is either a no-op or rejected.
    if data.len() >= 5 {
        let mut bytes = cap::TABLE_BYTES.to_vec();
        let at = u32::from_le_bytes([data[0], data[1], data[2], data[3]]) as usize % bytes.len();
        bytes[at] ^= data[4];
        let parsed = TableView::parse_expecting(&bytes, cap::TABLE_NAME, cap::TABLE_LEN);
        assert_eq!(
            parsed.is_ok(),
            data[4] == 0,
            "flip of byte {at} by {:#x}",
            data[4]
        );
    }
}
