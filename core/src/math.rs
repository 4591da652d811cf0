//! The one math shim: every float function the kernels use goes through here, so no other
//! module needs a `cfg`. With the `std` feature the standard library is used, otherwise the
//! `libm` crate.

#[cfg(feature = "std")]
mod imp {
    #[inline(always)]
    pub fn sqrtf(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline(always)]
    pub fn expf(x: f32) -> f32 {
        x.exp()
    }
    #[inline(always)]
    pub fn log1pf(x: f32) -> f32 {
        x.ln_1p()
    }
    #[inline(always)]
    pub fn powf(x: f32, y: f32) -> f32 {
        x.powf(y)
    }
    #[inline(always)]
    pub fn sinf(x: f32) -> f32 {
        x.sin()
    }
    #[inline(always)]
    pub fn asinf(x: f32) -> f32 {
        x.asin()
    }
    #[inline(always)]
    pub fn ceilf(x: f32) -> f32 {
        x.ceil()
    }
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp {
    #[inline(always)]
    pub fn sqrtf(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline(always)]
    pub fn expf(x: f32) -> f32 {
        libm::expf(x)
    }
    #[inline(always)]
    pub fn log1pf(x: f32) -> f32 {
        libm::log1pf(x)
    }
    #[inline(always)]
    pub fn powf(x: f32, y: f32) -> f32 {
        libm::powf(x, y)
    }
    #[inline(always)]
    pub fn sinf(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline(always)]
    pub fn asinf(x: f32) -> f32 {
        libm::asinf(x)
    }
    #[inline(always)]
    pub fn ceilf(x: f32) -> f32 {
        libm::ceilf(x)
    }
}

#[cfg(not(any(feature = "std", feature = "libm")))]
mod imp {
    // The crate root emits a `compile_error!`; these keep the rest of the build quiet.
    pub fn sqrtf(x: f32) -> f32 {
        x
    }
    pub fn expf(x: f32) -> f32 {
        x
    }
    pub fn log1pf(x: f32) -> f32 {
        x
    }
    pub fn powf(x: f32, _y: f32) -> f32 {
        x
    }
    pub fn sinf(x: f32) -> f32 {
        x
    }
    pub fn asinf(x: f32) -> f32 {
        x
    }
    pub fn ceilf(x: f32) -> f32 {
        x
    }
}

pub(crate) use imp::*;
