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

    /// `out[i] = 1 - exp(-z[i])` (the Masing kernel's exponential) as a [`Kernel`].
    struct OneMinusExp<'a>(&'a [f64], &'a mut [f64]);

    impl Kernel for OneMinusExp<'_> {
        type Output = ();
        #[inline(always)]
        fn run_at(self) {
            for (o, &z) in self.1.iter_mut().zip(self.0) {
                *o = crate::curve::one_minus_exp_neg(z);
            }
        }
    }

    /// Distance in units in the last place between two finite non-negative doubles.
    fn ulps(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    /// Arguments over the range the kernel uses (`z = ac |u| >= 0`): a geometric sweep from
    /// the smallest subnormal to past the clamp at 708, a dense sweep over [0, 20] (every
    /// power of two, the `k = -1` range), pseudo-random arguments, the neighbourhoods of the
    /// reduction's switch points `(k + 1/2) ln 2` (where `|r|` is largest), and the edge
    /// cases.
    fn arguments() -> Vec<f64> {
        let mut z = vec![
            0.0,
            f64::from_bits(1),
            f64::MIN_POSITIVE,
            1e-300,
            1e-30,
            1e-17,
            f64::EPSILON,
            1e-8,
            std::f64::consts::LN_2 / 128.0,
            std::f64::consts::LN_2 / 64.0,
            std::f64::consts::LN_2,
            0.5,
            1.0,
            36.0,
            37.5,
            38.0,
            707.9,
            708.0,
            708.5,
            709.8,
            745.2,
            1e6,
            f64::MAX,
        ];
        // subnormals by their bit patterns, then normal numbers geometrically
        z.extend((0..60).map(|k| f64::from_bits(1_u64 << k)));
        let mut g = f64::MIN_POSITIVE;
        while g < 800.0 {
            z.push(g);
            g *= 1.000_7;
        }
        z.extend((0..400_000).map(|i| f64::from(i) * 5e-5));
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..200_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let e = (state >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0);
            z.push(40.0 * e * e); // denser near 0
        }
        // around the switch points of the reduction, where |r| = ln2/2
        for k in 0..40 {
            let c = (f64::from(k) + 0.5) * std::f64::consts::LN_2;
            z.extend((0..2_000).map(|i| c * (1.0 + f64::from(i - 1_000) * 1e-9)));
        }
        // the neighbours of every edge case
        let edges: Vec<f64> = z[..23].to_vec();
        for e in edges {
            if e > 0.0 && e < f64::MAX {
                z.push(f64::from_bits(e.to_bits() - 1));
                z.push(f64::from_bits(e.to_bits() + 1));
            }
        }
        z
    }

    #[test]
    fn the_vectorised_exponential_is_within_one_ulp_of_libm_at_every_level() {
        let z = arguments();
        let mut scalar = vec![0.0; z.len()];
        for (o, &v) in scalar.iter_mut().zip(&z) {
            *o = std::hint::black_box(crate::curve::one_minus_exp_neg(v));
        }
        // libm: 1 - e^{-z} = -expm1(-z), accurate over the whole range
        let (mut worst, mut at, mut off) = (0_u64, 0.0_f64, 0_usize);
        for (&v, &o) in z.iter().zip(&scalar) {
            let want = -(-v).exp_m1();
            let d = ulps(o, want);
            off += usize::from(d > 0);
            if d > worst {
                (worst, at) = (d, v);
            }
        }
        eprintln!(
            "1 - exp(-z): {} arguments, worst {worst} ulp from libm (at z = {at:e}), {off} not \
             bit-equal to libm",
            z.len()
        );
        assert!(worst <= 1, "worst {worst} ulp at z = {at:e}");
        assert_eq!(scalar[0], 0.0);
        assert_eq!(*scalar.last().unwrap_or(&0.0), 1.0);
        for l in Level::ALL.into_iter().filter(|l| l.supported()) {
            let mut out = vec![f64::NAN; z.len()];
            run(l, OneMinusExp(&z, &mut out));
            let same = out
                .iter()
                .zip(&scalar)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "level {} differs from the scalar path", l.name());
        }
    }
}
