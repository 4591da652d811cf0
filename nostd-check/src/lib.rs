//! A `#![no_std]` consumer of `steradian-core` with the `libm` math backend. It builds in
//! the workspace (and for `thumbv7em-none-eabihf` where that target is installed), proving
//! the core needs neither std nor alloc.
#![no_std]

use steradian_core::{Vec3, lobe, lobe::cap, rsl::hemisphere};

/// Runs one kernel of each kind without std: map a direction, evaluate a lobe, fit a cap.
pub fn smoke() -> f32 {
    let p = hemisphere::map(Vec3::new(0.3, 0.4, 0.5));
    let l = lobe::CosineLobe::saturating(Vec3::Z, 1.0, 8.0);
    p.x + l.eval(hemisphere::unmap(p)) + cap::exponent_l2(0.1) + l.integral()
}
