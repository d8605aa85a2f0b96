//! Joint elements acting on a relative displacement `d` (PHYSICS.md §1 for Masing): the force
//! `F(d, ḋ, history)`, its tangents `∂F/∂d`, `∂F/∂ḋ` for Newton's method, the state update once
//! a step is accepted, the stored (recoverable) energy, and where inside a step the law
//! changes character (a reversal, a stick-slip transition) so the integrator can sub-step.
//!
//! Every hysteretic law here is rate-independent: a step from `d_n` to `d_{n+1}` is taken as a
//! monotone path, which is why steps are split at velocity reversals.

use crate::curve::{Backbone, Exponential, Tabulated};
use crate::error::{check_finite, check_positive, CoreError};
use crate::joints::{AnyLaw, AnyState, Law};
use crate::masing::{MasingState, Reversal};
use crate::normal::poly;

/// The virgin curve of a Masing joint.
#[derive(Debug, Clone, PartialEq)]
pub enum MasingCurve {
    Exp(Exponential),
    Tab(Tabulated),
}

impl Backbone for MasingCurve {
    #[inline]
    fn eval(&self, u: f64) -> f64 {
        match self {
            Self::Exp(c) => c.eval(u),
            Self::Tab(c) => c.eval(u),
        }
    }
    #[inline]
    fn slope(&self, u: f64) -> f64 {
        match self {
            Self::Exp(c) => c.slope(u),
            Self::Tab(c) => c.slope(u),
        }
    }
    fn integral(&self, u: f64) -> f64 {
        match self {
            Self::Exp(c) => c.integral(u),
            Self::Tab(c) => c.integral(u),
        }
    }
}

impl MasingCurve {
    /// `(f(u), f'(u))` with one transcendental call for the exponential curve.
    #[inline(always)]
    fn eval_slope(&self, u: f64) -> (f64, f64) {
        match self {
            Self::Exp(c) => {
                // One `exp` (a short table-driven libm call): the force to ~1 ulp of h0, the
                // tangent (Newton's only) to full relative accuracy.
                let e = (-c.ac * u.abs()).exp();
                ((c.h0 - c.h0 * e).copysign(u), c.h0 * c.ac * e)
            }
            Self::Tab(c) => (c.eval(u), c.slope(u)),
        }
    }
}

/// A joint's constitutive law.
#[derive(Debug, Clone, PartialEq)]
pub enum JointLaw {
    /// Masing operator with non-local memory, branch scale λ.
    Masing { curve: MasingCurve, scale: f64 },
    /// Elastic-Coulomb (Jenkins): stiffness `k` in series with a slider of slip force `fs`.
    Jenkins { k: f64, fs: f64 },
    /// Parallel Jenkins elements (a discretised Iwan model).
    Iwan { k: Vec<f64>, fs: Vec<f64> },
    /// `F = z`, `dz/dd = α − β (γ s |z|^(ν−1) z + δ |z|^ν)`, `s = sign(ḋ)` (Bouc-Wen in the
    /// form of the hysteretic benchmark).
    BoucWen {
        alpha: f64,
        beta: f64,
        gamma: f64,
        delta: f64,
        nu: f64,
    },
    /// `F = k d + c ḋ`.
    KelvinVoigt { k: f64, c: f64 },
    /// `F = k_s(d) d`, `k_s` a polynomial with ascending coefficients (normal contact, eq. 6);
    /// stored as the coefficients of `F(d)` itself.
    Normal {
        force: Vec<f64>,
        slope: Vec<f64>,
        energy: Vec<f64>,
    },
    /// A law of [`crate::joints`] (exact along each monotone step; tangent by a one-sided
    /// difference in the direction of motion), with its initial stiffness. A rate-dependent
    /// law (`rate`) sees the step's end velocity `v` as its constant velocity over the step
    /// (its time step taken as `Δd / v`), and adds `∂F/∂v` to Newton's damping tangent.
    Law {
        law: Box<AnyLaw>,
        k0: f64,
        rate: bool,
    },
}

impl JointLaw {
    pub fn jenkins(k: f64, fs: f64) -> Result<Self, CoreError> {
        check_positive("k", k)?;
        check_positive("fs", fs)?;
        Ok(Self::Jenkins { k, fs })
    }

    pub fn iwan(k: &[f64], fs: &[f64]) -> Result<Self, CoreError> {
        crate::error::check_same_len("iwan k", k.len(), "iwan fs", fs.len())?;
        if k.is_empty() {
            return Err(CoreError::Empty { name: "iwan k" });
        }
        for (&ki, &fi) in k.iter().zip(fs) {
            check_positive("iwan k", ki)?;
            check_positive("iwan fs", fi)?;
        }
        Ok(Self::Iwan {
            k: k.to_vec(),
            fs: fs.to_vec(),
        })
    }

    pub fn masing(curve: MasingCurve, scale: f64) -> Result<Self, CoreError> {
        check_positive("scale", scale)?;
        Ok(Self::Masing { curve, scale })
    }

    pub fn bouc_wen(
        alpha: f64,
        beta: f64,
        gamma: f64,
        delta: f64,
        nu: f64,
    ) -> Result<Self, CoreError> {
        check_positive("alpha", alpha)?;
        check_positive("nu", nu)?;
        check_finite("gamma", &[gamma])?;
        check_finite("delta", &[delta])?;
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "beta",
                value: beta,
                reason: "must be finite and >= 0",
            });
        }
        Ok(Self::BoucWen {
            alpha,
            beta,
            gamma,
            delta,
            nu,
        })
    }

    pub fn kelvin_voigt(k: f64, c: f64) -> Result<Self, CoreError> {
        for (name, v) in [("k", k), ("c", c)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(CoreError::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and >= 0",
                });
            }
        }
        Ok(Self::KelvinVoigt { k, c })
    }

    /// `k_s(d) = coeffs[0] + coeffs[1] d + …`, `F = k_s(d) d`.
    pub fn normal(coeffs: &[f64]) -> Result<Self, CoreError> {
        if coeffs.is_empty() {
            return Err(CoreError::Empty {
                name: "normal coeffs",
            });
        }
        check_finite("normal coeffs", coeffs)?;
        let force: Vec<f64> = std::iter::once(0.0).chain(coeffs.iter().copied()).collect();
        Ok(Self::Normal {
            slope: poly::deriv(&force),
            energy: poly::integral(&force),
            force,
        })
    }

    /// Tangent stiffness in the virgin state (d = 0, no history).
    pub fn initial_stiffness(&self) -> f64 {
        match self {
            Self::Masing { curve, .. } => curve.slope(0.0),
            Self::Jenkins { k, .. } | Self::KelvinVoigt { k, .. } => *k,
            Self::Iwan { k, .. } => k.iter().sum(),
            Self::BoucWen { alpha, .. } => *alpha,
            Self::Normal { slope, .. } => poly::eval(slope, 0.0),
            Self::Law { k0, .. } => *k0,
        }
    }

    /// A joint of a [`crate::joints`] law (rate-dependent ones included: see
    /// [`JointLaw::Law`]).
    pub fn law(law: AnyLaw) -> Result<Self, CoreError> {
        let st = law.start(0.0);
        let rate = law.rate_dependent();
        let k0 = law_tangent(&law, &st, 0.0, 0.0, 1.0, None).1;
        Ok(Self::Law {
            law: Box::new(law),
            k0,
            rate,
        })
    }

    /// The tangents `(∂F/∂d, ∂F/∂ḋ)` at the start `d_old` of the trial `tr` (to `d_new`) along
    /// its direction (the right limit), where they may differ from the left limit the last
    /// step ended with: a Masing branch that the trial starts (its slope at 0), a Bouc-Wen
    /// rate in the trial's direction, a Jenkins/Iwan element that began to slip or stick (its
    /// tangent is constant between events: the trial's own). `None`: the left limit holds.
    pub fn start_tangent(
        &self,
        state: &JointState,
        d_old: f64,
        d_new: f64,
        tr: &Trial,
    ) -> Option<(f64, f64)> {
        match (self, state) {
            (Self::Masing { curve, .. }, _) if tr.aux & 1 == 1 => Some((curve.slope(0.0), 0.0)),
            (Self::Jenkins { .. } | Self::Iwan { .. }, _) => Some((tr.kt, tr.ct)),
            (
                Self::BoucWen {
                    alpha,
                    beta,
                    gamma,
                    delta,
                    nu,
                },
                JointState::Slider(z0),
            ) => {
                let s = if d_new < d_old { -1.0 } else { 1.0 };
                let kt = bw_rate(*alpha, *beta, *gamma, *delta, *nu, *z0, s);
                Some((kt.max(0.0), 0.0))
            }
            _ => None,
        }
    }

    /// The relative displacement inside the monotone move from `state` to `d_new` at which
    /// the law's tangent jumps without an [`JointLaw::event`], and the jump: a Masing branch
    /// closing ([`masing_kink`]). `None` for every other law, or no such point.
    #[inline]
    pub fn kink(&self, state: &JointState, d_new: f64) -> Option<(f64, f64)> {
        match (self, state) {
            (Self::Masing { curve, scale }, JointState::Masing(st)) => {
                masing_kink(curve, *scale, st, d_new)
            }
            _ => None,
        }
    }

    /// The first stick-slip transition of a Jenkins/Iwan element on the monotone move
    /// `d_old → d_new` from `state` beyond the fraction `floor` of the move (an element's force
    /// is linear in `d` while it sticks), as a fraction of the move; `None`: none, or another
    /// law. (Transitions at most `floor` in are left to the piece that contains them, so that
    /// they do not hide a later event.)
    #[inline]
    pub fn slip_after(
        &self,
        state: &JointState,
        d_old: f64,
        d_new: f64,
        floor: f64,
    ) -> Option<f64> {
        let dd = d_new - d_old;
        if dd == 0.0 {
            return None;
        }
        let mut theta: Option<f64> = None;
        let mut stick_slip = |k: f64, fs: f64, f0: f64| {
            let ft = f0 + k * dd;
            if f0.abs() < fs && ft.abs() > fs {
                let t = (fs.copysign(ft) - f0) / (k * dd);
                if t > floor && t < 1.0 {
                    theta = Some(theta.map_or(t, |a: f64| a.min(t)));
                }
            }
        };
        match (self, state) {
            (Self::Jenkins { k, fs }, JointState::Slider(f0)) => stick_slip(*k, *fs, *f0),
            (Self::Iwan { k, fs }, JointState::Sliders(f0)) => {
                for ((&ki, &fi), &f0i) in k.iter().zip(fs).zip(f0) {
                    stick_slip(ki, fi, f0i);
                }
            }
            _ => {}
        }
        theta
    }

    /// Whether the trial `tr` from `state` crossed a Masing branch's closure (its memory walk
    /// dropped a branch: fewer branches kept than it started with). `false` for other laws.
    #[inline]
    pub fn closed(&self, state: &JointState, tr: &Trial) -> bool {
        match (self, state) {
            (Self::Masing { .. }, JointState::Masing(st)) => {
                tr.aux / 2 < st.stack.len().saturating_add(tr.aux & 1)
            }
            _ => false,
        }
    }

    /// A Bouc-Wen joint with `ν = 1` whose `z` changes sign over the trial `tr` from `state`:
    /// `(z0, z1, Δ)` with `Δ` the jump of `∂(dz/dd)/∂z` there (`−βδ (sgn z1 − sgn z0)`; the
    /// rate `dz/dd` itself is continuous, `α`, so the force's second time derivative jumps by
    /// `Δ α ḋ²`). `None` for every other law, `ν ≠ 1`, or no sign change.
    #[inline]
    pub fn zero_crossing(&self, state: &JointState, tr: &Trial) -> Option<(f64, f64, f64)> {
        match (self, state) {
            (
                Self::BoucWen {
                    beta, delta, nu, ..
                },
                JointState::Slider(z0),
            ) if *nu == 1.0 && *z0 * tr.f < 0.0 => {
                let jump = -beta * delta * (tr.f.signum() - z0.signum());
                Some((*z0, tr.f, jump))
            }
            _ => None,
        }
    }

    /// Whether a trial made at `d_trial` (from `state`, committed at `d_old`) still describes
    /// the nearby `d_new` when carried along its tangents: the move keeps its direction (a
    /// Masing branch, a Bouc-Wen rate and a rate-dependent law depend on it), no Masing branch
    /// closes between the two and no Jenkins/Iwan element sticks at one point and slips at the
    /// other. A Newton solve that ends without a
    /// last trial (see `newmark::newton_step`) tries the joint anew at `d_new` otherwise: an end
    /// that a small update moved back across the start, or across a slip point, would be
    /// carried along the tangents of the wrong branch or regime for the whole piece.
    #[inline]
    pub fn holds(&self, state: &JointState, d_old: f64, d_trial: f64, d_new: f64) -> bool {
        let slips = |k: f64, fs: f64, f0: f64, d: f64| {
            let ft = f0 + k * (d - d_old);
            (ft.abs() > fs, ft > 0.0)
        };
        match (self, state) {
            (Self::KelvinVoigt { .. } | Self::Normal { .. }, _) => true,
            (Self::Jenkins { k, fs }, JointState::Slider(f0)) => {
                slips(*k, *fs, *f0, d_trial) == slips(*k, *fs, *f0, d_new)
            }
            (Self::Iwan { k, fs }, JointState::Sliders(f0)) => {
                k.iter().zip(fs).zip(f0).all(|((&ki, &fi), &f0i)| {
                    slips(ki, fi, f0i, d_trial) == slips(ki, fi, f0i, d_new)
                })
            }
            (Self::Masing { .. }, JointState::Masing(st)) => {
                d_trial == d_new
                    || ((d_trial - d_old) * (d_new - d_old) > 0.0
                        && masing_closure(st, d_trial).is_some()
                            == masing_closure(st, d_new).is_some())
            }
            _ => (d_trial - d_old) * (d_new - d_old) > 0.0 || d_trial == d_new,
        }
    }

    /// The virgin state (d = 0, F = 0).
    pub fn fresh_state(&self) -> JointState {
        match self {
            Self::Masing { .. } => JointState::Masing(MasingState::default()),
            Self::Jenkins { .. } | Self::BoucWen { .. } => JointState::Slider(0.0),
            Self::Iwan { k, .. } => JointState::Sliders(vec![0.0; k.len()]),
            Self::KelvinVoigt { .. } | Self::Normal { .. } => JointState::Elastic,
            Self::Law { law, .. } => JointState::Law(Box::new(law.start(0.0))),
        }
    }
}

/// History of a joint.
#[derive(Debug, Clone, PartialEq)]
pub enum JointState {
    Masing(MasingState),
    /// Jenkins: the force; Bouc-Wen: `z`.
    Slider(f64),
    /// Iwan: each element's force.
    Sliders(Vec<f64>),
    Elastic,
    /// A [`crate::joints`] law's state.
    Law(Box<AnyState>),
}

/// The time step a rate-dependent law is given for the step `d_old -> d` at the end velocity
/// `v`: `Δd / v` (the law then sees the velocity `v`), `None` (a quasi-static step, velocity
/// 0) when `v` is 0 or against the step, or for a rate-independent law (`v = None`).
#[inline]
fn law_dt(d_old: f64, d: f64, v: Option<f64>) -> Option<f64> {
    let v = v?;
    let dt = (d - d_old) / v;
    (dt > 0.0 && dt.is_finite()).then_some(dt)
}

/// Force of `law` at `d` from `st` (unchanged) and its tangent by a one-sided difference in
/// the direction `dir` of the motion (`h`: 1e-7 of the step, at least 1e-9 of |d| and 1e-15),
/// at the velocity `v` held (a rate-dependent law; `None` otherwise).
fn law_tangent(
    law: &AnyLaw,
    st: &AnyState,
    d_old: f64,
    d: f64,
    dir: f64,
    v: Option<f64>,
) -> (f64, f64) {
    let mut s = st.clone();
    let f = law.step(&mut s, law_dt(d_old, d, v), d);
    let h = (1e-7 * (d - d_old).abs()).max(1e-9 * d.abs()).max(1e-15) * dir;
    let mut s2 = st.clone();
    let f2 = law.step(&mut s2, law_dt(d_old, d + h, v), d + h);
    (f, ((f2 - f) / h).max(0.0))
}

/// `∂F/∂v` of a rate-dependent law at the step `d_old -> d` (one-sided difference of 1e-7 of
/// `|v|`; 0 for a quasi-static step).
fn law_damping(law: &AnyLaw, st: &AnyState, d_old: f64, d: f64, v: f64, f: f64) -> f64 {
    if law_dt(d_old, d, Some(v)).is_none() {
        return 0.0;
    }
    let hv = 1e-7 * v;
    let Some(dt) = law_dt(d_old, d, Some(v + hv)) else {
        return 0.0;
    };
    let mut s = st.clone();
    let f2 = law.step(&mut s, Some(dt), d);
    ((f2 - f) / hv).max(0.0)
}

/// Force and tangents at a trial displacement.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Trial {
    pub f: f64,
    /// `∂F/∂d`.
    pub kt: f64,
    /// `∂F/∂ḋ`.
    pub ct: f64,
    /// Masing: `2 × (reversals kept) + (1 if the trial point pushed a reversal)`, so that
    /// committing applies the same memory update without walking the branches again.
    pub aux: usize,
    /// The velocity the trial was made at (a rate-dependent law's commit repeats it).
    pub v: f64,
}

/// Masing force and tangent at `x` from `state`, without changing the state (the branch logic
/// of [`crate::masing`]: a reversal pushes the current point, reaching a closure target pops).
/// Returns `(f, slope, aux)` with `aux` as in [`Trial::aux`].
// Stack-depth arithmetic: `len` counts the reversals walked (<= stack length + 1) and only
// `len - 1`, `len - 2` where len >= 1, 2; `2 * len + 1` <= 2 * stack length + 3.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
pub(super) fn masing_trial(
    curve: &MasingCurve,
    scale: f64,
    st: &MasingState,
    x: f64,
) -> (f64, f64, usize) {
    let dx = x - st.x;
    let dir = f64::from(st.dir);
    let s = if dx > 0.0 {
        1.0
    } else if dx < 0.0 {
        -1.0
    } else {
        dir
    };
    let pushed = s != dir && st.dir != 0 && dx != 0.0;
    let n = st.stack.len();
    let get = |k: usize| -> (f64, f64) {
        if k < n {
            (st.stack[k].x, st.stack[k].h)
        } else {
            (st.x, st.h)
        }
    };
    let mut len = n + usize::from(pushed);
    loop {
        let (xa, ha, target) = match len {
            0 => {
                let (f, k) = curve.eval_slope(x);
                return (f, k, usize::from(pushed));
            }
            1 => {
                let a = get(0);
                (a.0, a.1, -a.0)
            }
            _ => {
                let a = get(len - 1);
                (a.0, a.1, get(len - 2).0)
            }
        };
        if dx != 0.0 && (x - target) * s >= 0.0 {
            len -= if len == 1 { 1 } else { 2 };
            continue;
        }
        let (f, k) = curve.eval_slope((x - xa) / scale);
        return (ha + scale * f, k, 2 * len + usize::from(pushed));
    }
}

/// The closure a Masing joint in `st` (at `st.x`) crosses on a monotone move to `x1`, as
/// `(x_k, Δk)`: the displacement `x_k` where its branch rejoins the one below (the reversal
/// before the anchor, or the mirror point `−x_a` of a lone reversal) and the jump `Δk` of the
/// tangent there (the outer branch's slope minus the closing one's; the force is continuous).
/// The branch is the trial's own ([`masing_trial`]): after a reversal at `st.x` (a move
/// against `st.dir`), the new branch anchored there. `None`: the move stays on its branch (or
/// on the virgin curve, which never closes). Only the first closure is named: a piece that
/// ends there finds the next one from its end.
#[inline]
pub(super) fn masing_kink(
    curve: &MasingCurve,
    scale: f64,
    st: &MasingState,
    x1: f64,
) -> Option<(f64, f64)> {
    let (anchor, target) = masing_closure(st, x1)?;
    // the closing branch's slope there, and the outer one's (a trial at the target pops it)
    let left = curve.slope((target - anchor) / scale);
    let right = masing_trial(curve, scale, st, target).1;
    Some((target, right - left))
}

/// The anchor and the closure point of the branch a Masing joint in `st` moves on toward
/// `x1` (see [`masing_kink`]), when the monotone move to `x1` crosses that closure; `None`
/// otherwise.
#[inline]
pub(super) fn masing_closure(st: &MasingState, x1: f64) -> Option<(f64, f64)> {
    let dx = x1 - st.x;
    if dx == 0.0 {
        return None;
    }
    let s = if dx > 0.0 { 1.0 } else { -1.0 };
    let n = st.stack.len();
    let reversed = st.dir != 0 && s != f64::from(st.dir);
    let (anchor, target) = match (reversed, n) {
        (true, 0) => (st.x, -st.x),
        (true, _) => (st.x, st.stack[n.saturating_sub(1)].x),
        (false, 0) => return None,
        (false, 1) => (st.stack[0].x, -st.stack[0].x),
        (false, _) => (
            st.stack[n.saturating_sub(1)].x,
            st.stack[n.saturating_sub(2)].x,
        ),
    };
    ((x1 - target) * s > 0.0 && (target - st.x) * s > 0.0).then_some((anchor, target))
}

/// Accept the Masing trial at `x` (force `f`, memory update `aux` from [`masing_trial`]): the
/// same rules as `masing::run`.
#[inline(always)]
pub(super) fn masing_commit(st: &mut MasingState, x: f64, f: f64, aux: usize) {
    let dx = x - st.x;
    if dx != 0.0 {
        if aux & 1 == 1 {
            st.stack.push(Reversal {
                x: st.x,
                h: st.h,
                index: st.count.saturating_sub(1),
            });
        }
        st.stack.truncate(aux / 2);
        st.dir = if dx > 0.0 { 1 } else { -1 };
        st.x = x;
        st.h = f;
    }
    st.count = st.count.saturating_add(1);
}

/// `dz/dd` of the Bouc-Wen law for motion in direction `s`.
#[inline]
fn bw_rate(alpha: f64, beta: f64, gamma: f64, delta: f64, nu: f64, z: f64, s: f64) -> f64 {
    if nu == 1.0 {
        alpha - beta * (gamma * s * z + delta * z.abs())
    } else {
        let a = z.abs().powf(nu);
        alpha - beta * (gamma * s * a.copysign(z) + delta * a)
    }
}

/// `z` after a monotone displacement increment `dd` from `z0` for `ν = 1`, in closed form:
/// with `s = sgn dd` and `σ = sgn z`, `dz/dd = α − b z`, `b = β (γ s + δ σ)`, so
/// `z = α/b + (z0 − α/b) e^(−b dd)`; `z` crosses 0 at most once (from 0 it moves with `dd`),
/// where `b` changes.
fn bw_exact(alpha: f64, beta: f64, gamma: f64, delta: f64, z0: f64, dd: f64) -> f64 {
    let s = dd.signum();
    // `z` after `x` along `dd` with the branch of sign `sigma` (linear when `b` is 0)
    let along = |z: f64, sigma: f64, x: f64| -> f64 {
        let b = beta * (gamma * s + delta * sigma);
        if (b * x).abs() < 1e-300 {
            return z + alpha * x;
        }
        // z + (α − b z) (1 − e^(−b x)) / b, with expm1 for small b x
        z + (alpha - b * z) * (-(-b * x).exp_m1() / b)
    };
    let sigma0 = if z0 == 0.0 { s } else { z0.signum() };
    let z1 = along(z0, sigma0, dd);
    if z1 * sigma0 >= 0.0 || z0 == 0.0 {
        return z1;
    }
    // the crossing: 0 = α/b + (z0 − α/b) e^(−b x0)  ⇒  x0 = ln(1 − b z0 / α) / b
    let b = beta * (gamma * s + delta * sigma0);
    let x0 = if b.abs() * dd.abs() < 1e-300 {
        -z0 / alpha
    } else {
        (-b * z0 / alpha).ln_1p() / b
    };
    if !(x0.is_finite() && x0 * s > 0.0 && x0.abs() < dd.abs()) {
        return z1;
    }
    along(0.0, s, dd - x0)
}

/// `z` after a monotone displacement increment `dd` from `z0`: closed form for `ν = 1`
/// ([`bw_exact`]); otherwise classical RK4 in `d`, with enough sub-steps that
/// `|dd| · |∂rate/∂z| ≤ 0.05` per sub-step (local error ~1e-9 relative).
fn bw_advance(p: (f64, f64, f64, f64, f64), z0: f64, dd: f64) -> f64 {
    let (alpha, beta, gamma, delta, nu) = p;
    if dd == 0.0 {
        return z0;
    }
    if nu == 1.0 {
        return bw_exact(alpha, beta, gamma, delta, z0, dd);
    }
    let s = dd.signum();
    let zr = (z0.abs() + alpha * dd.abs()).max(f64::MIN_POSITIVE);
    let lip = beta * (gamma.abs() + delta.abs()) * nu * zr.powf(nu - 1.0).min(1e300);
    let m = ((dd.abs() * lip / 0.05).ceil()).clamp(1.0, 4000.0) as usize;
    let h = dd / m as f64;
    let g = |z: f64| bw_rate(alpha, beta, gamma, delta, nu, z, s);
    let mut z = z0;
    for _ in 0..m {
        let k1 = g(z);
        let k2 = g(z + 0.5 * h * k1);
        let k3 = g(z + 0.5 * h * k2);
        let k4 = g(z + h * k3);
        z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    z
}

impl JointLaw {
    /// Force and tangents at `d_new` (velocity `v_new`), having been at `d_old` in `state`.
    // Inlined into the Newton loops: returned through memory, the `Trial` costs a
    // store-forwarding stall per call that was a sixth of an SDOF step.
    #[inline(always)]
    pub fn trial(&self, state: &JointState, d_old: f64, d_new: f64, v_new: f64) -> Trial {
        let dd = d_new - d_old;
        match (self, state) {
            (Self::Masing { curve, scale }, JointState::Masing(st)) => {
                let (f, kt, aux) = masing_trial(curve, *scale, st, d_new);
                Trial {
                    f,
                    kt,
                    ct: 0.0,
                    aux,
                    v: 0.0,
                }
            }
            (Self::Jenkins { k, fs }, JointState::Slider(f0)) => {
                let ft = f0 + k * dd;
                if ft.abs() > *fs {
                    Trial {
                        f: fs.copysign(ft),
                        ..Trial::default()
                    }
                } else {
                    Trial {
                        f: ft,
                        kt: *k,
                        ..Trial::default()
                    }
                }
            }
            (Self::Iwan { k, fs }, JointState::Sliders(f0)) => {
                let mut out = Trial::default();
                for ((&ki, &fi), &f0i) in k.iter().zip(fs).zip(f0) {
                    let ft = f0i + ki * dd;
                    if ft.abs() > fi {
                        out.f += fi.copysign(ft);
                    } else {
                        out.f += ft;
                        out.kt += ki;
                    }
                }
                out
            }
            (
                Self::BoucWen {
                    alpha,
                    beta,
                    gamma,
                    delta,
                    nu,
                },
                JointState::Slider(z0),
            ) => {
                let p = (*alpha, *beta, *gamma, *delta, *nu);
                let z = bw_advance(p, *z0, dd);
                let s = if dd == 0.0 { 1.0 } else { dd.signum() };
                let kt = bw_rate(*alpha, *beta, *gamma, *delta, *nu, z, s);
                Trial {
                    f: z,
                    kt: kt.max(0.0),
                    ..Trial::default()
                }
            }
            (Self::KelvinVoigt { k, c }, _) => Trial {
                f: k * d_new + c * v_new,
                kt: *k,
                ct: *c,
                aux: 0,
                v: 0.0,
            },
            (Self::Normal { force, slope, .. }, _) => Trial {
                f: poly::eval(force, d_new),
                kt: poly::eval(slope, d_new),
                ..Trial::default()
            },
            (Self::Law { law, rate, .. }, JointState::Law(st)) => {
                let dir = if dd < 0.0 { -1.0 } else { 1.0 };
                let v = rate.then_some(v_new);
                let (f, kt) = law_tangent(law, st, d_old, d_new, dir, v);
                let ct = if *rate {
                    law_damping(law, st, d_old, d_new, v_new, f)
                } else {
                    0.0
                };
                Trial {
                    f,
                    kt,
                    ct,
                    v: v_new,
                    ..Trial::default()
                }
            }
            // A state of another law never reaches here (states are made by `fresh_state`).
            _ => Trial::default(),
        }
    }

    /// Accept the step to `d_new`: update the history.
    #[inline]
    pub fn commit(
        &self,
        state: &mut JointState,
        d_old: f64,
        d_new: f64,
        trial: &Trial,
    ) -> Result<(), CoreError> {
        let dd = d_new - d_old;
        match (self, state) {
            (Self::Masing { .. }, JointState::Masing(st)) => {
                masing_commit(st, d_new, trial.f, trial.aux);
                Ok(())
            }
            (Self::Jenkins { .. } | Self::BoucWen { .. }, JointState::Slider(f)) => {
                *f = trial.f;
                Ok(())
            }
            (Self::Iwan { k, fs }, JointState::Sliders(f0)) => {
                for ((&ki, &fi), f) in k.iter().zip(fs).zip(f0.iter_mut()) {
                    let ft = *f + ki * dd;
                    *f = if ft.abs() > fi { fi.copysign(ft) } else { ft };
                }
                Ok(())
            }
            (Self::Law { law, rate, .. }, JointState::Law(st)) => {
                let _ = law.step(st, law_dt(d_old, d_new, rate.then_some(trial.v)), d_new);
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Recoverable energy held by the joint in `state` at `d` (the dissipated energy is the
    /// work done on the joint minus this). Jenkins/Iwan: `Σ F_i² / (2 k_i)`; Bouc-Wen:
    /// `z² / (2 α)`; Masing: `F² / (2 k_0)` with the initial stiffness `k_0` (exact for every
    /// closed cycle, where F returns to its start); Kelvin-Voigt: `k d² / 2`; normal contact:
    /// `∫_0^d F`.
    #[inline]
    pub fn stored_energy(&self, state: &JointState, d: f64) -> f64 {
        match (self, state) {
            (Self::Masing { curve, .. }, JointState::Masing(st)) => {
                let k0 = match curve {
                    MasingCurve::Exp(c) => c.h0 * c.ac, // f'(0) without an exp per sample
                    MasingCurve::Tab(c) => c.slope(0.0),
                };
                if k0 > 0.0 {
                    0.5 * st.h * st.h / k0
                } else {
                    0.0
                }
            }
            (Self::Jenkins { k, .. }, JointState::Slider(f)) => 0.5 * f * f / k,
            (Self::BoucWen { alpha, .. }, JointState::Slider(z)) => 0.5 * z * z / alpha,
            (Self::Iwan { k, .. }, JointState::Sliders(f)) => {
                k.iter().zip(f).map(|(ki, fi)| 0.5 * fi * fi / ki).sum()
            }
            (Self::KelvinVoigt { k, .. }, _) => 0.5 * k * d * d,
            (Self::Normal { energy, .. }, _) => poly::eval(energy, d),
            // F² / (2 k0) as for Masing (exact for every closed cycle)
            (Self::Law { law, k0, .. }, JointState::Law(st)) if *k0 > 0.0 => {
                let f = law.step(&mut (**st).clone(), None, d);
                0.5 * f * f / k0
            }
            _ => 0.0,
        }
    }

    /// Fraction `θ ∈ (0, 1)` of the step `d_old → d_new` (velocities `v_old → v_new`) at which
    /// the law changes character: a velocity reversal (every hysteretic law) or a stick-slip
    /// transition of a Jenkins/Iwan element (linear in `d` while stuck). `None`: no event.
    #[inline]
    pub fn event(
        &self,
        state: &JointState,
        d_old: f64,
        d_new: f64,
        v_old: f64,
        v_new: f64,
    ) -> Option<f64> {
        let mut theta: Option<f64> = None;
        let mut take = |t: f64| {
            if t > 0.0 && t < 1.0 {
                theta = Some(theta.map_or(t, |a: f64| a.min(t)));
            }
        };
        let hysteretic = !matches!(self, Self::KelvinVoigt { .. } | Self::Normal { .. });
        if hysteretic && v_old * v_new < 0.0 {
            take(v_old / (v_old - v_new));
        }
        let dd = d_new - d_old;
        if dd != 0.0 {
            let mut stick_slip = |k: f64, fs: f64, f0: f64| {
                let ft = f0 + k * dd;
                if f0.abs() < fs && ft.abs() > fs {
                    take((fs.copysign(ft) - f0) / (k * dd));
                }
            };
            match (self, state) {
                (Self::Jenkins { k, fs }, JointState::Slider(f0)) => stick_slip(*k, *fs, *f0),
                (Self::Iwan { k, fs }, JointState::Sliders(f0)) => {
                    for ((&ki, &fi), &f0i) in k.iter().zip(fs).zip(f0) {
                        stick_slip(ki, fi, f0i);
                    }
                }
                _ => {}
            }
        }
        theta
    }
}

/// A joint between `dof` and `dof2` (`None`: the fixed ground); `d = x[dof] − x[dof2]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub law: JointLaw,
    pub dof: usize,
    pub dof2: Option<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::masing;

    fn exp_curve() -> MasingCurve {
        MasingCurve::Exp(Exponential { h0: 40.0, ac: 4e4 })
    }

    #[test]
    fn masing_trial_matches_the_operator_on_a_random_walk() -> Result<(), CoreError> {
        let curve = exp_curve();
        let law = JointLaw::masing(curve.clone(), 2.0)?;
        let mut st = law.fresh_state();
        let mut ref_state = MasingState::default();
        let mut x = 0.0_f64;
        let mut seed = 12345_u64;
        for _ in 0..2000 {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            let r = ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
            let xn = x + 4e-5 * r;
            let tr = law.trial(&st, x, xn, 0.0);
            let mut out = [0.0];
            masing::masing_force(&curve, 2.0, &[xn], &mut out, &mut ref_state)?;
            assert!(
                (tr.f - out[0]).abs() <= 1e-12 * 40.0,
                "{} vs {}",
                tr.f,
                out[0]
            );
            law.commit(&mut st, x, xn, &tr)?;
            if let JointState::Masing(ms) = &st {
                assert_eq!(ms.stack.len(), ref_state.stack.len());
                assert_eq!(ms.dir, ref_state.dir);
            }
            x = xn;
        }
        Ok(())
    }

    #[test]
    fn masing_tangent_is_the_derivative() {
        let curve = exp_curve();
        let law = JointLaw::Masing { curve, scale: 2.0 };
        let mut st = law.fresh_state();
        let path = [3e-5, -1e-5, 2e-5];
        let mut x = 0.0;
        for &xn in &path {
            let tr = law.trial(&st, x, xn, 0.0);
            assert!(law.commit(&mut st, x, xn, &tr).is_ok());
            x = xn;
        }
        // moving down from 2e-5: numerical derivative on the descending branch
        let h = 1e-9;
        let a = law.trial(&st, x, x - 5e-6, 0.0);
        let b = law.trial(&st, x, x - 5e-6 - h, 0.0);
        assert!(((a.f - b.f) / h - a.kt).abs() < 1e-4 * a.kt);
    }

    #[test]
    fn bouc_wen_rk4_matches_the_exact_solution_for_nu_one() {
        // ν = 1, z ≥ 0, s = +1: dz/dd = α − β(γ + δ) z → z = α/b (1 − e^{−b d}).
        let (alpha, beta, gamma, delta) = (5e4, 1e3, 0.8, -0.5);
        let b = beta * (gamma + delta);
        for &d in &[1e-5, 1e-4, 1e-3] {
            let z = bw_advance((alpha, beta, gamma, delta, 1.0), 0.0, d);
            let exact = alpha / b * (1.0 - (-b * d).exp());
            assert!((z - exact).abs() < 1e-6 * exact.abs(), "{z} vs {exact}");
        }
    }

    #[test]
    fn bouc_wen_closed_form_matches_fine_rk4_across_zero() {
        // ν = 1 in closed form against RK4 with ν = 1 + 1e-12 (the RK4 path), many sub-steps
        let (alpha, beta, gamma, delta) = (5e4, 1e3, 0.8, -1.1);
        for &(z0, dd) in &[
            (-20.0, 1e-3),
            (20.0, -1e-3),
            (5.0, 2e-4),
            (-30.0, -1e-4),
            (0.0, 3e-4),
        ] {
            let z = bw_advance((alpha, beta, gamma, delta, 1.0), z0, dd);
            let mut zr = z0;
            let k = 20000;
            for _ in 0..k {
                zr = bw_advance((alpha, beta, gamma, delta, 1.0 + 1e-12), zr, dd / k as f64);
            }
            assert!(
                (z - zr).abs() < 1e-8 * (1.0 + zr.abs()),
                "{z0} {dd}: {z} vs {zr}"
            );
        }
    }

    #[test]
    fn a_quick_trial_holds_on_its_branch_and_regime_only() -> Result<(), CoreError> {
        // Jenkins: both points stuck (or both slipping the same way), not one of each
        let jk = JointLaw::Jenkins { k: 100.0, fs: 1.0 };
        let st = JointState::Slider(0.5);
        assert!(jk.holds(&st, 0.0, 0.004, 0.0045));
        assert!(jk.holds(&st, 0.0, 0.006, 0.007));
        assert!(!jk.holds(&st, 0.0, 0.004, 0.006));
        assert!(!jk.holds(&st, 0.0, 0.006, 0.004));
        // Masing: up to 1e-4, back to -5e-5; moving up again, the branch closes at 1e-4
        let law = JointLaw::masing(exp_curve(), 1.0)?;
        let mut st = law.fresh_state();
        let mut d = 0.0;
        for x in [1e-4, -5e-5] {
            let tr = law.trial(&st, d, x, 0.0);
            law.commit(&mut st, d, x, &tr)?;
            d = x;
        }
        assert!(law.holds(&st, d, 5e-5, 6e-5));
        assert!(!law.holds(&st, d, 1.01e-4, 0.99e-4));
        assert!(!law.holds(&st, d, 0.99e-4, 1.01e-4));
        assert!(law.holds(&st, d, 1.01e-4, 1.02e-4));
        assert!(!law.holds(&st, d, -6e-5, -4e-5));
        // Bouc-Wen: the direction of the move; Kelvin-Voigt: always
        let bw = JointLaw::bouc_wen(5e4, 1e3, 0.8, -1.1, 1.0)?;
        let st = bw.fresh_state();
        assert!(bw.holds(&st, 0.0, 1e-6, 2e-6));
        assert!(!bw.holds(&st, 0.0, 1e-6, -1e-6));
        let kv = JointLaw::kelvin_voigt(1e3, 1.0)?;
        assert!(kv.holds(&JointState::Elastic, 0.0, 1e-6, -1e-6));
        Ok(())
    }

    #[test]
    fn jenkins_event_is_at_the_slip_force() {
        let law = JointLaw::Jenkins { k: 100.0, fs: 1.0 };
        let st = JointState::Slider(0.5);
        let th = law.event(&st, 0.0, 0.01, 1.0, 1.0);
        assert_eq!(th, Some(0.5));
    }
}
