//! steradian-simd's integration tests, one binary (as `wide` does): the lane-by-lane
//! contract of every batch kernel against its scalar kernel in `steradian-core`.

mod common;
mod contract;
mod product;
