//! [`super::newmark::simulate`] for one degree of freedom: the same Newmark average-acceleration
//! scheme, Newton iteration, event sub-steps, halvings and energy bookkeeping, on scalars.
//!
//! With `n = 1` every joint acts between the DOF and the ground (`d = x`), the "matrices" are
//! numbers and the Newton system is a division, so the dense path's row loops, `n × n`
//! Jacobian and LU disappear. Newton starts from the step of the equation linearised at the
//! start of the step (the dense path starts from the last acceleration): where the joints are
//! nearly linear over a step, one residual evaluation meets the tolerance. Both paths converge
//! to the same tolerance, so they agree to about `rtol` per step (the tests compare them).

use super::joint::{JointState, Trial};
use super::newmark::{Inputs, Options, Response, Status, Structure};
use crate::error::CoreError;

/// The state at the start of a step (`x`, `v`, `a`, load `f`) and the joints' histories.
struct State {
    x: f64,
    v: f64,
    a: f64,
    f: f64,
    joints: Vec<JointState>,
    /// Each joint's force at `x`.
    jf: Vec<f64>,
    jwork: Vec<f64>,
    stored0: Vec<f64>,
    e_in: f64,
    e_damp: f64,
    /// Σ joint forces, `∂/∂d` and `∂/∂ḋ` at the start of the step (Newton's predictor).
    g: f64,
    kt: f64,
    ct: f64,
}

/// A converged step (not yet committed).
struct Step {
    dx: f64,
    x1: f64,
    v1: f64,
    a1: f64,
    f1: f64,
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

/// One Newmark step of length `h` to load `f1`; the joints' trial states in `trials`.
/// Returns the step and the Newton iterations used, or `None` if Newton failed.
#[inline(always)]
fn newton(
    s: &Structure,
    w: &State,
    h: f64,
    f1: f64,
    trials: &mut [Trial],
    opts: &Options,
) -> Option<(Step, u64)> {
    let (m, c, k) = (s.m[0], s.c[0], s.k[0]);
    let (b, g) = (0.25 * h * h, 0.5 * h);
    // Predictor: the step of the equation linearised at its start (joint forces by their
    // tangents there). Where the joints are nearly linear over a step (stuck, or sliding far
    // from a reversal) this already meets the tolerance and Newton ends after one residual.
    let mut a1 = {
        let (kt, ct) = (w.kt, w.ct);
        let rhs = f1
            - c * (w.v + g * w.a)
            - k * (w.x + h * w.v + b * w.a)
            - w.g
            - kt * (h * w.v + b * w.a)
            - ct * (g * w.a);
        let lhs = m + g * c + b * k + b * kt + g * ct;
        let p = rhs / lhs;
        if p.is_finite() {
            p
        } else {
            w.a
        }
    };
    for it in 1..=opts.max_iter as u64 {
        let asum = w.a + a1;
        let dx = h * w.v + b * asum;
        let x1 = w.x + dx;
        let v1 = w.v + g * asum;
        let mut r = -f1;
        r += m * a1 + c * v1 + k * x1;
        let mut scale = f1.abs() + ((m * a1).abs() + (c * v1).abs() + (k * x1).abs());
        let mut jac = m + g * c + b * k;
        if let ([j], [st], [tr]) = (s.joints.as_slice(), w.joints.as_slice(), &mut *trials) {
            // one joint (the common case): no iterator set-up per Newton iteration
            *tr = j.law.trial(st, w.x, x1, v1);
            scale = scale.max(tr.f.abs());
            r += tr.f;
            jac += b * tr.kt + g * tr.ct;
        } else {
            for ((j, st), tr) in s.joints.iter().zip(&w.joints).zip(trials.iter_mut()) {
                *tr = j.law.trial(st, w.x, x1, v1);
                scale = scale.max(tr.f.abs());
                r += tr.f;
            }
            for tr in trials.iter() {
                jac += b * tr.kt + g * tr.ct;
            }
        }
        if !r.is_finite() {
            return None;
        }
        if r.abs() <= opts.rtol * scale.max(f64::MIN_POSITIVE) {
            return Some((Step { dx, x1, v1, a1, f1 }, it));
        }
        if !(jac != 0.0 && jac.is_finite()) {
            return None;
        }
        a1 -= r / jac;
    }
    None
}

/// Commit a converged step, with the energy bookkeeping.
#[inline(always)]
fn accept(s: &Structure, w: &mut State, st: &Step, trials: &[Trial]) -> Result<(), CoreError> {
    let c = s.c[0];
    w.e_in += st.dx * 0.5 * (w.f + st.f1);
    w.e_damp += st.dx * (c * (0.5 * (w.v + st.v1)));
    for (jn, (j, tr)) in s.joints.iter().zip(trials).enumerate() {
        w.jwork[jn] += 0.5 * (w.jf[jn] + tr.f) * (st.x1 - w.x);
        j.law.commit(&mut w.joints[jn], w.x, st.x1, tr)?;
        w.jf[jn] = tr.f;
    }
    w.x = st.x1;
    w.v = st.v1;
    w.g = trials.iter().map(|t| t.f).sum();
    w.kt = trials.iter().map(|t| t.kt).sum();
    w.ct = trials.iter().map(|t| t.ct).sum();
    w.a = st.a1;
    w.f = st.f1;
    Ok(())
}

/// Write the state as sample `i` (`i < len(t)`; the joint arrays are `len(t) × n_joints`).
// Row-major index arithmetic below len(t) · n_joints, checked by the caller.
#[inline(always)]
#[allow(clippy::arithmetic_side_effects)]
fn record(s: &Structure, w: &State, out: &mut Response, i: usize) {
    out.x[i] = w.x;
    out.v[i] = w.v;
    out.a[i] = w.a;
    let nj = s.joints.len();
    for (jn, j) in s.joints.iter().enumerate() {
        let at = i * nj + jn;
        out.joint_force[at] = w.jf[jn];
        out.joint_work[at] = w.jwork[jn];
        out.joint_dissipated[at] =
            w.jwork[jn] - (j.law.stored_energy(&w.joints[jn], w.x) - w.stored0[jn]);
    }
    out.input_work[i] = w.e_in;
    out.damping_work[i] = w.e_damp;
}

/// The one-DOF simulation (inputs already checked by `newmark::simulate`).
pub(super) fn simulate(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: f64,
    v0: f64,
    opts: &Options,
) -> Result<Response, CoreError> {
    let nt = inp.t.len();
    let nj = s.joints.len();
    let total_j = nt.checked_mul(nj).ok_or(CoreError::InvalidParameter {
        name: "t",
        value: nt as f64,
        reason: "too many samples",
    })?;
    let mut joints: Vec<JointState> = s.joints.iter().map(|j| j.law.fresh_state()).collect();
    let mut jf = vec![0.0; nj];
    let mut start_tangents = (0.0, 0.0, 0.0);
    for ((j, st), f) in s.joints.iter().zip(joints.iter_mut()).zip(jf.iter_mut()) {
        let tr = j.law.trial(st, 0.0, x0, v0);
        j.law.commit(st, 0.0, x0, &tr)?;
        *f = tr.f;
        start_tangents.0 += tr.f;
        start_tangents.1 += tr.kt;
        start_tangents.2 += tr.ct;
    }
    let f0 = load(inp, 0, 0.0);
    let stored0: Vec<f64> = s
        .joints
        .iter()
        .zip(&joints)
        .map(|(j, st)| j.law.stored_energy(st, x0))
        .collect();
    // a0 = (f0 − C v0 − K x0 − G0) / M
    let m = s.m[0];
    if !(m != 0.0 && m.is_finite()) {
        return Err(CoreError::InvalidParameter {
            name: "M",
            value: 0.0,
            reason: "mass matrix is singular",
        });
    }
    let mut rhs = f0 - s.c[0] * v0 - s.k[0] * x0;
    for g in &jf {
        rhs -= g;
    }
    let mut w = State {
        x: x0,
        v: v0,
        a: rhs / m,
        f: f0,
        joints,
        jf,
        jwork: vec![0.0; nj],
        stored0,
        e_in: 0.0,
        e_damp: 0.0,
        g: 0.0,
        kt: 0.0,
        ct: 0.0,
    };
    (w.g, w.kt, w.ct) = start_tangents;
    let mut trials = vec![Trial::default(); nj];
    let mut out = Response {
        x: vec![0.0; nt],
        v: vec![0.0; nt],
        a: vec![0.0; nt],
        joint_force: vec![0.0; total_j],
        joint_work: vec![0.0; total_j],
        joint_dissipated: vec![0.0; total_j],
        input_work: vec![0.0; nt],
        damping_work: vec![0.0; nt],
        status: Status::Success,
        n_out: 0,
        n_steps: 0,
        n_iter: 0,
    };
    record(s, &w, &mut out, 0);
    out.n_out = 1;
    for (i, pair) in inp.t.windows(2).enumerate() {
        let big_h = pair[1] - pair[0];
        let mut tau = 0.0_f64;
        let mut halvings = 0usize;
        let mut events = 0usize;
        let mut frac = 1.0_f64;
        while tau < 1.0 {
            let step = frac.min(1.0 - tau);
            let h = step * big_h;
            let tau1 = if step >= 1.0 - tau { 1.0 } else { tau + step };
            let f1 = load(inp, i, tau1);
            let Some((st, it)) = newton(s, &w, h, f1, &mut trials, opts) else {
                halvings = halvings.saturating_add(1);
                if halvings > opts.max_halvings {
                    out.status = Status::NoConvergence {
                        time: inp.t[i] + tau * big_h,
                        step: h,
                    };
                    return Ok(out);
                }
                frac = 0.5 * step;
                continue;
            };
            out.n_iter = out.n_iter.saturating_add(it);
            if events < opts.max_events {
                let mut theta = 1.0_f64;
                for (j, js) in s.joints.iter().zip(&w.joints) {
                    if let Some(th) = j.law.event(js, w.x, st.x1, w.v, st.v1) {
                        theta = theta.min(th);
                    }
                }
                let min_piece = 1e-3 / step;
                if theta > min_piece && theta < 1.0 - min_piece {
                    events = events.saturating_add(1);
                    frac = step * theta;
                    continue;
                }
            }
            accept(s, &mut w, &st, &trials)?;
            out.n_steps = out.n_steps.saturating_add(1);
            tau = tau1;
            frac = (1.0 - tau).max(0.0);
            if !(w.x.is_finite() && w.v.is_finite()) {
                out.status = Status::NonFinite {
                    time: inp.t[i] + tau * big_h,
                };
                return Ok(out);
            }
        }
        let next = i.saturating_add(1); // < nt
        record(s, &w, &mut out, next);
        out.n_out = next.saturating_add(1);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::joint::{Joint, JointLaw, MasingCurve};
    use super::super::newmark::simulate_dense;
    use super::*;
    use crate::curve::{Exponential, Tabulated};
    use proptest::prelude::*;

    fn laws() -> Result<Vec<JointLaw>, CoreError> {
        Ok(vec![
            JointLaw::masing(MasingCurve::Exp(Exponential::new(3.0, 2e3)?), 2.0)?,
            JointLaw::masing(
                MasingCurve::Tab(Tabulated::new(
                    &[0.0, 5e-4, 1e-3, 3e-3],
                    &[0.0, 0.8, 1.2, 1.5],
                )?),
                1.5,
            )?,
            JointLaw::jenkins(300.0, 0.6)?,
            JointLaw::iwan(&[100.0, 150.0, 80.0], &[0.2, 0.5, 0.9])?,
            JointLaw::bouc_wen(400.0, 2e3, 0.8, -0.3, 1.2)?,
            JointLaw::kelvin_voigt(120.0, 0.7)?,
            JointLaw::normal(&[200.0, 1e4])?,
        ])
    }

    /// The scalar path against the dense path on the same structure, input and start.
    fn compare(
        law: &JointLaw,
        two: bool,
        amp: f64,
        base: bool,
        x0: f64,
        v0: f64,
    ) -> Result<(), CoreError> {
        let mut joints = vec![Joint {
            law: law.clone(),
            dof: 0,
            dof2: None,
        }];
        if two {
            joints.push(Joint {
                law: JointLaw::jenkins(90.0, 0.3)?,
                dof: 0,
                dof2: None,
            });
        }
        let s = Structure::new(1, &[0.8], &[1.5], &[900.0], joints)?;
        let nt = 1501;
        let t: Vec<f64> = (0..nt).map(|i| i as f64 * 1e-3).collect();
        let u: Vec<f64> = t
            .iter()
            .map(|ti| {
                amp * ((2.0 * std::f64::consts::PI * 4.0 * ti).sin() + 0.4 * (47.0 * ti).cos())
            })
            .collect();
        let ud: Vec<f64> = t.iter().map(|ti| amp * 8.0 * (8.0 * ti).cos()).collect();
        let (kr, cr) = ([900.0], [1.5]);
        let inp = Inputs {
            t: &t,
            force: if base { None } else { Some(&u) },
            base: if base {
                Some((&u, &ud, &kr, &cr))
            } else {
                None
            },
        };
        let opts = Options::default();
        let a = simulate(&s, &inp, x0, v0, &opts)?;
        let b = simulate_dense(&s, &inp, &[x0], &[v0], &opts, nt, nt * s.joints().len())?;
        assert_eq!(a.status, b.status);
        assert_eq!(a.n_out, b.n_out);
        assert!(
            a.n_steps.abs_diff(b.n_steps) <= 2,
            "{} vs {}",
            a.n_steps,
            b.n_steps
        );
        // the linearised predictor never costs more Newton iterations than the last acceleration
        assert!(
            a.n_iter <= b.n_iter + 4,
            "{} vs {} iterations",
            a.n_iter,
            b.n_iter
        );
        for (name, p, q) in [
            ("x", &a.x, &b.x),
            ("v", &a.v, &b.v),
            ("a", &a.a, &b.a),
            ("joint_force", &a.joint_force, &b.joint_force),
            ("joint_work", &a.joint_work, &b.joint_work),
            ("joint_dissipated", &a.joint_dissipated, &b.joint_dissipated),
            ("input_work", &a.input_work, &b.input_work),
            ("damping_work", &a.damping_work, &b.damping_work),
        ] {
            let size = q.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let diff = p
                .iter()
                .zip(q.iter())
                .fold(0.0_f64, |m, (u, v)| m.max((u - v).abs()));
            // energies that stay at rounding level (a joint that never slips dissipates
            // nothing) are compared with the input work's size
            let floor = if name.ends_with("work") || name.ends_with("dissipated") {
                1e-9 * b.input_work.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
            } else {
                0.0
            };
            assert!(
                diff <= 1e-7 * size + floor + 1e-300,
                "{name} differs by {diff:e} (size {size:e}) for {law:?}"
            );
        }
        Ok(())
    }

    #[test]
    fn scalar_path_agrees_with_the_dense_path_for_every_joint_kind() -> Result<(), CoreError> {
        for law in laws()? {
            compare(&law, false, 1.0, false, 0.0, 0.0)?;
            compare(&law, true, 2.0, false, 1e-3, -0.02)?;
            compare(&law, false, 1e-3, true, 0.0, 0.01)?;
        }
        Ok(())
    }

    #[test]
    fn singular_mass_is_an_error() -> Result<(), CoreError> {
        let s = Structure::new(1, &[0.0], &[1.0], &[1.0], vec![])?;
        let t = [0.0, 1.0];
        let f = [0.0, 1.0];
        let inp = Inputs {
            t: &t,
            force: Some(&f),
            base: None,
        };
        assert!(simulate(&s, &inp, 0.0, 0.0, &Options::default()).is_err());
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn scalar_path_matches_dense_on_random_inputs(
            which in 0usize..7, two in any::<bool>(), amp in 0.01f64..5.0, base in any::<bool>(),
            x0 in -2e-3f64..2e-3, v0 in -0.05f64..0.05,
        ) {
            let law = laws().map_err(|e| TestCaseError::fail(e.to_string()))?.swap_remove(which);
            compare(&law, two, if base { amp * 1e-3 } else { amp }, base, x0, v0)
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
        }
    }
}
