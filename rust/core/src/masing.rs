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
        let mut v = Vec::with_capacity(4 + 3 * self.stack.len());
        v.extend([self.x, self.h, f64::from(self.dir), self.count as f64]);
        for r in &self.stack {
            v.extend([r.x, r.h, r.index as f64]);
        }
        v
    }

    /// Inverse of [`MasingState::to_vec`], validating what it reads.
    pub fn from_slice(v: &[f64]) -> Result<Self, CoreError> {
        let bad = |reason| Err(CoreError::InvalidState { reason });
        if v.len() < 4 || (v.len() - 4) % 3 != 0 {
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
            let from_top = stack.len() - 1 - k;
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
    fn closed(&mut self, closure: Closure);
}

/// The observer that ignores everything; the force kernel uses it (and compiles it away).
pub struct NoObserver;
impl Observer for NoObserver {
    #[inline(always)]
    fn closed(&mut self, _: Closure) {}
}

impl<F: FnMut(Closure)> Observer for F {
    fn closed(&mut self, closure: Closure) {
        self(closure);
    }
}

/// The current branch anchor `(x_a, h_a)`, its scale and its closure target.
#[derive(Clone, Copy)]
struct Branch {
    xa: f64,
    ha: f64,
    scale: f64,
    inv_scale: f64,
    /// Input value at which this branch closes (±inf: never).
    target: f64,
}

#[inline]
fn branch_of(stack: &[Reversal], dir: f64, scale: f64, inv_scale: f64) -> Branch {
    let n = stack.len();
    let (anchor, target) = match n {
        0 => {
            let never = if dir >= 0.0 {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
            return Branch {
                xa: 0.0,
                ha: 0.0,
                scale: 1.0,
                inv_scale: 1.0,
                target: never,
            };
        }
        1 => (stack[0], -stack[0].x),
        _ => (stack[n - 1], stack[n - 2].x),
    };
    Branch {
        xa: anchor.x,
        ha: anchor.h,
        scale,
        inv_scale,
        target,
    }
}

/// One step of the operator: stepping separate from driving, so the force kernel and the
/// cycle counter share the rules. The fast path (same direction, no closure) is inlined; the
/// rare events are not.
struct Stepper<'a, C: Backbone> {
    curve: &'a C,
    scale: f64,
    inv_scale: f64,
    xp: f64,
    hp: f64,
    /// +1, -1, or 0 before the first move.
    dir: f64,
    br: Branch,
    stack: &'a mut Vec<Reversal>,
}

impl<'a, C: Backbone> Stepper<'a, C> {
    fn new(curve: &'a C, scale: f64, state: &'a mut MasingState) -> Self {
        let dir = f64::from(state.dir);
        let inv_scale = 1.0 / scale;
        let br = branch_of(&state.stack, dir, scale, inv_scale);
        Self {
            curve,
            scale,
            inv_scale,
            xp: state.x,
            hp: state.h,
            dir,
            br,
            stack: &mut state.stack,
        }
    }

    #[inline(always)]
    fn step<O: Observer>(&mut self, xi: f64, index: u64, observer: &mut O) -> f64 {
        let dx = xi - self.xp;
        // Fast path: moving on along the branch without reaching its closure point
        // (closure uses >= so that exactly repeated extremes close the loop).
        if !(dx * self.dir > 0.0 && (xi - self.br.target) * self.dir < 0.0) {
            if dx == 0.0 {
                return self.hp; // zero-length steps change nothing
            }
            self.event(xi, dx, index, observer);
        }
        let br = &self.br;
        self.hp = br.ha + br.scale * self.curve.eval((xi - br.xa) * br.inv_scale);
        self.xp = xi;
        self.hp
    }

    /// A reversal and/or one or more loop closures at sample `index`.
    #[inline(never)]
    fn event<O: Observer>(&mut self, xi: f64, dx: f64, index: u64, observer: &mut O) {
        let s = if dx > 0.0 { 1.0 } else { -1.0 };
        if s != self.dir {
            if self.dir != 0.0 {
                self.stack.push(Reversal {
                    x: self.xp,
                    h: self.hp,
                    index: index.saturating_sub(1),
                });
            }
            self.dir = s;
            self.br = branch_of(self.stack, s, self.scale, self.inv_scale);
        }
        while (xi - self.br.target) * s >= 0.0 {
            let n = self.stack.len();
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
            self.br = branch_of(self.stack, s, self.scale, self.inv_scale);
        }
    }
}

/// Run the operator over `x`, writing forces to `out` (when given) and reporting closures.
///
/// The history continues from `state`, which is updated; processing a signal in chunks with
/// the state carried over gives bit-identical results to one pass. On error the state is
/// unchanged.
pub fn run<C: Backbone, O: Observer>(
    curve: &C,
    scale: f64,
    x: &[f64],
    out: Option<&mut [f64]>,
    state: &mut MasingState,
    observer: &mut O,
) -> Result<(), CoreError> {
    check_positive("scale", scale)?;
    if let Some(o) = out.as_deref() {
        crate::error::check_same_len("x", x.len(), "out", o.len())?;
    }
    crate::error::check_finite("x", x)?;
    let base = state.count;
    let saved = state.clone(); // restored when the forces overflow
    let mut range = Ok(());
    // `state` has public fields: a count near u64::MAX must not wrap the sample indices.
    let end = u64::try_from(x.len())
        .ok()
        .and_then(|n| base.checked_add(n))
        .ok_or(CoreError::InvalidState {
            reason: "sample count overflows",
        })?;
    let mut st = Stepper::new(curve, scale, state);
    match out {
        Some(out) => {
            for ((i, &xi), o) in x.iter().enumerate().zip(out.iter_mut()) {
                *o = st.step(xi, base + i as u64, observer);
            }
            range = crate::error::check_output("force", out);
        }
        None => {
            for (i, &xi) in x.iter().enumerate() {
                st.step(xi, base + i as u64, observer);
            }
        }
    }
    let (xp, hp, dir) = (st.xp, st.hp, st.dir);
    if let Err(e) = range {
        *state = saved;
        return Err(e);
    }
    state.x = xp;
    state.h = hp;
    state.dir = dir as i8;
    state.count = end;
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

/// `∮ F dx` of the closed polygon through `(x_i, F_i)` (last point joined to the first):
/// positive for a clockwise (dissipative) loop. Uses the trapezoid form with the mean force
/// removed and compensated summation, so large offsets in `x` or `F` cost no accuracy.
pub fn loop_area(x: &[f64], f: &[f64]) -> Result<f64, CoreError> {
    crate::error::check_same_len("x", x.len(), "F", f.len())?;
    if x.is_empty() {
        return Err(CoreError::Empty { name: "x" });
    }
    crate::error::check_finite("x", x)?;
    crate::error::check_finite("F", f)?;
    let n = x.len();
    // Work in units of the largest |x| and |F| so that sums and products of 1e±300 data
    // neither overflow nor underflow (found by fuzzing); the scales multiply the result.
    let sx = x.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
    let sf = f.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
    if sx == 0.0 || sf == 0.0 {
        return Ok(0.0);
    }
    let fm = f.iter().map(|&v| v / sf).sum::<f64>() / n as f64;
    let (mut sum, mut comp) = (0.0_f64, 0.0_f64);
    for i in 0..n {
        let j = if i + 1 == n { 0 } else { i + 1 };
        let (fi, fj) = (f[i] / sf - fm, f[j] / sf - fm);
        let term = 0.5 * (fi + fj) * (x[j] / sx - x[i] / sx);
        // Neumaier summation.
        let t = sum + term;
        if sum.abs() >= term.abs() {
            comp += (sum - t) + term;
        } else {
            comp += (term - t) + sum;
        }
        sum = t;
    }
    let area = (sum + comp) * sx * sf;
    crate::error::check_output("loop area", &[area])?;
    Ok(area)
}

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
