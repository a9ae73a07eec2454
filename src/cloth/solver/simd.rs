//! Run-time CPU-feature dispatch for the solver's hot kernels. The default build is portable
//! (no `target-cpu=native`), so a binary runs on any CPU of its target; the kernels that gain
//! from wider vectors are compiled twice with `multiversion!`, generic and with AVX2 and FMA
//! enabled, and each call takes the AVX2 form when [`avx2_fma`] says the CPU has both.
//!
//! Both forms compute bit-identical results: enabling a feature changes the instructions, not
//! the arithmetic (Rust never contracts `a * b + c` into a fused multiply-add on its own, and
//! the kernels call no `mul_add`). Setting `EMILION_NO_SIMD=1` in the environment forces the
//! generic forms, for checking exactly that.

use std::sync::atomic::{AtomicU8, Ordering};

/// Name of the environment variable that, set to anything but empty or `0`, forces the generic
/// forms of the kernels.
pub const NO_SIMD_VAR: &str = "EMILION_NO_SIMD";

/// Not yet checked / the generic forms / the AVX2 forms.
const UNKNOWN: u8 = 0;
const GENERIC: u8 = 1;
const AVX2_FMA: u8 = 2;

static CHOICE: AtomicU8 = AtomicU8::new(UNKNOWN);

/// Whether the kernels take their AVX2 + FMA forms: the CPU has both features and
/// `EMILION_NO_SIMD` does not forbid them. Checked once, then read from a cached flag (one
/// relaxed load per call).
#[inline]
pub fn avx2_fma() -> bool {
    match CHOICE.load(Ordering::Relaxed) {
        AVX2_FMA => true,
        GENERIC => false,
        _ => detect(),
    }
}

#[cold]
fn detect() -> bool {
    let forbidden = std::env::var_os(NO_SIMD_VAR).is_some_and(|v| !v.is_empty() && v != "0");
    let yes = !forbidden && cpu_has_avx2_fma();
    CHOICE.store(if yes { AVX2_FMA } else { GENERIC }, Ordering::Relaxed);
    yes
}

#[cfg(target_arch = "x86_64")]
fn cpu_has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

#[cfg(not(target_arch = "x86_64"))]
fn cpu_has_avx2_fma() -> bool {
    false
}

/// Defines a function whose body is compiled twice, generic and with AVX2 and FMA enabled
/// (x86-64 only), and which runs the AVX2 form when [`avx2_fma`] allows it. Everything the
/// body inlines, and the closures it defines (they inherit the enabled features), is compiled
/// for the wider registers too, so a whole loop nest handed to a parallel loop is vectorised;
/// what it calls that does not inline runs generic.
///
/// The function may not be generic and its parameters must be plain names. A method (taking
/// `&self` or `&mut self`) names its AVX2 twin after a slash, `fn name / name_avx2(&self, ..)`:
/// the twin is a private method of the same type.
///
/// ```ignore
/// multiversion! {
///     /// Doc comment.
///     pub(crate) fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
///         for (yi, xi) in y.iter_mut().zip(x) {
///             *yi += a * xi;
///         }
///     }
/// }
/// ```
macro_rules! multiversion {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                #[allow(clippy::too_many_arguments)]
                fn avx2($($arg: $ty),*) $(-> $ret)? $body
                if $crate::cloth::solver::simd::avx2_fma() {
                    // SAFETY: the CPU has AVX2 and FMA (checked at run time).
                    return unsafe { avx2($($arg),*) };
                }
            }
            $body
        }
    };
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident / $fast:ident(&mut $s:ident $(, $arg:ident: $ty:ty)* $(,)?)
        $(-> $ret:ty)? $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name(&mut $s $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::cloth::solver::simd::avx2_fma() {
                // SAFETY: the CPU has AVX2 and FMA (checked at run time).
                return unsafe { $s.$fast($($arg),*) };
            }
            $body
        }
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        #[allow(clippy::too_many_arguments)]
        fn $fast(&mut $s $(, $arg: $ty)*) $(-> $ret)? $body
    };
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident / $fast:ident(&$s:ident $(, $arg:ident: $ty:ty)* $(,)?)
        $(-> $ret:ty)? $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name(&$s $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::cloth::solver::simd::avx2_fma() {
                // SAFETY: the CPU has AVX2 and FMA (checked at run time).
                return unsafe { $s.$fast($($arg),*) };
            }
            $body
        }
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        #[allow(clippy::too_many_arguments)]
        fn $fast(&$s $(, $arg: $ty)*) $(-> $ret)? $body
    };
}
pub(crate) use multiversion;

#[cfg(test)]
mod tests {
    use super::*;

    multiversion! {
        /// A reduction whose rounding depends on the order of its operations.
        fn weighted_sum(x: &[f64], w: &[f64]) -> f64 {
            let mut acc = 0.0;
            for (a, b) in x.iter().zip(w) {
                acc += a * b + 0.1 * a;
            }
            acc
        }
    }

    #[test]
    fn both_forms_round_alike() {
        let x: Vec<f64> = (0..1000).map(|k| (k as f64 * 0.37).sin() * 1e3).collect();
        let w: Vec<f64> = (0..1000).map(|k| 1.0 / (1.0 + k as f64)).collect();
        let fast = weighted_sum(&x, &w);
        let mut slow = 0.0;
        for (a, b) in x.iter().zip(&w) {
            slow += std::hint::black_box(a * b) + std::hint::black_box(0.1 * a);
        }
        assert_eq!(fast.to_bits(), slow.to_bits());
        // the choice is made once and kept
        assert_eq!(avx2_fma(), avx2_fma());
    }
}
