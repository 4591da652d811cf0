//! The batch kernels ([`crate::kernels::Batch`]), one folder entry per paper: what the
//! backends run, the default workload with its named hard cases, the f64 reference and the
//! error metric of each. The registry ([`crate::registry::KERNELS`]) lists them.

pub mod lobe;
pub mod rsl;
