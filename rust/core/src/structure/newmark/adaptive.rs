//! Error-controlled stepping for n DOFs: step doubling with Richardson extrapolation, as in
//! the one-DOF path (`sdof::adaptive`, whose notes hold for this one): each piece is one
//! Newmark step and two half steps (the second from the midpoint, the joints tried from their
//! committed state), the kept state is the extrapolation `(4 y_{h/2} − y_h) / 3` with its
//! acceleration in equilibrium (`M⁻¹` of the residual forces), the joints' work and the
//! energies are extrapolated alike, and the piece length follows the estimate `|y_{h/2} − y_h|
//! / 3` relative to the largest displacement and velocity so far.

use super::super::dense::Lu;
use super::super::joint::JointLaw;
use super::super::{Buffers, Inputs, Options, Status, Structure, Summary};
use super::{load, matvec, newton_step, record, rel, Scratch, Work};
use crate::error::CoreError;

mod hermite;

/// Hermite pieces while `h ×` the fastest rate is at most this (as the one-DOF path).
const HERMITE_RATE: f64 = 1.0;

/// The factor on the piece length after a Hermite piece's estimate (as the one-DOF path's).
#[inline]
fn grow4(tol: f64, err: f64) -> f64 {
    if err * 391.0 <= tol {
        4.0
    } else {
        (0.9 * (tol / err).sqrt().sqrt()).clamp(0.2, 4.0)
    }
}

/// The pair's states (coarse end, midpoint, fine end), the extrapolated acceleration's
/// factors of `M`, and each joint's forces at the three points.
struct Pair {
    xc: Vec<f64>,
    vc: Vec<f64>,
    xm: Vec<f64>,
    vm: Vec<f64>,
    am: Vec<f64>,
    fm: Vec<f64>,
    xf: Vec<f64>,
    vf: Vec<f64>,
    f1: Vec<f64>,
    /// The committed state while the second half step runs from the midpoint.
    x0: Vec<f64>,
    v0: Vec<f64>,
    a0: Vec<f64>,
    kept: Vec<[f64; 3]>,
    m_lu: Lu,
    /// The extrapolation weight of the last piece (1/3; 0: the plain half steps kept).
    ext: f64,
}

impl Pair {
    fn new(s: &Structure) -> Result<Self, CoreError> {
        let n = s.n;
        let z = || vec![0.0; n];
        let mut m_lu = Lu::new(n);
        m_lu.factor(&s.m, n)
            .map_err(|_| CoreError::InvalidParameter {
                name: "M",
                value: 0.0,
                reason: "mass matrix is singular",
            })?;
        Ok(Self {
            xc: z(),
            vc: z(),
            xm: z(),
            vm: z(),
            am: z(),
            fm: z(),
            xf: z(),
            vf: z(),
            f1: z(),
            x0: z(),
            v0: z(),
            a0: z(),
            kept: vec![[0.0; 3]; s.joints.len()],
            m_lu,
            ext: 1.0 / 3.0,
        })
    }

    fn keep(&mut self, sc: &Scratch, slot: usize) {
        for (k, tr) in self.kept.iter_mut().zip(&sc.trials) {
            if let Some(v) = k.get_mut(slot) {
                *v = tr.f;
            }
        }
    }
}

/// Step doubling over `[tau, tau1]` (length `h`) of interval `i`: on success the extrapolated
/// state is in `sc.x1/v1/a1/f1/trials` and `(error estimate, event fraction (1: none),
/// Newton iterations)` is returned; `None` if Newton failed.
// The piece's context (structure, state, input, span, scales, options) as it is.
#[allow(clippy::too_many_arguments)]
fn piece(
    s: &Structure,
    w: &mut Work,
    sc: &mut Scratch,
    p: &mut Pair,
    inp: &Inputs<'_>,
    i: usize,
    (tau, tau1, h): (f64, f64, f64),
    (scale, ext): ((f64, f64), f64),
    opts: &Options,
) -> Option<(f64, f64, u64)> {
    p.ext = ext;
    load(s, inp, i, tau1, &mut p.f1);
    load(s, inp, i, 0.5 * (tau + tau1), &mut p.fm);
    sc.f1.copy_from_slice(&p.f1);
    // quick ends of the inner solves where every tangent is exact (as the one-DOF path)
    let exact = !s
        .joints
        .iter()
        .any(|j| matches!(j.law, JointLaw::Law { .. }));
    // (at most √rtol: the residual left is then of the order of rtol, as the one-DOF path)
    let quick = if exact {
        opts.rtol.sqrt().min(1e-3)
    } else {
        0.0
    };
    let i1 = newton_step(s, w, (h, quick, false), sc, opts)?;
    p.xc.copy_from_slice(&sc.x1);
    p.vc.copy_from_slice(&sc.v1);
    p.keep(sc, 0);
    sc.f1.copy_from_slice(&p.fm);
    let i2 = newton_step(s, w, (0.5 * h, quick, false), sc, opts)?;
    p.xm.copy_from_slice(&sc.x1);
    p.vm.copy_from_slice(&sc.v1);
    p.am.copy_from_slice(&sc.a1);
    p.keep(sc, 1);
    // the second half from the midpoint; the joints stay at their committed state
    p.x0.copy_from_slice(&w.x);
    p.v0.copy_from_slice(&w.v);
    p.a0.copy_from_slice(&w.a);
    w.x.copy_from_slice(&p.xm);
    w.v.copy_from_slice(&p.vm);
    w.a.copy_from_slice(&p.am);
    sc.f1.copy_from_slice(&p.f1);
    let i3 = newton_step(s, w, (0.5 * h, quick, false), sc, opts);
    w.x.copy_from_slice(&p.x0);
    w.v.copy_from_slice(&p.v0);
    w.a.copy_from_slice(&p.a0);
    let i3 = i3?;
    p.xf.copy_from_slice(&sc.x1);
    p.vf.copy_from_slice(&sc.v1);
    p.keep(sc, 2);
    // events: each joint's own from the committed start to the fine end, and a reversal of
    // its relative velocity in either half of the fine path
    let mut theta = 1.0_f64;
    for (jn, j) in s.joints.iter().enumerate() {
        let (vm, vf) = (rel(j, &p.vm), rel(j, &p.vf));
        if let Some(th) = j
            .law
            .event(&w.states[jn], w.jd[jn], rel(j, &p.xf), w.jv[jn], vf)
        {
            theta = theta.min(th);
        }
        let v0 = w.jv[jn];
        if v0 * vm < 0.0 {
            theta = theta.min(0.5 * v0 / (v0 - vm));
        } else if vm * vf < 0.0 {
            theta = theta.min(0.5 + 0.5 * vm / (vm - vf));
        }
    }
    // extrapolate; the error estimate relative to the sizes so far
    let (mut ex, mut ev, mut sx, mut sv) = (0.0_f64, 0.0_f64, scale.0, scale.1);
    for d in 0..s.n {
        let (xf, xc, vf, vc) = (p.xf[d], p.xc[d], p.vf[d], p.vc[d]);
        ex = ex.max((xf - xc).abs() / 3.0);
        ev = ev.max((vf - vc).abs() / 3.0);
        sx = sx.max(xf.abs()).max(xc.abs());
        sv = sv.max(vf.abs()).max(vc.abs());
        sc.x1[d] = xf + (xf - xc) * ext;
        sc.v1[d] = vf + (vf - vc) * ext;
        sc.dx[d] = sc.x1[d] - w.x[d];
    }
    let rel_err = |e: f64, sz: f64| if e == 0.0 { 0.0 } else { e / sz };
    let err = rel_err(ex, sx).max(rel_err(ev, sv));
    // the joints at the extrapolated point from their committed state; a = M⁻¹ (f − C v − K x − G)
    sc.f1.copy_from_slice(&p.f1);
    sc.r.copy_from_slice(&p.f1);
    for (mat, vec) in [(&s.c, &sc.v1), (&s.k, &sc.x1)] {
        matvec(mat, vec, s.n, &mut sc.tmp);
        for (r, t) in sc.r.iter_mut().zip(&sc.tmp) {
            *r -= t;
        }
    }
    for (jn, (j, st)) in s.joints.iter().zip(&w.states).enumerate() {
        let t = j.law.trial(st, w.jd[jn], rel(j, &sc.x1), rel(j, &sc.v1));
        sc.trials[jn] = t;
        sc.r[j.dof] -= t.f;
        if let Some(k) = j.dof2 {
            sc.r[k] += t.f;
        }
    }
    p.m_lu.solve(&mut sc.r);
    sc.a1.copy_from_slice(&sc.r);
    let err = if err.is_nan() { f64::INFINITY } else { err };
    Some((err, theta, i1.saturating_add(i2).saturating_add(i3)))
}

/// Commit the extrapolated piece: state, joints (work extrapolated), energies (Romberg on the
/// pair's trapezoidal sums).
// Row-major index arithmetic: rows d < n of the n × n C checked in `Structure::new`.
#[allow(clippy::arithmetic_side_effects)]
fn accept(s: &Structure, w: &mut Work, sc: &Scratch, p: &Pair) -> Result<(), CoreError> {
    let n = s.n;
    let rich = |coarse: f64, fine: f64| fine + (fine - coarse) * p.ext;
    let (mut in_c, mut in_f, mut d_c, mut d_f) = (0.0, 0.0, 0.0, 0.0);
    for d in 0..n {
        let x0 = w.x[d];
        let (dc, d1, d2) = (p.xc[d] - x0, p.xm[d] - x0, p.xf[d] - p.xm[d]);
        in_c += dc * 0.5 * (w.f[d] + p.f1[d]);
        in_f += d1 * 0.5 * (w.f[d] + p.fm[d]) + d2 * 0.5 * (p.fm[d] + p.f1[d]);
        let row = d * n..(d + 1) * n;
        let cv = |a: &[f64], b: &[f64]| -> f64 {
            s.c[row.clone()]
                .iter()
                .zip(a.iter().zip(b))
                .map(|(c, (u, v))| c * 0.5 * (u + v))
                .sum()
        };
        d_c += dc * cv(&w.v, &p.vc);
        d_f += d1 * cv(&w.v, &p.vm) + d2 * cv(&p.vm, &p.vf);
    }
    w.e_in += rich(in_c, in_f);
    w.e_damp += rich(d_c, d_f);
    for (jn, j) in s.joints.iter().enumerate() {
        let d0 = w.jd[jn];
        let (dc, dm, df) = (rel(j, &p.xc), rel(j, &p.xm), rel(j, &p.xf));
        let (f0, k) = (w.jf[jn], p.kept[jn]);
        let coarse = 0.5 * (f0 + k[0]) * (dc - d0);
        let fine = 0.5 * (f0 + k[1]) * (dm - d0) + 0.5 * (k[1] + k[2]) * (df - dm);
        let d1 = rel(j, &sc.x1);
        let tr = sc.trials[jn];
        w.jwork[jn] += rich(coarse, fine);
        j.law.commit(&mut w.states[jn], d0, d1, &tr)?;
        w.jf[jn] = tr.f;
        w.jd[jn] = d1;
        w.jv[jn] = rel(j, &sc.v1);
    }
    w.x.copy_from_slice(&sc.x1);
    w.v.copy_from_slice(&sc.v1);
    w.a.copy_from_slice(&sc.a1);
    w.f.copy_from_slice(&p.f1);
    Ok(())
}

/// The piece length (a fraction of the interval, whose length is `big_h`) to try from `tau`:
/// `want` (in seconds), or the rest of the interval cut into equal pieces no longer than it.
fn next_frac(tau: f64, want: f64, big_h: f64) -> f64 {
    // (compared in seconds: no division where the rest is taken whole, the common case)
    let rest = (1.0 - tau).max(0.0);
    if want >= rest * big_h {
        return rest;
    }
    rest / (rest * big_h / want).ceil().max(1.0)
}

/// The error-controlled loop of the n-DOF path (state `w` at `t[0]`, already recorded).
// The run's context, handed on from the fixed-step front as it is.
#[allow(clippy::too_many_arguments)]
pub(super) fn run(
    s: &Structure,
    inp: &Inputs<'_>,
    (tol, rate): (f64, f64),
    opts: &Options,
    mut w: Work,
    mut sc: Scratch,
    mut sum: Summary,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    let mut p = Pair::new(s)?;
    let mut hm = hermite::Herm::new(s, &w)?;
    let herm_ok = hermite::allowed(s);
    let amax = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let mut scale = (amax(&w.x), amax(&w.v));
    let mut want = f64::INFINITY;
    let min_frac = 1.0 / 64.0; // as the one-DOF path's `MIN_FRAC`
    let mut rejected = f64::NAN; // as there
    for (i, pair) in inp.t.windows(2).enumerate() {
        let big_h = pair[1] - pair[0];
        let (mut tau, mut halvings, mut events) = (0.0_f64, 0usize, 0usize);
        let mut frac = next_frac(tau, want, big_h);
        let mut shortened = false;
        if herm_ok {
            hm.interval(s, inp, i, big_h);
        }
        while tau < 1.0 {
            let step = frac.min(1.0 - tau);
            let h = step * big_h;
            let tau1 = if step >= 1.0 - tau { 1.0 } else { tau + step };
            let span = (tau, tau1, h);
            if herm_ok && h * rate <= HERMITE_RATE {
                let got = hermite::piece(
                    s,
                    &w,
                    &mut sc,
                    &mut hm,
                    inp,
                    i,
                    (tau1, h, step),
                    scale,
                    opts,
                );
                let Some((err, theta, it)) = got else {
                    halvings = halvings.saturating_add(1);
                    if halvings > opts.max_halvings.saturating_mul(4) {
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
                if events < opts.max_events && theta < 1.0 {
                    let min_piece = 1e-3 / step;
                    if theta > min_piece && theta < 1.0 - min_piece {
                        events = events.saturating_add(1);
                        frac = step * theta;
                        shortened = true;
                        continue;
                    }
                }
                let factor = grow4(tol, err);
                if err > tol && !(err > 0.5 * rejected || step <= min_frac) {
                    rejected = err;
                    frac = step * factor.min(0.8);
                    continue;
                }
                rejected = f64::NAN;
                hermite::accept(s, &mut w, &sc, &mut hm, h)?;
                sum.n_steps = sum.n_steps.saturating_add(1);
                scale = (scale.0.max(amax(&w.x)), scale.1.max(amax(&w.v)));
                if w.x.iter().chain(&w.v).any(|v| !v.is_finite()) {
                    sum.status = Status::NonFinite {
                        time: inp.t[i] + tau1 * big_h,
                    };
                    return Ok(sum);
                }
                if !shortened {
                    want = (h * factor).max(f64::MIN_POSITIVE);
                }
                shortened = false;
                tau = tau1;
                frac = next_frac(tau, want, big_h);
                continue;
            }
            let ext = (scale, if h * rate > 2.0 { 0.0 } else { 1.0 / 3.0 });
            let Some((mut err, theta, it)) =
                piece(s, &mut w, &mut sc, &mut p, inp, i, span, ext, opts)
            else {
                halvings = halvings.saturating_add(1);
                if halvings > opts.max_halvings.saturating_mul(4) {
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
            if events < opts.max_events && theta < 1.0 {
                let min_piece = 1e-3 / step;
                if theta > min_piece && theta < 1.0 - min_piece {
                    events = events.saturating_add(1);
                    frac = step * theta;
                    shortened = true;
                    continue;
                }
            }
            let mut factor = crate::structure::grow(tol, err);
            if err > tol {
                // not cut as h³ would, or at the shortest piece: kept plain (see sdof)
                if !(err > 0.5 * rejected || step <= min_frac) {
                    rejected = err;
                    frac = step * factor.min(0.8);
                    continue;
                }
                let plain = (scale, 0.0);
                let Some((e, _, it)) = piece(s, &mut w, &mut sc, &mut p, inp, i, span, plain, opts)
                else {
                    frac = 0.5 * step;
                    continue;
                };
                sum.n_iter = sum.n_iter.saturating_add(it);
                err = e;
            }
            rejected = f64::NAN;
            if p.ext == 0.0 {
                (factor, rejected) = (2.0, err);
            }
            accept(s, &mut w, &sc, &p)?;
            hm.committed(&sc);
            sum.n_steps = sum.n_steps.saturating_add(1);
            scale = (scale.0.max(amax(&w.x)), scale.1.max(amax(&w.v)));
            if w.x.iter().chain(&w.v).any(|v| !v.is_finite()) {
                sum.status = Status::NonFinite {
                    time: inp.t[i] + tau1 * big_h,
                };
                return Ok(sum);
            }
            if !shortened {
                want = (h * factor).max(f64::MIN_POSITIVE);
            }
            shortened = false;
            tau = tau1;
            frac = next_frac(tau, want, big_h);
        }
        let next = i.saturating_add(1); // < nt
        record(s, &w, out, next);
        sum.n_out = next.saturating_add(1);
    }
    Ok(sum)
}
