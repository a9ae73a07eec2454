//! Run-time CPU-feature dispatch for the solver's hot kernels. The default build is portable
//! (no `target-cpu=native`), so a binary runs on any CPU of its target; the kernels that gain
//! from wider vectors are compiled three times with `multiversion!`: generic, for AVX2 + FMA
//! (x86-64-v3), and for AVX-512 (x86-64-v4: 32 vector registers, which the solver's row
//! products need to stay out of memory); each call takes the best form [`level`] allows.
//!
//! Every form computes bit-identical results: enabling a feature changes the instructions, not
//! the arithmetic (Rust never contracts `a * b + c` into a fused multiply-add on its own, and
//! the kernels call no `mul_add`). Setting `EMILION_NO_SIMD=1` in the environment forces the
//! generic forms, `EMILION_NO_SIMD=512` the AVX2 ones at most, for checking exactly that.

use std::sync::atomic::{AtomicU8, Ordering};

/// Name of the environment variable that, set to anything but empty or `0`, forces the generic
/// forms of the kernels (`512`: forbids the AVX-512 forms only).
pub const NO_SIMD_VAR: &str = "EMILION_NO_SIMD";

/// The instruction-set level the kernels run at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The target's baseline (SSE2 on x86-64).
    Generic = 1,
    /// AVX2 and FMA (x86-64-v3).
    Avx2 = 2,
    /// AVX-512 F, VL, BW, DQ and CD on top of AVX2 and FMA (x86-64-v4).
    Avx512 = 3,
}

/// The chosen level; 0 while not yet checked.
static CHOICE: AtomicU8 = AtomicU8::new(0);

/// The level the kernels run at: the best the CPU has that `EMILION_NO_SIMD` does not forbid.
/// Checked once, then read from a cached value (one relaxed load per call).
#[inline]
pub fn level() -> Level {
    match CHOICE.load(Ordering::Relaxed) {
        1 => Level::Generic,
        2 => Level::Avx2,
        3 => Level::Avx512,
        _ => detect(),
    }
}

/// Whether the kernels take an AVX2 (or better) form.
#[inline]
pub fn avx2_fma() -> bool {
    level() >= Level::Avx2
}

#[cold]
fn detect() -> Level {
    let var = std::env::var_os(NO_SIMD_VAR).unwrap_or_default();
    let cap = match var.to_str() {
        Some("") | Some("0") => Level::Avx512,
        Some("512") => Level::Avx2,
        _ => Level::Generic,
    };
    let level = cpu_level().min(cap);
    CHOICE.store(level as u8, Ordering::Relaxed);
    level
}

#[cfg(target_arch = "x86_64")]
fn cpu_level() -> Level {
    use std::arch::is_x86_feature_detected as has;
    if !(has!("avx2") && has!("fma")) {
        Level::Generic
    } else if has!("avx512f")
        && has!("avx512vl")
        && has!("avx512bw")
        && has!("avx512dq")
        && has!("avx512cd")
    {
        Level::Avx512
    } else {
        Level::Avx2
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn cpu_level() -> Level {
    Level::Generic
}

/// Defines a function whose body is compiled three times, generic, for AVX2 + FMA and for
/// AVX-512 (x86-64 only), and which runs the best form [`level`] allows. Everything the body
/// inlines, and the closures it defines (they inherit the enabled features), is compiled for
/// the wider registers too, so a whole loop nest handed to a parallel loop is vectorised; what
/// it calls that does not inline runs generic.
///
/// The function may not be generic and its parameters must be plain names.
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
                #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq,avx512cd")]
                #[allow(clippy::too_many_arguments)]
                fn avx512($($arg: $ty),*) $(-> $ret)? $body
                match $crate::cloth::solver::simd::level() {
                    // SAFETY: the CPU has the features (checked at run time).
                    $crate::cloth::solver::simd::Level::Avx512 => return unsafe { avx512($($arg),*) },
                    // SAFETY: as above.
                    $crate::cloth::solver::simd::Level::Avx2 => return unsafe { avx2($($arg),*) },
                    $crate::cloth::solver::simd::Level::Generic => {}
                }
            }
            $body
        }
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
