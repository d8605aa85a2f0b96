//! [`super::simulate`] for one degree of freedom: the same Newmark average-acceleration
//! scheme, Newton iteration, event sub-steps, halvings and energy bookkeeping, on scalars.
//!
//! With `n = 1` every joint acts between the DOF and the ground (`d = x`), the "matrices" are
//! numbers and the Newton system is a division, so the dense path's row loops, `n × n`
//! Jacobian and LU disappear. Newton starts from the step of the equation linearised at the
//! start of the step (the dense path starts from the last acceleration): where the joints are
//! nearly linear over a step, one residual evaluation meets the tolerance. Both paths converge
//! to the same tolerance, so they agree to about `rtol` per step (the tests compare them).
//!
//! The integrator is generic over the joint set ([`Joints`]) and monomorphised: a single
//! Masing joint on the exponential curve (the common case) has its own implementation whose
//! trials cost one `exp` (Newton's small corrections: a short series) with no dispatch, memory
//! walk or division (the active branch's constants are cached when the memory changes); every
//! other joint set goes through [`Dyn`], the per-law dispatch of [`JointLaw`]. Outputs whose
//! buffer is empty are not computed.

use super::joint::{
    masing_closure, masing_commit, masing_kink, masing_trial, Joint, JointLaw, JointState,
    MasingCurve, Trial,
};
use super::{Buffers, Inputs, Options, Status, Structure, Summary};
use crate::error::CoreError;
use crate::masing::MasingState;

/// Sum of the joint forces at a trial point, the largest single force (for the convergence
/// scale), and the summed tangents `∂/∂d`, `∂/∂ḋ`.
#[derive(Debug, Clone, Copy, Default)]
struct Sum {
    f: f64,
    fmax: f64,
    kt: f64,
    ct: f64,
}

/// A Newton trial point: `x1 = xp + b a1` (`xp`, `b` fixed over the step, `a1` the iterate)
/// and its velocity `v1`.
#[derive(Debug, Clone, Copy)]
struct Point {
    x1: f64,
    v1: f64,
    xp: f64,
    b: f64,
    a1: f64,
}

/// The joints of a one-DOF structure (all between the DOF and the ground, `d = x`).
trait Joints {
    /// Forces and tangents at the trial point `pt`, moving from the committed `x0`. The trial
    /// is remembered: [`Joints::commit`] accepts the last one.
    fn trial(&mut self, x0: f64, pt: &Point) -> Sum;
    /// Earliest fraction `θ ∈ (0, 1)` of the step `x0 → x1` at which a joint changes
    /// character (see [`JointLaw::event`]); 1 when none does.
    fn event(&self, x0: f64, x1: f64, v0: f64, v1: f64) -> f64;
    /// Accept the last trial (at `x1`, from `x0`), with the work bookkeeping.
    fn commit(&mut self, x0: f64, x1: f64) -> Result<(), CoreError>;
    /// Write each joint's force, work and dissipated energy at `x` as sample `i`.
    fn record(&self, x: f64, i: usize, out: &mut Buffers<'_>);
    /// How close Newton's residual must come (relative) before a step-doubling pair's inner
    /// solve ends without a last trial: `QUICK` where every tangent is exact (convergence is
    /// quadratic), 0 (never) where a law's tangent is a difference quotient.
    fn quick(&self) -> f64 {
        adaptive::QUICK
    }
    /// Keep each joint's force at the last trial, moved by `(dx, dv)` along its tangents, in
    /// `slot` (0: the coarse end of a step-doubling pair, 1: its midpoint, 2: its fine end).
    fn keep(&mut self, slot: usize, moved: (f64, f64));
    /// Accept the last trial (at `xr`, from `x0`) of a step-doubling piece whose coarse end,
    /// midpoint and fine end were at `(xc, xm, xf)`: each joint's work is the Richardson
    /// extrapolation of the pair's trapezoidal sums.
    /// `ext`: the extrapolation weight (1/3, or 0 when the plain half steps are kept).
    fn commit_doubled(
        &mut self,
        x0: f64,
        ends: (f64, f64, f64),
        ext: f64,
        xr: f64,
    ) -> Result<(), CoreError>;
    /// The summed tangents at the start `x0` of the step last tried (to `x1`), along it (the
    /// right limit; see [`JointLaw::start_tangent`]), where they may differ from those the
    /// state holds. `None`: the state's.
    fn start_tangent(&self, x0: f64, x1: f64) -> Option<(f64, f64)>;
    /// The displacement nearest the committed point at which a joint's tangent jumps on the
    /// monotone move to `x1` (a Masing branch closing: [`JointLaw::kink`]), and the jump of
    /// the summed tangent there; `None`: none.
    fn kink(&self, x1: f64) -> Option<(f64, f64)>;
    /// Whether [`Joints::kink`] can name one (a Masing joint in the set).
    fn kinks(&self) -> bool;
    /// The first stick-slip transition beyond the fraction `floor` of the monotone move
    /// `x0 → x1`, as a fraction of the move ([`JointLaw::slip_after`]); 1 when none.
    fn slip(&self, _x0: f64, _x1: f64, _floor: f64) -> f64 {
        1.0
    }
    /// Where a Bouc-Wen joint's `z` crosses 0 on the step last tried from `x0` (to `x1`, over
    /// `h`, velocities `v0 → v1`), as a fraction of the step (the root of the cubic through
    /// `z` and `ż = k_t ḋ` at the ends), and `Δ α` ([`JointLaw::zero_crossing`]): the jump of
    /// the joint force's second time derivative there, per unit `ḋ²`. `None`: none.
    fn zero_jump(&self, _x0: f64, _x1: f64, _h: f64, _v: (f64, f64)) -> Option<(f64, f64)> {
        None
    }
    /// Whether [`Joints::zero_jump`] can name one (a Bouc-Wen joint with `ν = 1`).
    fn zero_crossings(&self) -> bool {
        false
    }
    /// Whether error control takes Hermite pieces (see `adaptive`) for this joint set: not
    /// where a law's tangent is a difference quotient (a [`JointLaw::Law`]): there step
    /// doubling.
    fn hermite(&self) -> bool;
    /// Move each joint's force at the last trial along its tangents by `(dx, dv)`.
    fn shift(&mut self, moved: (f64, f64));
    /// Whether the last trial, made at `x_trial` from the committed `x0`, still describes the
    /// nearby `x1` for every joint ([`JointLaw::holds`]).
    fn holds(&self, x0: f64, x_trial: f64, x1: f64) -> bool;
    /// Accept the last trial (shifted to `x1`, from `x0`) of a Hermite piece with the ends
    /// `e`: each joint's work by [`hermite_work`].
    fn commit_hermite(&mut self, x0: f64, x1: f64, e: &Ends) -> Result<(), CoreError>;
}

/// The ends of a Hermite piece (see `adaptive`): its length, the velocity and acceleration at
/// the start and end, and the summed joint stiffness at the start (for a joint set that does
/// not keep its own).
#[derive(Debug, Clone, Copy)]
struct Ends {
    h: f64,
    v0: f64,
    a0: f64,
    v1: f64,
    a1: f64,
    kt0: f64,
    /// Added to the tangent of the joint whose Masing branch closes next to the start (`.0`)
    /// or the end (`.1`) of the piece: the tangent of the branch the piece is on.
    dk: (f64, f64),
}

/// `∫ F ḋ dt` over a Hermite piece by the two-point Hermite rule (fourth order): `F ḋ` and its
/// rate `(kt ḋ + ct d̈) ḋ + F d̈` at both ends, `(f, kt, ct)` the force and tangents there.
#[inline(always)]
fn hermite_work(e: &Ends, (f0, kt0, ct0): (f64, f64, f64), (f1, kt1, ct1): (f64, f64, f64)) -> f64 {
    let (g0, g1) = (f0 * e.v0, f1 * e.v1);
    let dg0 = (kt0 * e.v0 + ct0 * e.a0) * e.v0 + f0 * e.a0;
    let dg1 = (kt1 * e.v1 + ct1 * e.a1) * e.v1 + f1 * e.a1;
    0.5 * e.h * (g0 + g1) + e.h * e.h / 12.0 * (dg0 - dg1)
}

/// `∫ F dd` of a rate-independent joint over a monotone move by `dd` on one branch, by the
/// two-point Hermite rule in `d` (exact for a cubic `F(d)`): the force and the tangent along
/// the move at both ends. (The same rule in time, `∫ F ḋ dt`, also depends on the ends'
/// velocities and accelerations: for Masing joints 1e-4 of the input work off at small
/// amplitudes, against 1e-5 with this.)
#[inline(always)]
fn masing_work(dd: f64, (f0, k0): (f64, f64), (f1, k1): (f64, f64)) -> f64 {
    0.5 * dd * (f0 + f1) + dd * dd / 12.0 * (k0 - k1)
}

/// The Richardson extrapolation of a joint's work over a step-doubling piece: forces `f0` at
/// the start `x0` and `kept` (coarse end, midpoint, fine end) at `(xc, xm, xf)`.
#[inline(always)]
fn doubled_work(f0: f64, kept: [f64; 3], x0: f64, (xc, xm, xf): (f64, f64, f64), ext: f64) -> f64 {
    let coarse = 0.5 * (f0 + kept[0]) * (xc - x0);
    let fine = 0.5 * (f0 + kept[1]) * (xm - x0) + 0.5 * (kept[1] + kept[2]) * (xf - xm);
    fine + (fine - coarse) * ext
}

/// Any set of joints, through [`JointLaw`]'s dispatch.
struct Dyn<'a> {
    joints: &'a [Joint],
    states: Vec<JointState>,
    trials: Vec<Trial>,
    /// Each joint's force at the committed point, cumulative work, stored energy at the start.
    jf: Vec<f64>,
    jwork: Vec<f64>,
    stored0: Vec<f64>,
    /// Each joint's forces kept by [`Joints::keep`].
    kept: Vec<[f64; 3]>,
    /// Each joint's tangents `(∂/∂d, ∂/∂ḋ)` at the committed point.
    tang: Vec<(f64, f64)>,
}

impl Dyn<'_> {
    /// Joint `jn`'s tangents at the start `x0` of its last trial (to `x1`), along it.
    #[inline]
    fn start_of(&self, jn: usize, x0: f64, x1: f64) -> (f64, f64) {
        let (j, st, tr) = (&self.joints[jn], &self.states[jn], &self.trials[jn]);
        j.law.start_tangent(st, x0, x1, tr).unwrap_or(self.tang[jn])
    }
}

impl<'a> Dyn<'a> {
    /// Joints loaded from the virgin state to `x0`; returns them and their [`Sum`] there.
    fn new(joints: &'a [Joint], x0: f64, v0: f64) -> Result<(Self, Sum), CoreError> {
        let nj = joints.len();
        let mut states: Vec<JointState> = joints.iter().map(|j| j.law.fresh_state()).collect();
        let mut jf = vec![0.0; nj];
        let mut tang = vec![(0.0, 0.0); nj];
        let mut sum = Sum::default();
        let parts = joints.iter().zip(states.iter_mut());
        for ((j, st), (f, tg)) in parts.zip(jf.iter_mut().zip(tang.iter_mut())) {
            let tr = j.law.trial(st, 0.0, x0, v0);
            j.law.commit(st, 0.0, x0, &tr)?;
            *f = tr.f;
            *tg = (tr.kt, tr.ct);
            sum.f += tr.f;
            sum.kt += tr.kt;
            sum.ct += tr.ct;
        }
        let stored0 = joints
            .iter()
            .zip(&states)
            .map(|(j, st)| j.law.stored_energy(st, x0))
            .collect();
        Ok((
            Self {
                joints,
                states,
                trials: vec![Trial::default(); nj],
                jf,
                jwork: vec![0.0; nj],
                stored0,
                kept: vec![[0.0; 3]; nj],
                tang,
            },
            sum,
        ))
    }
}

impl Joints for Dyn<'_> {
    fn quick(&self) -> f64 {
        let exact = !self
            .joints
            .iter()
            .any(|j| matches!(j.law, JointLaw::Law { .. }));
        if exact {
            adaptive::QUICK
        } else {
            0.0
        }
    }

    #[inline]
    fn keep(&mut self, slot: usize, (dx, dv): (f64, f64)) {
        for (k, tr) in self.kept.iter_mut().zip(&self.trials) {
            if let Some(v) = k.get_mut(slot) {
                *v = tr.f + tr.kt * dx + tr.ct * dv;
            }
        }
    }

    #[inline]
    fn commit_doubled(
        &mut self,
        x0: f64,
        ends: (f64, f64, f64),
        ext: f64,
        xr: f64,
    ) -> Result<(), CoreError> {
        let parts = self.joints.iter().zip(&self.trials).zip(&mut self.states);
        let books = self.jwork.iter_mut().zip(&mut self.jf).zip(&self.kept);
        for (((j, tr), st), ((work, f), kept)) in parts.zip(books) {
            *work += doubled_work(*f, *kept, x0, ends, ext);
            j.law.commit(st, x0, xr, tr)?;
            *f = tr.f;
        }
        for (tg, tr) in self.tang.iter_mut().zip(&self.trials) {
            *tg = (tr.kt, tr.ct);
        }
        Ok(())
    }

    fn hermite(&self) -> bool {
        !self
            .joints
            .iter()
            .any(|j| matches!(j.law, JointLaw::Law { .. }))
    }

    #[inline]
    fn kinks(&self) -> bool {
        self.joints
            .iter()
            .any(|j| matches!(j.law, JointLaw::Masing { .. }))
    }

    #[inline]
    fn slip(&self, x0: f64, x1: f64, floor: f64) -> f64 {
        let mut theta = 1.0_f64;
        for (j, st) in self.joints.iter().zip(&self.states) {
            if let Some(th) = j.law.slip_after(st, x0, x1, floor) {
                theta = theta.min(th);
            }
        }
        theta
    }

    fn zero_crossings(&self) -> bool {
        self.joints
            .iter()
            .any(|j| matches!(j.law, JointLaw::BoucWen { nu, .. } if nu == 1.0))
    }

    #[inline]
    fn zero_jump(&self, x0: f64, x1: f64, h: f64, (v0, v1): (f64, f64)) -> Option<(f64, f64)> {
        let mut out = None;
        for (jn, j) in self.joints.iter().enumerate() {
            let tr = &self.trials[jn];
            if let Some((z0, z1, jump)) = j.law.zero_crossing(&self.states[jn], tr) {
                let JointLaw::BoucWen { alpha, .. } = j.law else {
                    continue;
                };
                let k0 = self.start_of(jn, x0, x1).0;
                let lin = z0 / (z0 - z1);
                let th = adaptive::cubic_root(lin, (z0, h * k0 * v0), (z1, h * tr.kt * v1));
                out = Some((th, jump * alpha));
            }
        }
        out
    }

    #[inline]
    fn kink(&self, x1: f64) -> Option<(f64, f64)> {
        let mut near: Option<(f64, f64)> = None;
        for (j, st) in self.joints.iter().zip(&self.states) {
            if let Some(k) = j.law.kink(st, x1) {
                // all joints move from the same committed point toward x1: the nearest
                // closure is the one farthest from x1
                near = Some(match near {
                    Some(b) if (k.0 - b.0) * (x1 - b.0) > 0.0 => b,
                    _ => k,
                });
            }
        }
        near
    }

    #[inline]
    fn start_tangent(&self, x0: f64, x1: f64) -> Option<(f64, f64)> {
        let mut out = (0.0, 0.0);
        for jn in 0..self.joints.len() {
            let (kt, ct) = self.start_of(jn, x0, x1);
            out = (out.0 + kt, out.1 + ct);
        }
        Some(out)
    }

    #[inline]
    fn shift(&mut self, (dx, dv): (f64, f64)) {
        for tr in &mut self.trials {
            tr.f += tr.kt * dx + tr.ct * dv;
        }
    }

    #[inline]
    fn holds(&self, x0: f64, x_trial: f64, x1: f64) -> bool {
        self.joints
            .iter()
            .zip(&self.states)
            .all(|(j, st)| j.law.holds(st, x0, x_trial, x1))
    }

    #[inline]
    fn commit_hermite(&mut self, x0: f64, x1: f64, e: &Ends) -> Result<(), CoreError> {
        // (the closure's jumps go to the joint that crosses it)
        let mut dk = e.dk;
        for jn in 0..self.joints.len() {
            let (kt, ct) = self.start_of(jn, x0, x1);
            let (j, tr) = (&self.joints[jn], &self.trials[jn]);
            let (d0, d1) = if dk != (0.0, 0.0) && j.law.kink(&self.states[jn], x1).is_some() {
                std::mem::replace(&mut dk, (0.0, 0.0))
            } else {
                (0.0, 0.0)
            };
            let (f0, f1) = (self.jf[jn], tr.f);
            self.jwork[jn] += if matches!(j.law, JointLaw::Masing { .. }) {
                masing_work(x1 - x0, (f0, kt + d0), (f1, tr.kt + d1))
            } else {
                hermite_work(e, (f0, kt + d0, ct), (f1, tr.kt + d1, tr.ct))
            };
        }
        let parts = self.joints.iter().zip(&self.trials).zip(&mut self.states);
        let books = self.jf.iter_mut().zip(&mut self.tang);
        for (((j, tr), st), (f, tg)) in parts.zip(books) {
            j.law.commit(st, x0, x1, tr)?;
            *f = tr.f;
            *tg = (tr.kt, tr.ct);
        }
        Ok(())
    }

    #[inline(always)]
    fn trial(&mut self, x0: f64, pt: &Point) -> Sum {
        let (x1, v1) = (pt.x1, pt.v1);
        let mut out = Sum::default();
        for ((j, st), tr) in self.joints.iter().zip(&self.states).zip(&mut self.trials) {
            *tr = j.law.trial(st, x0, x1, v1);
            out.f += tr.f;
            out.fmax = out.fmax.max(tr.f.abs());
            out.kt += tr.kt;
            out.ct += tr.ct;
        }
        out
    }

    #[inline]
    fn event(&self, x0: f64, x1: f64, v0: f64, v1: f64) -> f64 {
        let mut theta = 1.0_f64;
        for (j, js) in self.joints.iter().zip(&self.states) {
            if let Some(th) = j.law.event(js, x0, x1, v0, v1) {
                theta = theta.min(th);
            }
        }
        theta
    }

    #[inline]
    fn commit(&mut self, x0: f64, x1: f64) -> Result<(), CoreError> {
        let parts = self.joints.iter().zip(&self.trials).zip(&mut self.states);
        let books = self.jwork.iter_mut().zip(&mut self.jf);
        for (((j, tr), st), (work, f)) in parts.zip(books) {
            *work += 0.5 * (*f + tr.f) * (x1 - x0);
            j.law.commit(st, x0, x1, tr)?;
            *f = tr.f;
        }
        for (tg, tr) in self.tang.iter_mut().zip(&self.trials) {
            *tg = (tr.kt, tr.ct);
        }
        Ok(())
    }

    // Row-major index arithmetic below len(t) · n_joints (the output size checked by the caller).
    #[inline]
    #[allow(clippy::arithmetic_side_effects)]
    fn record(&self, x: f64, i: usize, out: &mut Buffers<'_>) {
        let nj = self.joints.len();
        for (jn, j) in self.joints.iter().enumerate() {
            let at = i * nj + jn;
            put(out.joint_force, at, self.jf[jn]);
            put(out.joint_work, at, self.jwork[jn]);
            if let Some(d) = out.joint_dissipated.get_mut(at) {
                *d = self.jwork[jn] - (j.law.stored_energy(&self.states[jn], x) - self.stored0[jn]);
            }
        }
    }
}

/// One Masing joint on the exponential curve `f(u) = h0 (1 − e^(−ac |u|)) sgn u`, branch scale
/// λ. The branch the joint is on (moving on in its direction) is cached when the memory
/// changes: `F = ha + A (1 − e^(−p |x − xa|)) sgn(x − xa)`, `∂F/∂x = k0 e^(−p |x − xa|)` with
/// `A = λ h0`, `p = ac / λ` (`λ = 1`, `xa = ha = 0` on the virgin curve), valid until `x`
/// reaches the branch's closure target. A trial on that branch costs one `exp`; any other
/// (a reversal inside the trial, a loop closing) walks the memory as [`masing_trial`] does.
struct MasingExp {
    curve: MasingCurve,
    h0: f64,
    ac: f64,
    scale: f64,
    /// `h0 · ac`, `λ h0`, `ac / λ`.
    k0: f64,
    amp_branch: f64,
    p_branch: f64,
    st: MasingState,
    /// The cached branch, for motion in `dir` (along which `x − xa` has the sign of `dir`):
    /// `F = cg − sa e`, `e = e^(pd (xa − x))` with `cg = ha + dir A`, `sa = dir A`, `pd = dir p`.
    /// It holds while `x · dir < lim` (`+∞` on the virgin curve, `−∞`: no cached branch).
    xa: f64,
    cg: f64,
    sa: f64,
    pd: f64,
    lim: f64,
    /// The last trial: force, tangent, memory update (as [`Trial::aux`]).
    f: f64,
    kt: f64,
    aux: usize,
    /// The exponent `pd (xa − x)` and `e` at the last trial on the cached branch in this step
    /// (`argl` NaN: none).
    argl: f64,
    el: f64,
    jf: f64,
    jwork: f64,
    stored0: f64,
    kept: [f64; 3],
}

impl MasingExp {
    /// The joint loaded from the virgin state to `x0`; `None` unless `joints` is exactly one
    /// Masing joint on the exponential curve.
    fn new(joints: &[Joint], x0: f64) -> Option<(Self, Sum)> {
        let [Joint {
            law: JointLaw::Masing { curve, scale },
            ..
        }] = joints
        else {
            return None;
        };
        let MasingCurve::Exp(c) = curve else {
            return None;
        };
        let (h0, ac, scale) = (c.h0, c.ac, *scale);
        let mut me = Self {
            curve: curve.clone(),
            h0,
            ac,
            scale,
            k0: h0 * ac,
            amp_branch: scale * h0,
            p_branch: ac / scale,
            st: MasingState::default(),
            xa: 0.0,
            cg: 0.0,
            sa: 0.0,
            pd: 0.0,
            lim: f64::NEG_INFINITY,
            f: 0.0,
            kt: 0.0,
            aux: 0,
            argl: f64::NAN,
            el: 1.0,
            jf: 0.0,
            jwork: 0.0,
            stored0: 0.0,
            kept: [0.0; 3],
        };
        // (the virgin state has no cached branch: this is the memory walk)
        let pt = Point {
            x1: x0,
            v1: 0.0,
            xp: x0,
            b: 0.0,
            a1: 0.0,
        };
        let s = me.trial(0.0, &pt);
        masing_commit(&mut me.st, x0, me.f, me.aux);
        me.refresh();
        me.jf = me.f;
        me.stored0 = me.stored();
        Some((me, s))
    }

    /// Cache the branch that motion in the current direction follows.
    #[inline(always)]
    fn refresh(&mut self) {
        let dir = f64::from(self.st.dir);
        let (xa, ha, amp, p, lim) = match self.st.stack.split_last() {
            None => (0.0, 0.0, self.h0, self.ac, f64::INFINITY),
            Some((top, rest)) => {
                // Moving on, the branch closes at the reversal below (or, from the first
                // reversal, rejoins the virgin curve at its mirror point).
                let target = rest.last().map_or(-top.x, |b| b.x);
                (top.x, top.h, self.amp_branch, self.p_branch, target * dir)
            }
        };
        (self.xa, self.cg, self.sa, self.pd) = (xa, ha + dir * amp, dir * amp, dir * p);
        // The memory rules keep the current point on the far side of the anchor in the
        // direction of motion; anything else (or no direction yet) takes the memory walk.
        let on_branch = dir != 0.0 && (self.st.x - xa) * dir >= 0.0;
        self.lim = if on_branch { lim } else { f64::NEG_INFINITY };
    }

    /// A trial off the cached branch (a reversal inside the trial, a loop closing): the
    /// memory walk of [`masing_trial`]. Out of line, so the Newton loop stays small.
    #[cold]
    #[inline(never)]
    fn walk(&mut self, x1: f64) {
        (self.f, self.kt, self.aux) = masing_trial(&self.curve, self.scale, &self.st, x1);
        self.argl = f64::NAN;
    }

    #[inline(always)]
    fn stored(&self) -> f64 {
        0.5 * self.st.h * self.st.h / self.k0
    }
}

impl Joints for MasingExp {
    #[inline(always)]
    fn keep(&mut self, slot: usize, (dx, _): (f64, f64)) {
        if let Some(v) = self.kept.get_mut(slot) {
            *v = self.f + self.kt * dx;
        }
    }

    #[inline(always)]
    fn shift(&mut self, (dx, _): (f64, f64)) {
        self.f += self.kt * dx;
    }

    #[inline(always)]
    fn holds(&self, x0: f64, x_trial: f64, x1: f64) -> bool {
        x_trial == x1
            || ((x_trial - x0) * (x1 - x0) > 0.0
                && masing_closure(&self.st, x_trial).is_some()
                    == masing_closure(&self.st, x1).is_some())
    }

    fn hermite(&self) -> bool {
        true
    }

    fn kinks(&self) -> bool {
        true
    }

    #[inline(always)]
    fn kink(&self, x1: f64) -> Option<(f64, f64)> {
        masing_kink(&self.curve, self.scale, &self.st, x1)
    }

    #[inline(always)]
    fn start_tangent(&self, _x0: f64, _x1: f64) -> Option<(f64, f64)> {
        // a trial that reversed starts a branch, whose slope at its anchor is f'(0)
        (self.aux & 1 == 1).then_some((self.k0, 0.0))
    }

    #[inline(always)]
    fn commit_hermite(&mut self, x0: f64, x1: f64, e: &Ends) -> Result<(), CoreError> {
        let k1 = self.kt + e.dk.1;
        self.jwork += masing_work(x1 - x0, (self.jf, e.kt0), (self.f, k1));
        masing_commit(&mut self.st, x1, self.f, self.aux);
        self.refresh();
        self.argl = f64::NAN;
        self.jf = self.f;
        Ok(())
    }

    #[inline(always)]
    fn commit_doubled(
        &mut self,
        x0: f64,
        ends: (f64, f64, f64),
        ext: f64,
        xr: f64,
    ) -> Result<(), CoreError> {
        self.jwork += doubled_work(self.jf, self.kept, x0, ends, ext);
        masing_commit(&mut self.st, xr, self.f, self.aux);
        self.refresh();
        self.argl = f64::NAN;
        self.jf = self.f;
        Ok(())
    }

    // `2 · (reversals kept)`: at most twice the stack length, a Vec's length.
    #[inline(always)]
    #[allow(clippy::arithmetic_side_effects)]
    fn trial(&mut self, _x0: f64, pt: &Point) -> Sum {
        let x1 = pt.x1;
        let dx = x1 - self.st.x;
        let dir = f64::from(self.st.dir);
        let lim = self.lim;
        if (dx * dir > 0.0 && x1 * dir < lim) || (dx == 0.0 && lim > f64::NEG_INFINITY) {
            // −p |x1 − xa| with x1 = xp + b a1: the part without a1 is known before the
            // iterate, so the exponent is one multiply-add away from it.
            let arg = self.pd * (self.xa - pt.xp) - (self.pd * pt.b) * pt.a1;
            // Newton's later trials move by a small correction from the last one on this
            // branch: e = e_last · e^z, z = arg − arg_last, with e^z by its series (|z| <
            // 1e-3: truncation below 1e-17 relative). NaN `argl`: none.
            let z = arg - self.argl;
            let e = if z.abs() < 1e-3 {
                let z2 = z * z;
                self.el * ((1.0 + z) + z2 * ((0.5 + z * (1.0 / 6.0)) + z2 * (1.0 / 24.0)))
            } else {
                // (≤ 0 up to rounding; a NaN stays NaN and fails the step)
                (if arg > 0.0 { 0.0 } else { arg }).exp()
            };
            (self.argl, self.el) = (arg, e);
            self.f = self.cg - self.sa * e;
            self.kt = self.k0 * e;
            self.aux = 2 * self.st.stack.len();
        } else {
            self.walk(x1);
        }
        Sum {
            f: self.f,
            fmax: self.f.abs(),
            kt: self.kt,
            ct: 0.0,
        }
    }

    #[inline(always)]
    fn event(&self, _x0: f64, _x1: f64, v0: f64, v1: f64) -> f64 {
        // a velocity reversal (the law is rate-independent, so that is its only event)
        if v0 * v1 < 0.0 {
            let t = v0 / (v0 - v1);
            if t > 0.0 && t < 1.0 {
                return t;
            }
        }
        1.0
    }

    #[inline(always)]
    fn commit(&mut self, x0: f64, x1: f64) -> Result<(), CoreError> {
        self.jwork += 0.5 * (self.jf + self.f) * (x1 - x0);
        masing_commit(&mut self.st, x1, self.f, self.aux);
        self.refresh();
        // each step's first trial is a full `exp` (no drift from chained products)
        self.argl = f64::NAN;
        self.jf = self.f;
        Ok(())
    }

    #[inline(always)]
    fn record(&self, _x: f64, i: usize, out: &mut Buffers<'_>) {
        put(out.joint_force, i, self.jf);
        put(out.joint_work, i, self.jwork);
        if let Some(d) = out.joint_dissipated.get_mut(i) {
            *d = self.jwork - (self.stored() - self.stored0);
        }
    }
}

/// The state at the start of a step (`x`, `v`, `a`, load `f`), the energies, and the joints'
/// summed force and tangents there (Newton's predictor).
struct State {
    x: f64,
    v: f64,
    a: f64,
    f: f64,
    e_in: f64,
    e_damp: f64,
    g: f64,
    kt: f64,
    ct: f64,
}

/// A converged step (not yet committed) and the joints' sum at its end.
struct Step {
    /// (How far the end moved after the joints' last trial, in `x` and `v`: nonzero only for
    /// a step ended without a final trial.)
    moved: (f64, f64),
    dx: f64,
    x1: f64,
    v1: f64,
    a1: f64,
    f1: f64,
    joints: Sum,
}

/// External load at fraction `tau` of interval `i → i+1` (the dense path's `load`, n = 1).
#[inline(always)]
// `i + 1` for a sample index i < len(t) (the caller's loop bound); `last = len(t) − 1 ≥ 0`.
#[allow(clippy::arithmetic_side_effects)]
fn load(inp: &Inputs<'_>, i: usize, tau: f64) -> f64 {
    let last = inp.t.len() - 1;
    let i1 = (i + 1).min(last);
    let w0 = if i1 == i { 1.0 } else { 1.0 - tau };
    let w1 = 1.0 - w0;
    let mut out = 0.0;
    if let Some(f) = inp.force {
        out += w0 * f[i] + w1 * f[i1];
    }
    if let Some((y, yd, kr, cr)) = inp.base {
        let yy = w0 * y[i] + w1 * y[i1];
        let yv = w0 * yd[i] + w1 * yd[i1];
        out += kr[0] * yy + cr[0] * yv;
    }
    out
}

/// One Newmark step of length `h` from `w` to load `f1` (`mck`: the scalar M, C, K), the joints
/// tried from their committed position `xc` (`w.x`, or the start of a step-doubling piece when
/// `w` is its midpoint: a monotone path, so the same end state). Returns the step and the
/// Newton iterations used, or `None` if Newton failed.
// The step's context (joints, M C K, state, start, length, load, options) as it is.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn newton<J: Joints>(
    jt: &mut J,
    (m, c, k): (f64, f64, f64),
    w: &State,
    (xc, quick): (f64, f64),
    h: f64,
    f1: f64,
    opts: &Options,
) -> Option<(Step, u64)> {
    let (b, g) = (0.25 * h * h, 0.5 * h);
    // The step's known parts: x1 = xp + b a1, v1 = vp + g a1 (Newmark, β = 1/4, γ = 1/2).
    // Written so that the chains from the joints' last `exp` to the next trial point are short:
    // the sums below that do not involve the joints are formed while it runs.
    let (dxp, dvp) = (h * w.v + b * w.a, g * w.a);
    let (xp, vp) = (w.x + dxp, w.v + dvp);
    let jac0 = m + g * c + b * k;
    // Predictor: the step of the equation linearised at its start (joint forces by their
    // tangents there). Where the joints are nearly linear over a step (stuck, or sliding far
    // from a reversal) this already meets the tolerance and Newton ends after one residual.
    let mut a1 = {
        let (kt, ct) = (w.kt, w.ct);
        let lin = f1 - (c * vp + k * xp);
        let rhs = (lin - w.g) - (kt * dxp + ct * dvp);
        let p = rhs / (jac0 + (b * kt + g * ct));
        if p.is_finite() {
            p
        } else {
            w.a
        }
    };
    for it in 1..=opts.max_iter as u64 {
        let x1 = xp + b * a1;
        let v1 = vp + g * a1;
        let pt = Point { x1, v1, xp, b, a1 };
        let js = jt.trial(xc, &pt);
        let (ma, cv, kx) = (m * a1, c * v1, k * x1);
        let r = ((ma + cv) + (kx - f1)) + js.f;
        let scale = (f1.abs() + ((ma.abs() + cv.abs()) + kx.abs())).max(js.fmax);
        if !r.is_finite() {
            return None;
        }
        if r.abs() <= opts.rtol * scale.max(f64::MIN_POSITIVE) {
            let st = Step {
                dx: x1 - xc,
                x1,
                v1,
                a1,
                f1,
                joints: js,
                moved: (0.0, 0.0),
            };
            return Some((st, it));
        }
        let jac = jac0 + (b * js.kt + g * js.ct);
        if !(jac != 0.0 && jac.is_finite()) {
            return None;
        }
        let da = r / jac;
        a1 -= da;
        if r.abs() <= quick * scale {
            // Newton converges quadratically: the next residual would be of the order of the
            // square of this one, so the update is kept without another trial, the joints'
            // forces carried along their tangents (a step-doubling pair's inner steps only:
            // their joint trials are never committed)
            let (mut mx, mut mv) = (-b * da, -g * da);
            let mut joints = js;
            joints.f += js.kt * mx + js.ct * mv;
            let (x1, v1) = (xp + b * a1, vp + g * a1);
            if !jt.holds(xc, x1 - mx, x1) {
                // the update moved the end across the start or a slip point: tried anew
                joints = jt.trial(xc, &Point { x1, v1, xp, b, a1 });
                (mx, mv) = (0.0, 0.0);
            }
            let st = Step {
                dx: x1 - xc,
                x1,
                v1,
                a1,
                f1,
                joints,
                moved: (mx, mv),
            };
            return Some((st, it));
        }
    }
    None
}

/// Commit a converged step, with the energy bookkeeping.
#[inline(always)]
fn accept<J: Joints>(jt: &mut J, c: f64, w: &mut State, st: &Step) -> Result<(), CoreError> {
    w.e_in += st.dx * 0.5 * (w.f + st.f1);
    w.e_damp += st.dx * (c * (0.5 * (w.v + st.v1)));
    jt.commit(w.x, st.x1)?;
    w.x = st.x1;
    w.v = st.v1;
    (w.g, w.kt, w.ct) = (st.joints.f, st.joints.kt, st.joints.ct);
    w.a = st.a1;
    w.f = st.f1;
    Ok(())
}

/// `buf[i] = v`, unless the buffer is empty (an output the caller did not ask for).
#[inline(always)]
fn put(buf: &mut [f64], i: usize, v: f64) {
    if let Some(slot) = buf.get_mut(i) {
        *slot = v;
    }
}

/// Write the state as sample `i` (`i < len(t)`).
#[inline(always)]
fn record<J: Joints>(jt: &J, w: &State, out: &mut Buffers<'_>, i: usize) {
    put(out.x, i, w.x);
    put(out.v, i, w.v);
    put(out.a, i, w.a);
    jt.record(w.x, i, out);
    put(out.input_work, i, w.e_in);
    put(out.damping_work, i, w.e_damp);
}

/// The one-DOF simulation (inputs already checked by `newmark::simulate`).
pub(super) fn simulate(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: f64,
    v0: f64,
    opts: &Options,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    if let Some((mut jt, start)) = MasingExp::new(&s.joints, x0) {
        return run(s, inp, x0, v0, opts, &mut jt, start, out);
    }
    let (mut jt, start) = Dyn::new(&s.joints, x0, v0)?;
    run(s, inp, x0, v0, opts, &mut jt, start, out)
}

/// The integration loop for the joint set `jt` (already loaded to `x0`, with `start` there).
fn run<J: Joints>(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: f64,
    v0: f64,
    opts: &Options,
    jt: &mut J,
    start: Sum,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    let f0 = load(inp, 0, 0.0);
    // a0 = (f0 − C v0 − K x0 − G0) / M
    let (m, c, k) = (s.m[0], s.c[0], s.k[0]);
    if !(m != 0.0 && m.is_finite()) {
        return Err(CoreError::InvalidParameter {
            name: "M",
            value: 0.0,
            reason: "mass matrix is singular",
        });
    }
    let rhs = f0 - c * v0 - k * x0 - start.f;
    let mut w = State {
        x: x0,
        v: v0,
        a: rhs / m,
        f: f0,
        e_in: 0.0,
        e_damp: 0.0,
        g: start.f,
        kt: start.kt,
        ct: start.ct,
    };
    let mut sum = Summary::new();
    record(jt, &w, out, 0);
    sum.n_out = 1;
    if let Some(tol) = opts.tol {
        let rate = super::stiff_rate(s);
        return adaptive::run(inp, (m, c, k), (tol, rate), opts, jt, w, sum, out);
    }
    // fixed steps: `substeps` equal pieces per interval (events and halvings split them)
    let k_sub = opts.substeps as f64;
    let piece = 1.0 / k_sub;
    let max_events = opts.max_events.saturating_mul(opts.substeps);
    for (i, pair) in inp.t.windows(2).enumerate() {
        let big_h = pair[1] - pair[0];
        let mut tau = 0.0_f64;
        let mut halvings = 0usize;
        let mut events = 0usize;
        let mut frac = piece;
        while tau < 1.0 {
            let step = frac.min(1.0 - tau);
            let h = step * big_h;
            let tau1 = if step >= 1.0 - tau { 1.0 } else { tau + step };
            let f1 = load(inp, i, tau1);
            let Some((st, it)) = newton(jt, (m, c, k), &w, (w.x, 0.0), h, f1, opts) else {
                halvings = halvings.saturating_add(1);
                if halvings > opts.max_halvings.saturating_mul(opts.substeps) {
                    sum.status = Status::NoConvergence {
                        time: inp.t[i] + tau * big_h,
                        step: h,
                    };
                    return Ok(sum);
                }
                frac = 0.5 * step;
                continue;
            };
            sum.n_iter = sum.n_iter.saturating_add(it);
            if events < max_events {
                let theta = jt.event(w.x, st.x1, w.v, st.v1);
                if theta < 1.0 {
                    let min_piece = 1e-3 * piece / step;
                    if theta > min_piece && theta < 1.0 - min_piece {
                        events = events.saturating_add(1);
                        frac = step * theta;
                        continue;
                    }
                }
            }
            accept(jt, c, &mut w, &st)?;
            sum.n_steps = sum.n_steps.saturating_add(1);
            tau = tau1;
            // on to the next point of the fixed grid (events split between them)
            frac = ((tau * k_sub + 1e-9).floor() + 1.0) / k_sub - tau;
            frac = frac.min(1.0 - tau).max(0.0);
            if !(w.x.is_finite() && w.v.is_finite()) {
                sum.status = Status::NonFinite {
                    time: inp.t[i] + tau * big_h,
                };
                return Ok(sum);
            }
        }
        let next = i.saturating_add(1); // < nt
        record(jt, &w, out, next);
        sum.n_out = next.saturating_add(1);
    }
    Ok(sum)
}

mod adaptive;
#[cfg(test)]
mod tests;
