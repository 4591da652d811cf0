//! The one math shim: every float function the kernels use goes through here, so no other
//! module needs a `cfg`. With the `std` feature the standard library is used, otherwise the
//! `libm` crate. Add a function with one line in the `shim!` list below.

// Some functions serve only modules behind the `alloc` feature; without it they are unused.
macro_rules! shim {
    ($( $name:ident ( $($arg:ident),* ) => $method:ident ; )*) => {
        #[cfg(feature = "std")]
        mod imp {
            $(
                #[inline(always)]
                #[cfg_attr(not(feature = "alloc"), allow(dead_code))]
                pub fn $name(x: f32 $(, $arg: f32)*) -> f32 {
                    x.$method($($arg),*)
                }
            )*
        }

        #[cfg(all(not(feature = "std"), feature = "libm"))]
        mod imp {
            $(
                #[inline(always)]
                #[cfg_attr(not(feature = "alloc"), allow(dead_code))]
                pub fn $name(x: f32 $(, $arg: f32)*) -> f32 {
                    libm::$name(x $(, $arg)*)
                }
            )*
        }

        #[cfg(not(any(feature = "std", feature = "libm")))]
        mod imp {
            // The crate root emits a `compile_error!`; these keep the rest of the build quiet.
            $(
                #[allow(dead_code)]
                pub fn $name(x: f32 $(, $arg: f32)*) -> f32 {
                    $( let _ = $arg; )*
                    x
                }
            )*
        }
    };
}

shim! {
    sqrtf() => sqrt;
    expf() => exp;
    expm1f() => exp_m1;
    logf() => ln;
    log1pf() => ln_1p;
    powf(y) => powf;
    sinf() => sin;
    cosf() => cos; // used by `brdf_sat` (feature `alloc`) only
    asinf() => asin;
    atan2f(x2) => atan2;
    ceilf() => ceil;
    floorf() => floor;
}

pub(crate) use imp::*;

/// `f64` square root and cube root (table builders and statistics, not hot paths), from the
/// same backend as the `f32` functions above.
#[cfg(feature = "std")]
mod imp64 {
    #[inline(always)]
    #[allow(dead_code)]
    pub fn sqrt64(x: f64) -> f64 {
        x.sqrt()
    }
    #[inline(always)]
    #[allow(dead_code)]
    pub fn cbrt64(x: f64) -> f64 {
        x.cbrt()
    }
}
#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp64 {
    #[inline(always)]
    #[allow(dead_code)]
    pub fn sqrt64(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline(always)]
    #[allow(dead_code)]
    pub fn cbrt64(x: f64) -> f64 {
        libm::cbrt(x)
    }
}
#[cfg(not(any(feature = "std", feature = "libm")))]
mod imp64 {
    // Unreachable: the crate root emits a `compile_error!`.
    #[allow(dead_code)]
    pub fn sqrt64(x: f64) -> f64 {
        x
    }
    #[allow(dead_code)]
    pub fn cbrt64(x: f64) -> f64 {
        x
    }
}
pub(crate) use imp64::*;
