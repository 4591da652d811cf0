//! The one math shim: every float function the kernels use goes through here, so no other
//! module needs a `cfg`. With the `std` feature the standard library is used, otherwise (or with
//! `force-libm`) the `libm` crate. Add a function with one line in the `shim!` list below.

macro_rules! shim {
    ($( $name:ident ( $t:ty $(, $arg:ident)* ) => $method:ident, $libm:ident ; )*) => {
        #[cfg(all(feature = "std", not(feature = "force-libm")))]
        mod imp {
            $(
                #[doc = concat!("`", stringify!($t), "::", stringify!($method), "` of the standard library.")]
                #[inline(always)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    x.$method($($arg),*)
                }
            )*
        }

        #[cfg(any(all(not(feature = "std"), feature = "libm"), feature = "force-libm"))]
        mod imp {
            $(
                #[doc = concat!("`libm::", stringify!($libm), "`.")]
                #[inline(always)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    libm::$libm(x $(, $arg)*)
                }
            )*
        }

        #[cfg(not(any(feature = "std", feature = "libm")))]
        mod imp {
            // The crate root emits a `compile_error!`; these keep the rest of the build quiet.
            $(
                #[allow(dead_code)]
                pub fn $name(x: $t $(, $arg: $t)*) -> $t {
                    $( let _ = $arg; )*
                    x
                }
            )*
        }
    };
}

shim! {
    sqrtf(f32) => sqrt, sqrtf;
    expf(f32) => exp, expf;
    expm1f(f32) => exp_m1, expm1f;
    logf(f32) => ln, logf;
    log1pf(f32) => ln_1p, log1pf;
    powf(f32, y) => powf, powf;
    sinf(f32) => sin, sinf;
    cosf(f32) => cos, cosf; // used by `brdf_sat` (feature `alloc`) only
    asinf(f32) => asin, asinf;
    acosf(f32) => acos, acosf;
    atan2f(f32, x2) => atan2, atan2f;
    ceilf(f32) => ceil, ceilf;
    floorf(f32) => floor, floorf;
    // f64 for table builders, statistics and the environment decomposition, not hot paths.
    sqrt64(f64) => sqrt, sqrt;
    cbrt64(f64) => cbrt, cbrt;
    sin64(f64) => sin, sin;
    cos64(f64) => cos, cos;
    atan2_64(f64, x2) => atan2, atan2;
    floor64(f64) => floor, floor;
}

pub use imp::*;
