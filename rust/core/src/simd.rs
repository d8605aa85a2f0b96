//! Runtime SIMD dispatch for the generic (abi3, baseline x86-64) wheel.
//!
//! The kernels that vectorise (loop-area sums, finiteness and min/max scans, …) are written
//! once as plain Rust over fixed lanes (`[f64; 8]` accumulators, independent chains of
//! additions) and marked `#[inline(always)]`; [`dispatch!`] compiles each of them three
//! times — for the baseline (SSE2 on x86-64; NEON on aarch64, where it is the baseline), for
//! AVX2 and for AVX-512 — and picks one by the CPU's features, detected once per process
//! ([`level`]). The same source in the same order of operations: every path gives the
//! scalar path's numbers bit for bit (no fused multiply-add is formed: Rust never contracts
//! `a * b + c`), which the tests check for every path the machine has.
//!
//! `CONTACTLAB_SIMD=generic|avx2|avx512` caps the level (read once, at the first call).
//!
//! The one unsafe operation of the crate lives here: calling a `#[target_feature]` function,
//! which is sound only on a CPU with those features — each call is guarded by the runtime
//! detection of exactly the features the function enables.
#![allow(unsafe_code)]

use std::sync::OnceLock;

/// An instruction-set level a kernel can run at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The build's baseline (SSE2 on x86-64, NEON on aarch64).
    Generic,
    /// x86-64 AVX2 + FMA.
    Avx2,
    /// x86-64 AVX-512 (F, VL, DQ) with AVX2 + FMA.
    Avx512,
}

impl Level {
    /// Every level, lowest first.
    pub const ALL: [Level; 3] = [Level::Generic, Level::Avx2, Level::Avx512];

    /// Whether this CPU can run kernels compiled for the level.
    pub fn supported(self) -> bool {
        match self {
            Level::Generic => true,
            #[cfg(target_arch = "x86_64")]
            Level::Avx2 => {
                std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Level::Avx512 => {
                Level::Avx2.supported()
                    && std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl")
                    && std::is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The level's name (as `CONTACTLAB_SIMD` takes it).
    pub fn name(self) -> &'static str {
        match self {
            Level::Generic => "generic",
            Level::Avx2 => "avx2",
            Level::Avx512 => "avx512",
        }
    }
}

static LEVEL: OnceLock<Level> = OnceLock::new();

/// The level the kernels run at: the highest this CPU supports, capped by
/// `CONTACTLAB_SIMD`; detected at the first call, the same for the whole process.
pub fn level() -> Level {
    *LEVEL.get_or_init(|| {
        let cap = std::env::var("CONTACTLAB_SIMD")
            .ok()
            .and_then(|v| Level::ALL.into_iter().find(|l| l.name() == v.trim()))
            .unwrap_or(Level::Avx512);
        Level::ALL
            .into_iter()
            .filter(|&l| l <= cap && l.supported())
            .max()
            .unwrap_or(Level::Generic)
    })
}

/// `dispatch!(pub fn name(a: A, …) -> R = generic_fn;)`: `name(level, a, …)` runs
/// `generic_fn` (which must be `#[inline(always)]`) compiled for `level` when the CPU has it,
/// else for the baseline.
macro_rules! dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident : $ty:ty),* $(,)?) -> $ret:ty = $generic:path;) => {
        $(#[$meta])*
        #[allow(unsafe_code)]
        $vis fn $name(level: $crate::simd::Level, $($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                fn avx2($($arg: $ty),*) -> $ret {
                    $generic($($arg),*)
                }
                #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
                fn avx512($($arg: $ty),*) -> $ret {
                    $generic($($arg),*)
                }
                match level {
                    // SAFETY: the CPU has every feature `avx512` is compiled for (checked).
                    $crate::simd::Level::Avx512 if $crate::simd::Level::Avx512.supported() => {
                        return unsafe { avx512($($arg),*) };
                    }
                    // SAFETY: the CPU has every feature `avx2` is compiled for (checked).
                    $crate::simd::Level::Avx2 | $crate::simd::Level::Avx512
                        if $crate::simd::Level::Avx2.supported() =>
                    {
                        return unsafe { avx2($($arg),*) };
                    }
                    _ => {}
                }
            }
            #[cfg(not(target_arch = "x86_64"))]
            let _ = level;
            $generic($($arg),*)
        }
    };
}
pub(crate) use dispatch;

/// A kernel whose body [`run`] compiles for each level: `run_at` must be `#[inline(always)]`
/// (so that it is compiled inside the `#[target_feature]` functions of [`run`]), and is
/// written in plain Rust over slices, in the same order of operations whatever the level.
pub trait Kernel {
    type Output;
    /// The kernel's body.
    fn run_at(self) -> Self::Output;
}

/// Run `kernel` compiled for `level` when the CPU has it, else for the baseline: the generic
/// counterpart of [`dispatch!`] for kernels generic over a curve or a closure.
#[allow(unsafe_code)]
pub fn run<K: Kernel>(level: Level, kernel: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        fn avx2<K: Kernel>(kernel: K) -> K::Output {
            kernel.run_at()
        }
        #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
        fn avx512<K: Kernel>(kernel: K) -> K::Output {
            kernel.run_at()
        }
        match level {
            // SAFETY: `avx512` is compiled for AVX-512 F/VL/DQ, AVX2 and FMA; `supported`
            // has just checked (by `is_x86_feature_detected!`) that this CPU has each of them.
            Level::Avx512 if Level::Avx512.supported() => {
                return unsafe { avx512(kernel) };
            }
            // SAFETY: `avx2` is compiled for AVX2 and FMA; `supported` has just checked
            // (by `is_x86_feature_detected!`) that this CPU has both.
            Level::Avx2 | Level::Avx512 if Level::Avx2.supported() => {
                return unsafe { avx2(kernel) };
            }
            _ => {}
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = level;
    kernel.run_at()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_level_is_supported_and_fixed() {
        let l = level();
        assert!(l.supported());
        assert_eq!(level(), l);
        assert!(Level::Generic.supported());
    }
}
