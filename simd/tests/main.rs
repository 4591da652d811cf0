//! steradian-simd's integration tests, one binary (as `wide` does): the lane-by-lane
//! contract of every batch kernel against its scalar kernel in `steradian-core`: the
//! cosine-lobe kernels (`contract`, `product`) and the rotatable-square-lights kernels
//! (`rsl`: SAT, VDT, eq. 5 and moments shading), the control-point query (`cp`).

mod common;
mod contract;
mod cp;
mod product;
mod rsl;
mod sh;
