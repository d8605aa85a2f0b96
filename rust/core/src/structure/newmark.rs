//! Implicit Newmark time integration (average acceleration: β = 1/4, γ = 1/2) of
//! `M x'' + C x' + K x + Σ F_j(d_j, ḋ_j, history) = f(t) + K r y(t) + C r ẏ(t)`
//! with Newton iterations on the joint forces (each joint's tangent stiffness and damping),
//! steps split at joint events (velocity reversals, stick-slip transitions), and outputs at
//! exactly the sample times.
//!
//! `y` is a prescribed ground (base) displacement, `ẏ` its velocity, and `K r`, `C r` the
//! coupling vectors (`r` the influence vector: ones for a structure on one moving base).
//! Joints to the ground attach to the fixed ground, not to the moving base.
//!
//! Energy bookkeeping is the scheme's own (trapezoidal) balance, exact for every accepted
//! step: input work `Σ Δxᵀ f̄` = kinetic + `½ xᵀ K x` + viscous `Σ Δxᵀ C v̄` + joint work
//! `Σ F̄_j Δd_j`, where a bar is the mean over the step.

use super::dense::Lu;
use super::joint::{Joint, JointState, Trial};
use super::{Buffers, Inputs, Options, Status, Structure, Summary};
use crate::error::CoreError;

mod adaptive;

/// The integrator's per-step state.
struct Work {
    x: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    f: Vec<f64>,
    states: Vec<JointState>,
    jf: Vec<f64>,
    jd: Vec<f64>,
    jv: Vec<f64>,
    jwork: Vec<f64>,
    /// Stored energy of each joint at the start (dissipation counts from there).
    stored0: Vec<f64>,
    e_in: f64,
    e_damp: f64,
}

fn rel(j: &Joint, x: &[f64]) -> f64 {
    x[j.dof] - j.dof2.map_or(0.0, |k| x[k])
}

/// Total external load at fraction `tau` of interval `i → i+1` (linear interpolation).
// Row-major index arithmetic: indices < n (dofs), nj (joints) or the sample count, into
// buffers whose sizes n*n, nt*n and nt*nj were checked in `Structure::new` and `simulate`.
#[allow(clippy::arithmetic_side_effects)]
fn load(s: &Structure, inp: &Inputs<'_>, i: usize, tau: f64, out: &mut [f64]) {
    let n = s.n;
    out.fill(0.0);
    let last = inp.t.len() - 1;
    let i1 = (i + 1).min(last);
    let w0 = if i1 == i { 1.0 } else { 1.0 - tau };
    let w1 = 1.0 - w0;
    if let Some(f) = inp.force {
        for (d, o) in out.iter_mut().enumerate() {
            *o += w0 * f[i * n + d] + w1 * f[i1 * n + d];
        }
    }
    if let Some((y, yd, kr, cr)) = inp.base {
        let yy = w0 * y[i] + w1 * y[i1];
        let yv = w0 * yd[i] + w1 * yd[i1];
        for (d, o) in out.iter_mut().enumerate() {
            *o += kr[d] * yy + cr[d] * yv;
        }
    }
}

// Row-major index arithmetic: indices < n (dofs), nj (joints) or the sample count, into
// buffers whose sizes n*n, nt*n and nt*nj were checked in `Structure::new` and `simulate`.
#[allow(clippy::arithmetic_side_effects)]
fn matvec(a: &[f64], x: &[f64], n: usize, out: &mut [f64]) {
    for (r, o) in out.iter_mut().enumerate().take(n) {
        *o = a[r * n..(r + 1) * n]
            .iter()
            .zip(x)
            .map(|(p, q)| p * q)
            .sum();
    }
}

/// Scratch space for one Newton step (allocated once per run).
struct Scratch {
    dx: Vec<f64>,
    x1: Vec<f64>,
    v1: Vec<f64>,
    a1: Vec<f64>,
    f1: Vec<f64>,
    r: Vec<f64>,
    tmp: Vec<f64>,
    jac: Vec<f64>,
    trials: Vec<Trial>,
    lu: Lu,
}

/// One Newmark step of length `h` from `w` to load `f1` (in `sc.f1`); on success the new
/// state is in `sc.x1/v1/a1/trials` (not yet committed). Returns the Newton iterations used,
/// or `None` if Newton failed.
// Row-major index arithmetic: indices < n (dofs), nj (joints) or the sample count, into
// buffers whose sizes n*n, nt*n and nt*nj were checked in `Structure::new` and `simulate`.
#[allow(clippy::arithmetic_side_effects)]
///
/// `quick` (0: never): a residual below this fraction of the forces ends the solve after its
/// update without another trial, the joints' forces carried along their tangents (a
/// step-doubling pair's inner solves, whose trials are never committed; see `sdof::newton`).
fn newton_step(
    s: &Structure,
    w: &Work,
    (h, quick, guessed): (f64, f64, bool),
    sc: &mut Scratch,
    opts: &Options,
) -> Option<u64> {
    let n = s.n;
    let (b, g) = (0.25 * h * h, 0.5 * h);
    // The unknown is the new acceleration: x1 and v1 follow from it without the cancellation
    // of the displacement form (4/h² Δx − 4/h v), which loses all accuracy on short sub-steps.
    // (`guessed`: the caller put a better start in `sc.a1`)
    if !guessed {
        sc.a1.copy_from_slice(&w.a);
    }
    for it in 1..=opts.max_iter as u64 {
        for d in 0..n {
            let asum = w.a[d] + sc.a1[d];
            sc.dx[d] = h * w.v[d] + b * asum;
            sc.x1[d] = w.x[d] + sc.dx[d];
            sc.v1[d] = w.v[d] + g * asum;
        }
        // residual R = M a + C v + K x + G − f, and its size: the sum of the magnitudes of
        // every term (rounding in any of them shows up at eps times this)
        let mut scale = 0.0_f64;
        for d in 0..n {
            sc.r[d] = -sc.f1[d];
            let mut mag = sc.f1[d].abs();
            for e in 0..n {
                let (m, c, k) = (s.m[d * n + e], s.c[d * n + e], s.k[d * n + e]);
                sc.r[d] += m * sc.a1[e] + c * sc.v1[e] + k * sc.x1[e];
                mag += (m * sc.a1[e]).abs() + (c * sc.v1[e]).abs() + (k * sc.x1[e]).abs();
            }
            scale = scale.max(mag);
        }
        for (jn, (j, st)) in s.joints.iter().zip(&w.states).enumerate() {
            let t = j.law.trial(st, w.jd[jn], rel(j, &sc.x1), rel(j, &sc.v1));
            sc.trials[jn] = t;
            scale = scale.max(t.f.abs());
            sc.r[j.dof] += t.f;
            if let Some(k) = j.dof2 {
                sc.r[k] -= t.f;
            }
        }
        let rn = sc.r.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !rn.is_finite() {
            return None;
        }
        if rn <= opts.rtol * scale.max(f64::MIN_POSITIVE) {
            return Some(it);
        }
        // ∂R/∂a1 = M + (h/2) C + (h²/4) K + joint tangents
        for ((jv, &m), (&c, &k)) in sc.jac.iter_mut().zip(&s.m).zip(s.c.iter().zip(&s.k)) {
            *jv = m + g * c + b * k;
        }
        for (j, t) in s.joints.iter().zip(&sc.trials) {
            let gj = b * t.kt + g * t.ct;
            let (p, q) = (j.dof, j.dof2);
            sc.jac[p * n + p] += gj;
            if let Some(q) = q {
                sc.jac[q * n + q] += gj;
                sc.jac[p * n + q] -= gj;
                sc.jac[q * n + p] -= gj;
            }
        }
        if sc.lu.factor(&sc.jac, n).is_err() {
            return None;
        }
        sc.tmp.copy_from_slice(&sc.r);
        sc.lu.solve(&mut sc.tmp);
        for d in 0..n {
            sc.a1[d] -= sc.tmp[d];
        }
        if rn <= quick * scale {
            for d in 0..n {
                let asum = w.a[d] + sc.a1[d];
                sc.dx[d] = h * w.v[d] + b * asum;
                sc.x1[d] = w.x[d] + sc.dx[d];
                sc.v1[d] = w.v[d] + g * asum;
            }
            for (jn, (j, t)) in s.joints.iter().zip(sc.trials.iter_mut()).enumerate() {
                // the end moved by −b δa in x and −g δa in v since the trial (a joint whose
                // trial does not hold there, see `JointLaw::holds`, is tried anew)
                let (dd, dv) = (-b * rel(j, &sc.tmp), -g * rel(j, &sc.tmp));
                let (st, d0, d1) = (&w.states[jn], w.jd[jn], rel(j, &sc.x1));
                if j.law.holds(st, d0, d1 - dd, d1) {
                    t.f += t.kt * dd + t.ct * dv;
                } else {
                    *t = j.law.trial(st, d0, d1, rel(j, &sc.v1));
                }
            }
            return Some(it);
        }
    }
    None
}

/// The dense path alone, allocating its output (the tests compare the one-DOF path with it).
#[cfg(test)]
pub(super) fn simulate_dense_response(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: &[f64],
    v0: &[f64],
    opts: &Options,
) -> Result<super::Response, CoreError> {
    let nt = inp.t.len();
    let (total, total_j) = super::sizes(s, nt)?;
    let mut out = super::Response::zeros(nt, total, total_j);
    let sum = simulate_dense(s, inp, x0, v0, opts, &mut out.buffers())?;
    out.set(sum);
    Ok(out)
}

/// The n-DOF path of [`simulate_into`] (inputs and buffer sizes already checked).
pub(super) fn simulate_dense(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: &[f64],
    v0: &[f64],
    opts: &Options,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    let n = s.n;
    let nj = s.joints.len();
    let mut states: Vec<JointState> = s.joints.iter().map(|j| j.law.fresh_state()).collect();
    let mut jf = vec![0.0; nj];
    let mut jd = vec![0.0; nj];
    let mut jv = vec![0.0; nj];
    for (jn, j) in s.joints.iter().enumerate() {
        let d0 = rel(j, x0);
        let tr = j.law.trial(&states[jn], 0.0, d0, rel(j, v0));
        j.law.commit(&mut states[jn], 0.0, d0, &tr)?;
        jf[jn] = tr.f;
        jd[jn] = d0;
        jv[jn] = rel(j, v0);
    }
    let mut w = Work {
        x: x0.to_vec(),
        v: v0.to_vec(),
        a: vec![0.0; n],
        f: vec![0.0; n],
        states,
        jf,
        jd,
        jv,
        jwork: vec![0.0; nj],
        stored0: vec![0.0; nj],
        e_in: 0.0,
        e_damp: 0.0,
    };
    let mut sc = Scratch {
        dx: vec![0.0; n],
        x1: vec![0.0; n],
        v1: vec![0.0; n],
        a1: vec![0.0; n],
        f1: vec![0.0; n],
        r: vec![0.0; n],
        tmp: vec![0.0; n],
        jac: vec![0.0; n.saturating_mul(n)], // n * n checked in Structure::new
        trials: vec![Trial::default(); nj],
        lu: Lu::new(n),
    };
    // a0 = M⁻¹ (f0 − C v0 − K x0 − G0)
    load(s, inp, 0, 0.0, &mut w.f);
    for (jn, j) in s.joints.iter().enumerate() {
        w.stored0[jn] = j.law.stored_energy(&w.states[jn], w.jd[jn]);
    }
    let mut rhs = w.f.clone();
    for (mat, vec) in [(&s.c, &w.v), (&s.k, &w.x)] {
        matvec(mat, vec, n, &mut sc.tmp);
        for (r, t) in rhs.iter_mut().zip(&sc.tmp) {
            *r -= t;
        }
    }
    for (jn, j) in s.joints.iter().enumerate() {
        let g = w.jf[jn];
        rhs[j.dof] -= g;
        if let Some(k) = j.dof2 {
            rhs[k] += g;
        }
    }
    sc.lu
        .factor(&s.m, n)
        .map_err(|_| CoreError::InvalidParameter {
            name: "M",
            value: 0.0,
            reason: "mass matrix is singular",
        })?;
    sc.lu.solve(&mut rhs);
    w.a.copy_from_slice(&rhs);

    let mut sum = Summary::new();
    record(s, &w, out, 0);
    sum.n_out = 1;
    if let Some(tol) = opts.tol {
        let rate = super::stiff_rate(s);
        return adaptive::run(s, inp, (tol, rate), opts, w, sc, sum, out);
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
        let mut frac = piece; // fraction of the interval to try next
        while tau < 1.0 {
            let step = frac.min(1.0 - tau);
            let h = step * big_h;
            let tau1 = if step >= 1.0 - tau { 1.0 } else { tau + step };
            load(s, inp, i, tau1, &mut sc.f1);
            match newton_step(s, &w, (h, 0.0, false), &mut sc, opts) {
                None => {
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
                }
                Some(it) => sum.n_iter = sum.n_iter.saturating_add(it),
            }
            // Split the step at the earliest joint event strictly inside it.
            if events < max_events {
                let mut theta = 1.0_f64;
                for (jn, j) in s.joints.iter().enumerate() {
                    let d1 = rel(j, &sc.x1);
                    let v1 = rel(j, &sc.v1);
                    if let Some(th) = j.law.event(&w.states[jn], w.jd[jn], d1, w.jv[jn], v1) {
                        theta = theta.min(th);
                    }
                }
                let min_piece = 1e-3 * piece / step;
                if theta > min_piece && theta < 1.0 - min_piece {
                    events = events.saturating_add(1);
                    frac = step * theta;
                    continue;
                }
            }
            accept(s, &mut w, &mut sc)?;
            sum.n_steps = sum.n_steps.saturating_add(1);
            tau = tau1;
            // on to the next point of the fixed grid (events split between them)
            frac = ((tau * k_sub + 1e-9).floor() + 1.0) / k_sub - tau;
            frac = frac.min(1.0 - tau).max(0.0);
            if w.x.iter().chain(&w.v).any(|v| !v.is_finite()) {
                sum.status = Status::NonFinite {
                    time: inp.t[i] + tau * big_h,
                };
                return Ok(sum);
            }
        }
        let next = i.saturating_add(1); // < nt
        record(s, &w, out, next);
        sum.n_out = next.saturating_add(1);
    }
    Ok(sum)
}

/// Commit the converged step in `sc` to `w`, with the energy bookkeeping.
// Row-major index arithmetic: indices < n (dofs), nj (joints) or the sample count, into
// buffers whose sizes n*n, nt*n and nt*nj were checked in `Structure::new` and `simulate`.
#[allow(clippy::arithmetic_side_effects)]
fn accept(s: &Structure, w: &mut Work, sc: &mut Scratch) -> Result<(), CoreError> {
    let n = s.n;
    // Δxᵀ f̄ and Δxᵀ C v̄ (Δx = h v̄ for Newmark average acceleration).
    let mut e_in = 0.0;
    let mut e_d = 0.0;
    for d in 0..n {
        sc.tmp[d] = 0.5 * (w.v[d] + sc.v1[d]);
    }
    for d in 0..n {
        let dx = sc.dx[d];
        e_in += dx * 0.5 * (w.f[d] + sc.f1[d]);
        let cvd: f64 = s.c[d * n..(d + 1) * n]
            .iter()
            .zip(&sc.tmp)
            .map(|(p, q)| p * q)
            .sum();
        e_d += dx * cvd;
    }
    w.e_in += e_in;
    w.e_damp += e_d;
    for (jn, j) in s.joints.iter().enumerate() {
        let d1 = rel(j, &sc.x1);
        let tr = sc.trials[jn];
        w.jwork[jn] += 0.5 * (w.jf[jn] + tr.f) * (d1 - w.jd[jn]);
        j.law.commit(&mut w.states[jn], w.jd[jn], d1, &tr)?;
        w.jf[jn] = tr.f;
        w.jd[jn] = d1;
        w.jv[jn] = rel(j, &sc.v1);
    }
    w.x.copy_from_slice(&sc.x1);
    w.v.copy_from_slice(&sc.v1);
    w.a.copy_from_slice(&sc.a1);
    w.f.copy_from_slice(&sc.f1);
    Ok(())
}

// Row-major index arithmetic: indices < n (dofs), nj (joints) or the sample count, into
// buffers whose sizes n*n, nt*n and nt*nj were checked in `Structure::new` and `simulate`.
#[allow(clippy::arithmetic_side_effects)]
fn record(s: &Structure, w: &Work, out: &mut Buffers<'_>, i: usize) {
    let n = s.n;
    let nj = s.joints.len();
    // (an empty buffer: an output not wanted)
    for (buf, val) in [
        (&mut *out.x, &w.x),
        (&mut *out.v, &w.v),
        (&mut *out.a, &w.a),
    ] {
        if let Some(row) = buf.get_mut(i * n..(i + 1) * n) {
            row.copy_from_slice(val);
        }
    }
    for (jn, j) in s.joints.iter().enumerate() {
        let at = i * nj + jn;
        if let Some(f) = out.joint_force.get_mut(at) {
            *f = w.jf[jn];
        }
        if let Some(f) = out.joint_work.get_mut(at) {
            *f = w.jwork[jn];
        }
        if let Some(d) = out.joint_dissipated.get_mut(at) {
            *d = w.jwork[jn] - (j.law.stored_energy(&w.states[jn], w.jd[jn]) - w.stored0[jn]);
        }
    }
    if let Some(e) = out.input_work.get_mut(i) {
        *e = w.e_in;
    }
    if let Some(e) = out.damping_work.get_mut(i) {
        *e = w.e_damp;
    }
}

#[cfg(test)]
mod tests {
    use super::super::joint::JointLaw;
    use super::super::simulate;
    use super::*;

    fn sdof(m: f64, c: f64, k: f64, joints: Vec<Joint>) -> Result<Structure, CoreError> {
        Structure::new(1, &[m], &[c], &[k], joints)
    }

    #[test]
    fn linear_free_vibration_matches_the_closed_form() -> Result<(), CoreError> {
        let s = sdof(2.0, 4.0, 800.0, vec![])?;
        let t: Vec<f64> = (0..4001).map(|i| i as f64 * 5e-4).collect();
        let inp = Inputs {
            t: &t,
            force: None,
            base: None,
        };
        let r = simulate(&s, &inp, &[1e-3], &[0.0], &Options::default())?;
        assert_eq!(r.status, Status::Success);
        let (wn, z) = (20.0_f64, 0.05_f64);
        let wd = wn * (1.0 - z * z).sqrt();
        for (ti, xi) in t.iter().zip(&r.x) {
            let xe =
                1e-3 * (-z * wn * ti).exp() * ((wd * ti).cos() + z * wn / wd * (wd * ti).sin());
            assert!((xi - xe).abs() < 1e-7, "t={ti}: {xi} vs {xe}");
        }
        Ok(())
    }

    #[test]
    fn jenkins_forced_run_converges_and_balances_energy() -> Result<(), CoreError> {
        let j = Joint {
            law: JointLaw::jenkins(200.0, 1.0)?,
            dof: 0,
            dof2: None,
        };
        let s = sdof(2.0, 4.0, 800.0, vec![j])?;
        let t: Vec<f64> = (0..2001).map(|i| i as f64 * 1e-3).collect();
        let f: Vec<f64> = t
            .iter()
            .map(|ti| 5.0 * (2.0 * std::f64::consts::PI * 3.0 * ti).sin())
            .collect();
        let inp = Inputs {
            t: &t,
            force: Some(&f),
            base: None,
        };
        let r = simulate(&s, &inp, &[0.0], &[0.0], &Options::default())?;
        assert_eq!(r.status, Status::Success, "{}", r.status.message());
        let last = t.len() - 1;
        let ke = 0.5 * 2.0 * r.v[last] * r.v[last];
        let se = 0.5 * 800.0 * r.x[last] * r.x[last];
        let bal = r.input_work[last] - ke - se - r.damping_work[last] - r.joint_work[last];
        assert!(
            bal.abs() < 1e-9 * r.input_work[last].abs(),
            "{bal} {} {} {} {} {} {}",
            r.input_work[last],
            ke,
            se,
            r.damping_work[last],
            r.joint_work[last],
            r.n_steps
        );
        Ok(())
    }
}
