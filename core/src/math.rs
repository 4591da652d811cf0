//! The one math shim: every float function the kernels use goes through here, so no other
//! module needs a `cfg`. With the `std` feature the standard library is used, otherwise the
//! `libm` crate. Add a function with one line in the `shim!` list below.

macro_rules! shim {
    ($( $name:ident ( $($arg:ident),* ) => $method:ident ; )*) => {
        #[cfg(feature = "std")]
        mod imp {
            $(
                #[inline(always)]
                #[allow(dead_code)]
                pub fn $name(x: f32 $(, $arg: f32)*) -> f32 {
                    x.$method($($arg),*)
                }
            )*
        }

        #[cfg(all(not(feature = "std"), feature = "libm"))]
        mod imp {
            $(
                #[inline(always)]
                #[allow(dead_code)]
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
    cosf() => cos;
    asinf() => asin;
    atan2f(x2) => atan2;
    ceilf() => ceil;
    floorf() => floor;
}

pub(crate) use imp::*;
