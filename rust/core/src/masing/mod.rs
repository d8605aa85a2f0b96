//! Masing hysteresis operator with non-local memory (Masing's rules plus the Madelung
//! "wiping-out" rules), PHYSICS.md §1.
//!
//! Branch from a reversal point `(x_r, h_r)`: `h = h_r + λ f((x - x_r) / λ)`; `λ = 2` is Masing's
//! rule, other values give the generalized (non-Masing) operator. A branch that reaches the
//! reversal at which the interrupted branch began closes the inner loop: both reversals are
//! forgotten and the older branch continues. A branch that leaves the virgin curve and reaches
//! the mirrored largest excursion rejoins the virgin curve. With `λ ≠ 2` that rejoin is a jump
//! (the branch does not meet the virgin curve there); inner loops close exactly for every `λ`.

use crate::curve::Backbone;
use crate::error::{check_positive, CoreError};

mod kernel;
use kernel::{eval_block, Run, BLOCK, KNOWN};

pub mod channels;
pub mod split;

/// A remembered reversal point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reversal {
    pub x: f64,
    pub h: f64,
    /// Global sample index at which the reversal happened (sample before the direction change).
    pub index: u64,
}

/// Largest sample count a state exports exactly (`to_vec` stores it as f64).
const MAX_EXACT_COUNT: f64 = 9_007_199_254_740_992.0; // 2^53

/// Operator memory. `Default` is the origin: no history, on the virgin curve at (0, 0).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MasingState {
    /// Last input and output.
    pub x: f64,
    pub h: f64,
    /// Direction of the current branch: +1, -1, or 0 before the first move.
    pub dir: i8,
    /// Samples processed so far (global index of the next sample).
    pub count: u64,
    /// Active reversal points, oldest first. Empty: on the virgin curve.
    pub stack: Vec<Reversal>,
}

impl MasingState {
    /// Flatten to `[x, h, dir, count, x_1, h_1, i_1, x_2, h_2, i_2, ...]` (for pickling).
    pub fn to_vec(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.stack.len().saturating_mul(3).saturating_add(4));
        v.extend([self.x, self.h, f64::from(self.dir), self.count as f64]);
        for r in &self.stack {
            v.extend([r.x, r.h, r.index as f64]);
        }
        v
    }

    /// Inverse of [`MasingState::to_vec`], validating what it reads.
    pub fn from_slice(v: &[f64]) -> Result<Self, CoreError> {
        let bad = |reason| Err(CoreError::InvalidState { reason });
        if v.len().checked_sub(4).is_none_or(|r| r % 3 != 0) {
            return bad("length must be 4 + 3 * (number of reversals)");
        }
        if v.iter().any(|a| !a.is_finite()) {
            return bad("contains a non-finite value");
        }
        let dir = v[2];
        if dir != -1.0 && dir != 0.0 && dir != 1.0 {
            return bad("direction must be -1, 0 or 1");
        }
        // Counts are exported as f64: above 2^53 they were never exact (nor reachable).
        if v[3] < 0.0 || v[3].fract() != 0.0 || v[3] > MAX_EXACT_COUNT {
            return bad("sample count must be a non-negative integer no larger than 2^53");
        }
        let stack: Vec<Reversal> = v[4..]
            .chunks_exact(3)
            .map(|c| Reversal {
                x: c[0],
                h: c[1],
                index: c[2].max(0.0) as u64,
            })
            .collect();
        if dir == 0.0 && !stack.is_empty() {
            return bad("reversals recorded before the first move");
        }
        // Reversals must alternate and nest: each new one lies strictly inside the previous
        // range, on the side opposite to the current direction.
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for (k, r) in stack.iter().enumerate() {
            // Counting back from the top (the reversal the current branch started at, which is
            // opposite to the current direction), maxima and minima alternate.
            let from_top = stack.len().saturating_sub(k).saturating_sub(1); // k < len
            let is_max = (dir > 0.0) == (from_top % 2 == 1);
            if k == 0 {
                // The first reversal left the virgin curve, which runs outward from 0; the
                // branch from it rejoins the virgin curve at the mirror point.
                if (is_max && r.x <= 0.0) || (!is_max && r.x >= 0.0) {
                    return bad("first reversal is on the wrong side of the origin");
                }
                lo = -r.x.abs();
                hi = r.x.abs();
                continue;
            }
            if !(r.x > lo && r.x < hi) {
                return bad("reversal points are not nested");
            }
            if is_max {
                hi = r.x;
            } else {
                lo = r.x;
            }
        }
        let x = v[0];
        if !(stack.is_empty() || (lo..=hi).contains(&x)) {
            return bad("current input lies outside the remembered reversals");
        }
        Ok(Self {
            x,
            h: v[1],
            dir: dir as i8,
            count: v[3] as u64,
            stack,
        })
    }
}

/// What a loop closure looked like; reported to an [`Observer`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Closure {
    /// An inner loop between reversals `older` and `newer` closed at sample `index`.
    Inner {
        older: Reversal,
        newer: Reversal,
        index: u64,
    },
    /// A branch that left the virgin curve at `from` rejoined it at `-from.x`.
    Virgin { from: Reversal, index: u64 },
}

/// Receives loop closures as the operator runs (rainflow-style cycle counting).
pub trait Observer {
    /// True when closures are ignored: the force kernel may then defer the forces of new
    /// reversals (closures would report them as NaN; see `masing/kernel.rs`).
    const IGNORES: bool = false;
    fn closed(&mut self, closure: Closure);
}

/// The observer that ignores everything; the force kernel uses it (and compiles it away).
pub struct NoObserver;
impl Observer for NoObserver {
    const IGNORES: bool = true;
    #[inline(always)]
    fn closed(&mut self, _: Closure) {}
}

impl<F: FnMut(Closure)> Observer for F {
    fn closed(&mut self, closure: Closure) {
        self(closure);
    }
}

/// How a branch is drawn from its anchor reversal `(x_a, h_a)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BranchRule {
    /// `h = h_a + λ f((x - x_a) / λ)`: Masing's rule for `λ = 2`, the generalised (non-Masing)
    /// operator otherwise, which jumps where a branch rejoins the virgin curve.
    Scaled(f64),
    /// `h = h_a + (h_t - h_a) f((x - x_a)/λ) / f((x_t - x_a)/λ)`: the λ-scaled branch shape
    /// anchored at both ends, the reversal `(x_a, h_a)` and the target `(x_t, h_t)` the memory
    /// rules say it ends at (the older reversal, or the mirrored first reversal on the virgin
    /// curve). Loops close for every `λ`; `λ = 2` is Masing's branch (PHYSICS.md §1).
    Anchored(f64),
}

impl BranchRule {
    fn lambda(self) -> f64 {
        match self {
            Self::Scaled(l) | Self::Anchored(l) => l,
        }
    }
}

/// The current branch: `h = ha + mul · f((x - xa) · inv)`.
#[derive(Clone, Copy)]
struct Branch {
    xa: f64,
    ha: f64,
    mul: f64,
    inv: f64,
    /// Input value at which this branch closes (±inf: never).
    target: f64,
}

/// One step of the operator: stepping separate from driving, so the cycle counter, the
/// anchored-rule force kernel and the branch-memory export share the rules (the scaled-rule
/// force kernel, `kernel`, applies the same rules and tie-breaking). The fast path (same
/// direction, no closure) is inlined; the rare events are not. Reversal forces are evaluated
/// on the spot with the same expression as the samples', so both agree bit for bit.
struct Stepper<'a, C: Backbone> {
    curve: &'a C,
    rule: BranchRule,
    inv_lambda: f64,
    /// Record runs of samples on one branch (the force kernel).
    track: bool,
    xp: f64,
    /// +1, -1, or 0 before the first move.
    dir: f64,
    br: Branch,
    /// Curve argument of the last sample (on branch `br`).
    u: f64,
    /// Index in `runs` of the current run.
    run: u16,
    stack: &'a mut Vec<Reversal>,
    runs: Vec<Run>,
}

impl<'a, C: Backbone> Stepper<'a, C> {
    fn new(curve: &'a C, rule: BranchRule, track: bool, state: &'a mut MasingState) -> Self {
        let dir = f64::from(state.dir);
        let inv_lambda = 1.0 / rule.lambda();
        let mut st = Self {
            curve,
            rule,
            inv_lambda,
            track,
            xp: state.x,
            dir,
            br: Branch {
                xa: 0.0,
                ha: 0.0,
                mul: 1.0,
                inv: 1.0,
                target: f64::INFINITY,
            },
            u: 0.0,
            run: 0,
            stack: &mut state.stack,
            runs: Vec::with_capacity(if track { BLOCK + 1 } else { 0 }),
        };
        st.br = st.branch(dir);
        // The state's force is the last output of the branch its stack defines (bit for bit
        // when the state came from this kernel); continuing from the branch keeps chunked
        // and one-pass runs identical.
        st.u = (st.xp - st.br.xa) * st.br.inv;
        st
    }

    /// Force of the last sample.
    #[inline]
    fn last_value(&self) -> f64 {
        self.br.ha + self.br.mul * self.curve.eval(self.u)
    }

    /// The branch the stack defines when moving in direction `dir`.
    #[inline]
    // `n - 1`, `n - 2` only in the arm where the stack holds n >= 2 reversals.
    #[allow(clippy::arithmetic_side_effects)]
    fn branch(&self, dir: f64) -> Branch {
        let stack = &self.stack;
        let n = stack.len();
        let (k, target) = match n {
            0 => {
                let never = if dir >= 0.0 {
                    f64::INFINITY
                } else {
                    f64::NEG_INFINITY
                };
                return Branch {
                    xa: 0.0,
                    ha: 0.0,
                    mul: 1.0,
                    inv: 1.0,
                    target: never,
                };
            }
            1 => (0, -stack[0].x),
            _ => (n - 1, stack[n - 2].x),
        };
        let anchor = stack[k];
        let mul = match self.rule {
            BranchRule::Scaled(l) => l,
            BranchRule::Anchored(_) => {
                let ht = if n == 1 {
                    self.curve.eval(target)
                } else {
                    stack[n - 2].h
                };
                let den = self.curve.eval((target - anchor.x) * self.inv_lambda);
                if den == 0.0 {
                    0.0
                } else {
                    (ht - anchor.h) / den
                }
            }
        };
        Branch {
            xa: anchor.x,
            ha: anchor.h,
            mul,
            inv: self.inv_lambda,
            target,
        }
    }

    /// Advance to input `xi` (global sample `index`); the curve argument is left in `self.u`.
    #[inline(always)]
    fn advance<O: Observer>(&mut self, xi: f64, index: u64, observer: &mut O) {
        let dx = xi - self.xp;
        // Fast path: moving on along the branch without reaching its closure point
        // (closure uses >= so that exactly repeated extremes close the loop).
        if !(dx * self.dir > 0.0 && (xi - self.br.target) * self.dir < 0.0) {
            if dx == 0.0 {
                return; // zero-length steps change nothing
            }
            self.event(xi, dx, index, observer);
        }
        self.u = (xi - self.br.xa) * self.br.inv;
        self.xp = xi;
    }

    /// A reversal and/or one or more loop closures at sample `index`.
    #[inline(never)]
    // `n - 1`, `n - 2` only where the stack holds n >= 2 reversals.
    #[allow(clippy::arithmetic_side_effects)]
    fn event<O: Observer>(&mut self, xi: f64, dx: f64, index: u64, observer: &mut O) {
        let s = if dx > 0.0 { 1.0 } else { -1.0 };
        if s != self.dir {
            if self.dir != 0.0 {
                // The reversal is the previous sample.
                self.stack.push(Reversal {
                    x: self.xp,
                    h: self.last_value(),
                    index: index.saturating_sub(1),
                });
            }
            self.dir = s;
        }
        // Wipe out every loop this step closes; the branch is rebuilt once, at the end.
        loop {
            let n = self.stack.len();
            let target = match n {
                0 => break,
                1 => -self.stack[0].x,
                _ => self.stack[n - 2].x,
            };
            if (xi - target) * s < 0.0 {
                break;
            }
            if n == 1 {
                let from = self.stack[0];
                self.stack.clear();
                observer.closed(Closure::Virgin { from, index });
            } else {
                let newer = self.stack[n - 1];
                let older = self.stack[n - 2];
                self.stack.truncate(n - 2);
                observer.closed(Closure::Inner {
                    older,
                    newer,
                    index,
                });
            }
        }
        self.br = self.branch(s);
        if self.track {
            self.runs.push(Run {
                ha: self.br.ha,
                src: KNOWN,
                mul: self.br.mul,
            });
            // At most one run per sample plus the block's first: BLOCK + 1 < 2^16.
            self.run = (self.runs.len() - 1) as u16;
        }
    }

    /// Start a block: its first run is the current branch.
    fn begin_block(&mut self) {
        self.run = 0;
        self.runs.clear();
        self.runs.push(Run {
            ha: self.br.ha,
            src: KNOWN,
            mul: self.br.mul,
        });
    }
}

/// Run the operator over `x` with Masing's branch rule of scale `scale`, writing forces to
/// `out` (when given) and reporting closures. See [`run_rule`].
pub fn run<C: Backbone, O: Observer>(
    curve: &C,
    scale: f64,
    x: &[f64],
    out: Option<&mut [f64]>,
    state: &mut MasingState,
    observer: &mut O,
) -> Result<(), CoreError> {
    run_rule(curve, BranchRule::Scaled(scale), x, out, state, observer)
}

fn checked_end(state: &MasingState, len: usize) -> Result<u64, CoreError> {
    u64::try_from(len)
        .ok()
        .and_then(|n| state.count.checked_add(n))
        .filter(|&e| i64::try_from(e).is_ok())
        .ok_or(CoreError::TooLong { len })
}

/// Run the operator over `x` with branch rule `rule`, writing forces to `out` (when given) and
/// reporting closures.
///
/// The history continues from `state`, which is updated; processing a signal in chunks with
/// the state carried over gives bit-identical results to one pass. On error the state is
/// unchanged.
///
/// With `out`, the kernel runs in two passes per block of samples: a sequential pass applies
/// the memory rules and records each sample's curve argument and the runs of samples on one
/// branch; then one loop per run evaluates the curve (auto-vectorised for the exponential
/// curve, whose `1 - e^{-z}` is branch-free and needs no library call). Closures report
/// reversal forces evaluated on the spot.
pub fn run_rule<C: Backbone, O: Observer>(
    curve: &C,
    rule: BranchRule,
    x: &[f64],
    out: Option<&mut [f64]>,
    state: &mut MasingState,
    observer: &mut O,
) -> Result<(), CoreError> {
    check_positive("scale", rule.lambda())?;
    if let Some(o) = out.as_deref() {
        crate::error::check_same_len("x", x.len(), "out", o.len())?;
    }
    // Masing's scaled rule with nobody watching closures: the kernel that defers reversal
    // forces to the curve pass, and checks the input block by block as it goes.
    let fast = out.is_some() && matches!(rule, BranchRule::Scaled(_)) && O::IGNORES;
    let fast = fast && kernel::takes(state);
    if !fast && !kernel::all_finite(x) {
        crate::error::check_finite("x", x)?;
    }
    let end = checked_end(state, x.len())?;
    let saved = state.clone(); // restored when the forces overflow
    let range = match (out, rule) {
        (Some(out), BranchRule::Scaled(lam)) if fast => {
            match kernel::scaled_force(crate::simd::level(), curve, lam, x, out, state) {
                kernel::Forces::Finite => Ok(()),
                kernel::Forces::NotFinite => crate::error::check_output("force", out),
                kernel::Forces::BadInput => crate::error::check_finite("x", x),
            }
        }
        (out, _) => {
            let mut index = state.count;
            let mut st = Stepper::new(curve, rule, out.is_some(), state);
            let range = if let Some(out) = out {
                let level = crate::simd::level();
                let mut tab = kernel::RunTab::new();
                let mut ub = [0.0_f64; BLOCK];
                let mut rid = [0_u16; BLOCK];
                for (xc, oc) in x.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
                    st.begin_block();
                    for ((&xi, u), r) in xc.iter().zip(ub.iter_mut()).zip(rid.iter_mut()) {
                        st.advance(xi, index, observer);
                        *u = st.u;
                        *r = st.run;
                        index = index.saturating_add(1); // <= end, checked above
                    }
                    let m = xc.len();
                    // the forces' finiteness is checked over `out` below
                    let _ = eval_block(
                        level,
                        curve,
                        &mut st.runs,
                        &ub[..m],
                        &rid[..m],
                        oc,
                        &mut tab,
                    );
                }
                crate::error::check_output("force", out)
            } else {
                for &xi in x {
                    st.advance(xi, index, observer);
                    index = index.saturating_add(1); // <= end, checked above
                }
                Ok(())
            };
            let (xp, dir, hp) = (st.xp, st.dir, st.last_value());
            state.x = xp;
            state.h = hp;
            state.dir = dir as i8;
            state.count = end;
            range
        }
    };
    if let Err(e) = range {
        *state = saved;
        return Err(e);
    }
    Ok(())
}

/// Forces for `x`, continuing from `state` (the origin when `MasingState::default()`).
pub fn masing_force<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    out: &mut [f64],
    state: &mut MasingState,
) -> Result<(), CoreError> {
    run(curve, scale, x, Some(out), state, &mut NoObserver)
}

/// Forces for `x` under branch rule `rule`, continuing from `state`.
pub fn masing_force_rule<C: Backbone>(
    curve: &C,
    rule: BranchRule,
    x: &[f64],
    out: &mut [f64],
    state: &mut MasingState,
) -> Result<(), CoreError> {
    run_rule(curve, rule, x, Some(out), state, &mut NoObserver)
}

/// A curve that is zero everywhere: drives the memory rules when only the reversal bookkeeping
/// is wanted.
struct NoCurve;
impl Backbone for NoCurve {
    #[inline(always)]
    fn eval(&self, _: f64) -> f64 {
        0.0
    }
    fn slope(&self, _: f64) -> f64 {
        0.0
    }
    fn integral(&self, _: f64) -> f64 {
        0.0
    }
}

/// Per-sample branch bookkeeping of the memory rules (the same rules, tie-breaking and state
/// as the force kernel): `anchor[i]` is the global sample index of the reversal the branch at
/// sample `i` starts from (`-1` on the virgin curve); `target[i]` the index of the reversal it
/// heads for, or `-1 - j` when it heads for the mirror `-x[j]` of the first reversal `j`.
/// Streaming: `state` carries the memory across chunks (its forces are not computed).
// Stack arithmetic: `k - 1`, `k - 2` only where k >= 2; indices fit in 63 bits (`TooLong`
// otherwise), so `-1 - index` as i64 cannot overflow.
#[allow(clippy::arithmetic_side_effects)]
pub fn branch_memory(
    x: &[f64],
    anchor: &mut [i64],
    target: &mut [i64],
    state: &mut MasingState,
) -> Result<(), CoreError> {
    crate::error::check_same_len("x", x.len(), "anchor", anchor.len())?;
    crate::error::check_same_len("x", x.len(), "target", target.len())?;
    crate::error::check_finite("x", x)?;
    let base = state.count;
    let n = u64::try_from(x.len()).map_err(|_| CoreError::TooLong { len: x.len() })?;
    let end = base
        .checked_add(n)
        .ok_or(CoreError::TooLong { len: x.len() })?;
    if i64::try_from(end).is_err() {
        return Err(CoreError::TooLong { len: x.len() });
    }
    let mut st = Stepper::new(&NoCurve, BranchRule::Scaled(2.0), false, state);
    let samples = x.iter().zip(anchor.iter_mut()).zip(target.iter_mut());
    for (index, ((&xi, a), t)) in (base..).zip(samples) {
        st.advance(xi, index, &mut NoObserver);
        let s = &st.stack;
        // Indices fit in i64: checked against `end` above.
        (*a, *t) = match s.len() {
            0 => (-1, -1),
            1 => (s[0].index as i64, -1 - s[0].index as i64),
            k => (s[k - 1].index as i64, s[k - 2].index as i64),
        };
    }
    let (xp, dir) = (st.xp, st.dir);
    state.x = xp;
    state.h = 0.0;
    state.dir = dir as i8;
    state.count = end;
    Ok(())
}

/// One closed cycle found by [`cycle_energies`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    /// Peak-to-peak input range of the loop.
    pub range: f64,
    /// Mean input of the loop (midpoint of its reversals).
    pub mean: f64,
    /// Global sample index where the loop started (the older reversal).
    pub start: u64,
    /// Global sample index where the loop closed.
    pub end: u64,
    /// 1 for a closed inner loop; 0.5 for a half cycle that rejoined the virgin curve.
    pub count: f64,
    /// Energy dissipated: `count · 2 λ² B(range / λ)`.
    pub energy: f64,
}

/// Every closed cycle of `x`, counted by the operator's own memory (equivalent to rainflow
/// counting): each inner-loop closure is a full cycle; each virgin rejoin is a half cycle.
/// The energies sum to `∮ F dx` over a stretch that returns the operator to its start state.
pub fn cycle_energies<C: Backbone>(
    curve: &C,
    scale: f64,
    x: &[f64],
    state: &mut MasingState,
) -> Result<Vec<Cycle>, CoreError> {
    let mut cycles = Vec::new();
    let loop_energy = |range: f64| 2.0 * scale * scale * curve.chord_area(range / scale);
    let mut obs = |c: Closure| match c {
        Closure::Inner {
            older,
            newer,
            index,
        } => {
            let range = (older.x - newer.x).abs();
            cycles.push(Cycle {
                range,
                mean: 0.5 * (older.x + newer.x),
                start: older.index,
                end: index,
                count: 1.0,
                energy: loop_energy(range),
            });
        }
        Closure::Virgin { from, index } => {
            let range = 2.0 * from.x.abs();
            cycles.push(Cycle {
                range,
                mean: 0.0,
                start: from.index,
                end: index,
                count: 0.5,
                energy: 0.5 * loop_energy(range),
            });
        }
    };
    run(curve, scale, x, None, state, &mut obs)?;
    let energies: Vec<f64> = cycles.iter().map(|c| c.energy).collect();
    crate::error::check_output("cycle energy", &energies)?;
    Ok(cycles)
}

pub use crate::loop_area::loop_area;

#[cfg(test)]
mod range_tests {
    //! Extreme but finite inputs found by fuzzing (fuzz/afl, fuzz/kernels.py): a result
    //! or a clear `OutOfRange`, never a NaN reported as success.
    use super::*;
    use crate::curve::{Exponential, Tabulated};

    #[test]
    fn loop_area_of_1e274_data_is_scaled_not_nan() {
        let x = [1e274, -1e274, -1e274, 1e274];
        let f = [1e30, 1e30, -1e30, -1e30];
        // 4e304 fits although every product of differences overflowed before
        let a = loop_area(&x, &f).unwrap_or(f64::NAN);
        assert!((a.abs() / 4e304 - 1.0).abs() < 1e-12, "{a}");
        let big = [1e40, 1e40, -1e40, -1e40];
        assert!(matches!(
            loop_area(&x, &big),
            Err(CoreError::OutOfRange { .. })
        ));
        // same shape at ordinary magnitudes: the area scales exactly
        let xs: Vec<f64> = x.iter().map(|v| v * 1e-270).collect();
        let fs: Vec<f64> = f.iter().map(|v| v * 1e-30).collect();
        let small = loop_area(&xs, &fs).unwrap_or(f64::NAN);
        let tiny: Vec<f64> = xs.iter().map(|v| v * 1e-300).collect();
        let t = loop_area(&tiny, &fs).unwrap_or(f64::NAN);
        assert!((t / small / 1e-300 - 1.0).abs() < 1e-12, "{t} vs {small}");
    }

    #[test]
    fn exponential_with_overflowing_stiffness_is_refused() {
        assert!(matches!(
            Exponential::new(4e201, 4e204),
            Err(CoreError::OutOfRange { .. })
        ));
    }

    #[test]
    fn overflowing_force_is_an_error_and_leaves_the_state() {
        let c = Tabulated::new(&[0.0, 1.0], &[0.0, 1.7e308]).unwrap_or_else(|_| unreachable!());
        let mut st = MasingState::default();
        let x = [1.0, -0.99]; // the branch 2·f(-0.995) overflows before it is added
        let mut out = [0.0; 2];
        let r = masing_force(&c, 2.0, &x, &mut out, &mut st);
        assert!(matches!(r, Err(CoreError::OutOfRange { .. })), "{r:?}");
        assert_eq!(st, MasingState::default());
    }
}
