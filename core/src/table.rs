//! The table file format: a small header, then `f32` values, all little-endian.
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `b"STRDTBL\0"` |
//! | 8 | 4 | format version `u32` (= [`FORMAT_VERSION`]) |
//! | 12 | 4 | rank `u32` (1..=4) |
//! | 16 | 4 | channels `u32` (values per grid point) |
//! | 20 | 4 | reserved, zero |
//! | 24 | 16 | name, ASCII, zero-padded |
//! | 40 | 16 | dims `[u32; 4]` (unused axes = 1) |
//! | 56 | 32 | domain lower bounds `[f64; 4]` |
//! | 88 | 32 | domain upper bounds `[f64; 4]` |
//! | 120 | 8 | value count `u64` (= product of dims × channels) |
//! | 128 | 8 | FNV-1a 64 checksum of bytes `0..128` followed by the payload |
//! | 136 | 4·count | values `f32` |
//!
//! The built-in tables are decoded at compile time by a `const fn` (a corrupt committed table
//! fails the build, never a run). Tables from user bytes go through [`TableView::parse`], which
//! checks magic, version, shape, length and checksum and returns a [`TableError`].

use core::fmt;

/// Magic bytes at the start of every table.
pub const MAGIC: [u8; 8] = *b"STRDTBL\0";
/// Version of the header layout.
pub const FORMAT_VERSION: u32 = 1;
/// Size of the header in bytes.
pub const HEADER_LEN: usize = 136;

/// Why table bytes were rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TableError {
    /// Fewer bytes than the header, or than the header says the payload has.
    Truncated,
    /// The first eight bytes are not [`MAGIC`].
    BadMagic,
    /// Unknown header version.
    BadVersion(u32),
    /// Rank, channels or dims are inconsistent.
    BadShape,
    /// The name is not the one the caller expected.
    WrongName,
    /// The shape is not the one the caller expected.
    WrongShape,
    /// Payload bytes do not match the checksum.
    BadChecksum,
    /// The domain bounds are not finite with `lo < hi`.
    BadDomain,
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableError::Truncated => f.write_str("truncated table bytes"),
            TableError::BadMagic => f.write_str("not a steradian table (bad magic)"),
            TableError::BadVersion(v) => write!(f, "unsupported table format version {v}"),
            TableError::BadShape => f.write_str("inconsistent table shape"),
            TableError::WrongName => f.write_str("table has a different name than expected"),
            TableError::WrongShape => f.write_str("table has a different shape than expected"),
            TableError::BadChecksum => f.write_str("table checksum mismatch"),
            TableError::BadDomain => f.write_str("table domain is not finite and increasing"),
        }
    }
}

impl core::error::Error for TableError {}

/// The parsed header of a table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    /// Number of axes in use (1..=4).
    pub rank: u32,
    /// Values per grid point.
    pub channels: u32,
    /// Name, zero-padded ASCII.
    pub name: [u8; 16],
    /// Samples per axis (unused axes = 1).
    pub dims: [u32; 4],
    /// Lower domain bound per axis.
    pub lo: [f64; 4],
    /// Upper domain bound per axis.
    pub hi: [f64; 4],
    /// Number of `f32` values in the payload.
    pub count: u64,
    /// Checksum of the header prefix and payload (see [`checksum`]).
    pub checksum: u64,
}

/// FNV-1a 64-bit hash.
pub const fn fnv1a64(bytes: &[u8]) -> u64 {
    fnv1a64_continue(0xcbf2_9ce4_8422_2325, bytes)
}

/// The table checksum: FNV-1a 64 over the header up to the checksum field, then the payload,
/// so any single changed byte anywhere in a table is detected.
pub const fn checksum(header_prefix: &[u8], payload: &[u8]) -> u64 {
    fnv1a64_continue(fnv1a64(header_prefix), payload)
}

const fn fnv1a64_continue(mut h: u64, bytes: &[u8]) -> u64 {
    let mut i = 0;
    while i < bytes.len() {
        h ^= bytes[i] as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
        i += 1;
    }
    h
}

const fn rd_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

const fn rd_u64(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes([
        b[at],
        b[at + 1],
        b[at + 2],
        b[at + 3],
        b[at + 4],
        b[at + 5],
        b[at + 6],
        b[at + 7],
    ])
}

const fn name16(name: &str) -> [u8; 16] {
    let src = name.as_bytes();
    let mut out = [0u8; 16];
    let mut i = 0;
    while i < src.len() && i < 16 {
        out[i] = src[i];
        i += 1;
    }
    out
}

impl Header {
    /// Parses and validates a header and its payload length and checksum.
    pub const fn parse(bytes: &[u8]) -> Result<Header, TableError> {
        Self::parse_impl(bytes, true)
    }

    /// [`Header::parse`] without the checksum: magic, version, shape, domain and length
    /// only. For large built-in tables, whose checksum is too slow to verify in a `const`
    /// (their checksums are verified by tests and `steradian tables --check`).
    pub const fn parse_shape(bytes: &[u8]) -> Result<Header, TableError> {
        Self::parse_impl(bytes, false)
    }

    const fn parse_impl(bytes: &[u8], verify: bool) -> Result<Header, TableError> {
        if bytes.len() < HEADER_LEN {
            return Err(TableError::Truncated);
        }
        let mut i = 0;
        while i < 8 {
            if bytes[i] != MAGIC[i] {
                return Err(TableError::BadMagic);
            }
            i += 1;
        }
        let version = rd_u32(bytes, 8);
        if version != FORMAT_VERSION {
            return Err(TableError::BadVersion(version));
        }
        let rank = rd_u32(bytes, 12);
        let channels = rd_u32(bytes, 16);
        if rank == 0 || rank > 4 || channels == 0 {
            return Err(TableError::BadShape);
        }
        let mut name = [0u8; 16];
        let mut dims = [0u32; 4];
        let mut lo = [0f64; 4];
        let mut hi = [0f64; 4];
        i = 0;
        while i < 16 {
            name[i] = bytes[24 + i];
            i += 1;
        }
        let mut count: u64 = channels as u64;
        i = 0;
        while i < 4 {
            dims[i] = rd_u32(bytes, 40 + 4 * i);
            lo[i] = f64::from_bits(rd_u64(bytes, 56 + 8 * i));
            hi[i] = f64::from_bits(rd_u64(bytes, 88 + 8 * i));
            if dims[i] == 0 || (i as u32 >= rank && dims[i] != 1) {
                return Err(TableError::BadShape);
            }
            if (i as u32) < rank && !(lo[i].is_finite() && hi[i].is_finite() && lo[i] < hi[i]) {
                return Err(TableError::BadDomain);
            }
            count = match count.checked_mul(dims[i] as u64) {
                Some(c) => c,
                None => return Err(TableError::BadShape),
            };
            i += 1;
        }
        if rd_u32(bytes, 20) != 0 {
            return Err(TableError::BadShape);
        }
        if rd_u64(bytes, 120) != count {
            return Err(TableError::BadShape);
        }
        let payload_len = match (count as usize).checked_mul(4) {
            Some(n) => n,
            None => return Err(TableError::BadShape),
        };
        if bytes.len() != HEADER_LEN + payload_len {
            return Err(TableError::Truncated);
        }
        let stored = rd_u64(bytes, 128);
        let (head, payload) = bytes.split_at(HEADER_LEN);
        let (prefix, _) = head.split_at(128);
        if verify && checksum(prefix, payload) != stored {
            return Err(TableError::BadChecksum);
        }
        Ok(Header {
            rank,
            channels,
            name,
            dims,
            lo,
            hi,
            count,
            checksum: stored,
        })
    }

    /// Whether the header's name equals `name`.
    pub const fn has_name(&self, name: &str) -> bool {
        let want = name16(name);
        let mut i = 0;
        while i < 16 {
            if self.name[i] != want[i] {
                return false;
            }
            i += 1;
        }
        true
    }
}

/// Decodes a built-in table at compile time. Panics (a build error in a `const`) when the
/// bytes are not a valid table named `name` with exactly `N` values.
pub const fn decode_const<const N: usize>(bytes: &[u8], name: &str) -> (Header, [f32; N]) {
    let h = match Header::parse(bytes) {
        Ok(h) => h,
        Err(_) => panic!("built-in table failed validation"),
    };
    if !h.has_name(name) {
        panic!("built-in table has the wrong name");
    }
    if h.count != N as u64 {
        panic!("built-in table has the wrong length");
    }
    let mut out = [0f32; N];
    let mut i = 0;
    while i < N {
        out[i] = f32::from_bits(rd_u32(bytes, HEADER_LEN + 4 * i));
        i += 1;
    }
    (h, out)
}

/// A validated view of table bytes supplied at run time.
#[derive(Clone, Copy, Debug)]
pub struct TableView<'a> {
    header: Header,
    payload: &'a [u8],
}

impl<'a> TableView<'a> {
    /// Validates `bytes` (magic, version, shape, length, checksum).
    pub fn parse(bytes: &'a [u8]) -> Result<Self, TableError> {
        let header = Header::parse(bytes)?;
        Ok(TableView {
            header,
            payload: &bytes[HEADER_LEN..],
        })
    }

    /// Validates `bytes` and checks that the table has the expected name and value count.
    pub fn parse_expecting(bytes: &'a [u8], name: &str, count: usize) -> Result<Self, TableError> {
        let v = Self::parse(bytes)?;
        if !v.header.has_name(name) {
            return Err(TableError::WrongName);
        }
        if v.header.count != count as u64 {
            return Err(TableError::WrongShape);
        }
        Ok(v)
    }

    /// The header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.header.count as usize
    }

    /// Whether the table holds no values (never true for a valid table).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i`, or `None` past the end.
    pub fn get(&self, i: usize) -> Option<f32> {
        let b = self.payload.get(4 * i..4 * i + 4)?;
        Some(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// Copies the values into `out` (which must have [`len`](Self::len) elements);
    /// returns `WrongShape` otherwise.
    pub fn copy_to(&self, out: &mut [f32]) -> Result<(), TableError> {
        if out.len() != self.len() {
            return Err(TableError::WrongShape);
        }
        for (o, b) in out.iter_mut().zip(self.payload.chunks_exact(4)) {
            *o = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        }
        Ok(())
    }
}

/// Description of a table to encode (used by the generators in the harness).
#[derive(Clone, Copy, Debug)]
pub struct Spec<'a> {
    /// Name, at most 16 ASCII bytes.
    pub name: &'a str,
    /// Number of axes in use (1..=4).
    pub rank: u32,
    /// Values per grid point.
    pub channels: u32,
    /// Samples per axis (unused axes = 1).
    pub dims: [u32; 4],
    /// Lower domain bound per axis.
    pub lo: [f64; 4],
    /// Upper domain bound per axis.
    pub hi: [f64; 4],
}

/// Writes header and values into `out`, which must be exactly
/// `HEADER_LEN + 4 * values.len()` bytes. Returns `WrongShape` when the sizes disagree.
pub fn encode_into(spec: &Spec<'_>, values: &[f32], out: &mut [u8]) -> Result<(), TableError> {
    let count: u64 = spec.dims.iter().map(|&d| d as u64).product::<u64>() * spec.channels as u64;
    if count != values.len() as u64 || out.len() != HEADER_LEN + 4 * values.len() {
        return Err(TableError::WrongShape);
    }
    let (head, payload) = out.split_at_mut(HEADER_LEN);
    for (o, v) in payload.chunks_exact_mut(4).zip(values) {
        o.copy_from_slice(&v.to_le_bytes());
    }
    head.fill(0);
    head[0..8].copy_from_slice(&MAGIC);
    head[8..12].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    head[12..16].copy_from_slice(&spec.rank.to_le_bytes());
    head[16..20].copy_from_slice(&spec.channels.to_le_bytes());
    head[24..40].copy_from_slice(&name16(spec.name));
    for i in 0..4 {
        head[40 + 4 * i..44 + 4 * i].copy_from_slice(&spec.dims[i].to_le_bytes());
        head[56 + 8 * i..64 + 8 * i].copy_from_slice(&spec.lo[i].to_le_bytes());
        head[88 + 8 * i..96 + 8 * i].copy_from_slice(&spec.hi[i].to_le_bytes());
    }
    head[120..128].copy_from_slice(&count.to_le_bytes());
    let sum = checksum(&head[..128], payload);
    head[128..136].copy_from_slice(&sum.to_le_bytes());
    Header::parse(out).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> [u8; HEADER_LEN + 12] {
        let spec = Spec {
            name: "test",
            rank: 1,
            channels: 1,
            dims: [3, 1, 1, 1],
            lo: [0.0; 4],
            hi: [1.0; 4],
        };
        let mut out = [0u8; HEADER_LEN + 12];
        encode_into(&spec, &[1.0, 2.0, 3.0], &mut out).unwrap();
        out
    }

    #[test]
    fn round_trip() {
        let b = sample();
        let v = TableView::parse_expecting(&b, "test", 3).unwrap();
        assert_eq!(v.get(2), Some(3.0));
        assert_eq!(v.get(3), None);
        let (_, arr) = decode_const::<3>(&b, "test");
        assert_eq!(arr, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn rejects_corruption() {
        let good = sample();
        let mut b = good;
        b[0] = b'X';
        assert_eq!(TableView::parse(&b).unwrap_err(), TableError::BadMagic);
        let mut b = good;
        b[8] = 9;
        assert_eq!(TableView::parse(&b).unwrap_err(), TableError::BadVersion(9));
        let mut b = good;
        b[HEADER_LEN + 1] ^= 1;
        assert_eq!(TableView::parse(&b).unwrap_err(), TableError::BadChecksum);
        assert_eq!(
            TableView::parse(&good[..good.len() - 1]).unwrap_err(),
            TableError::Truncated
        );
        assert_eq!(
            TableView::parse(&good[..10]).unwrap_err(),
            TableError::Truncated
        );
        // every single-byte change anywhere is rejected
        for at in 0..good.len() {
            let mut b = good;
            b[at] ^= 0x10;
            assert!(TableView::parse(&b).is_err(), "flip at {at} accepted");
        }
        assert_eq!(
            TableView::parse_expecting(&good, "other", 3).unwrap_err(),
            TableError::WrongName
        );
        assert_eq!(
            TableView::parse_expecting(&good, "test", 4).unwrap_err(),
            TableError::WrongShape
        );
    }
}
