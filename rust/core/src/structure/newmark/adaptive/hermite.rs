//! Hermite-corrected pieces for n DOFs (the one-DOF path's `sdof::adaptive` notes hold):
//! one Newmark step, its end corrected twice by the two-point Hermite rule with the jerk
//! `M j = ḟ − C a − K v − Σ (k_t ḋ + c_t d̈)` (joint terms scattered to their DOFs; at the
//! start the joints' right-limit tangents), the joints carried along their tangents from the
//! Newmark end and the acceleration put back in equilibrium (`M⁻¹` of the residual forces)
//! after each correction. The change of the second correction is the error estimate. `M⁻¹`,
//! `M⁻¹ C`, `M⁻¹ K` and `M⁻¹` of each joint's direction are formed once, so the jerks and the
//! equilibria are products, without a solve (a third of the cost of a 3-DOF piece, stop 38).

use super::super::super::dense::Lu;
use super::super::super::joint::JointLaw;
use super::super::super::{Inputs, Options, Structure};
use super::super::{load, matvec, newton_step, rel, Scratch, Work};
use crate::error::CoreError;

/// Whether the n-DOF error control takes Hermite pieces for these joints (not for
/// [`crate::joints`] laws, as the one-DOF path).
pub(super) fn allowed(s: &Structure) -> bool {
    !s.joints
        .iter()
        .any(|j| matches!(j.law, JointLaw::Law { .. }))
}

/// The buffers of the Hermite pieces.
pub(super) struct Herm {
    /// The load's rate over the current interval.
    fd: Vec<f64>,
    j0: Vec<f64>,
    j1: Vec<f64>,
    xp: Vec<f64>,
    vp: Vec<f64>,
    tmp: Vec<f64>,
    /// Each joint's tangents at the committed point (left limit), at the piece's start along
    /// it (right limit) and at the Newmark end; its relative displacement and velocity and its
    /// force at the Newmark end.
    tang: Vec<(f64, f64)>,
    start: Vec<(f64, f64)>,
    end: Vec<(f64, f64)>,
    dt: Vec<(f64, f64)>,
    ft: Vec<f64>,
    /// The end tangents the jerk is taken with (`end`, less the jump of a Masing closure
    /// just before the end), whether a joint can have such a jump, and whether the joint's
    /// Newmark end crossed one.
    end_j: Vec<(f64, f64)>,
    kinks: bool,
    crossed: Vec<bool>,
    /// `M⁻¹`, `M⁻¹ C` and `M⁻¹ K` (row-major), and each joint's column `M⁻¹ (e_dof −
    /// e_dof2)`: the jerk and the equilibrium acceleration as products, without a solve.
    mi: Vec<f64>,
    mic: Vec<f64>,
    mik: Vec<f64>,
    mcol: Vec<Vec<f64>>,
    /// `M⁻¹` of the load at the interval's start and of its rate, and the interval's length.
    mf0: Vec<f64>,
    mfd: Vec<f64>,
    mf1: Vec<f64>,
    big_h: f64,
    /// `C v` and `C a` at the committed point (the start's damping power in [`accept`]), when
    /// `cv_ok`: kept from the last Hermite piece's end.
    cv: Vec<f64>,
    ca: Vec<f64>,
    cv_ok: bool,
}

impl Herm {
    // Row-major n × n index arithmetic, n * n checked in `Structure::new`.
    #[allow(clippy::arithmetic_side_effects)]
    pub(super) fn new(s: &Structure, w: &Work) -> Result<Self, CoreError> {
        let n = s.n;
        let z = || vec![0.0; n];
        let mut m_lu = Lu::new(n);
        m_lu.factor(&s.m, n)
            .map_err(|_| CoreError::InvalidParameter {
                name: "M",
                value: 0.0,
                reason: "mass matrix is singular",
            })?;
        // M⁻¹ column by column, then M⁻¹ C and M⁻¹ K (row-major)
        let mut mi = vec![0.0; n * n];
        let mut col = vec![0.0; n];
        for c in 0..n {
            col.fill(0.0);
            col[c] = 1.0;
            m_lu.solve(&mut col);
            for r in 0..n {
                mi[r * n + c] = col[r];
            }
        }
        let prod = |a: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n * n];
            for r in 0..n {
                for c in 0..n {
                    out[r * n + c] = (0..n).map(|q| mi[r * n + q] * a[q * n + c]).sum();
                }
            }
            out
        };
        let (mic, mik) = (prod(&s.c), prod(&s.k));
        let mcol = s
            .joints
            .iter()
            .map(|j| {
                (0..n)
                    .map(|r| mi[r * n + j.dof] - j.dof2.map_or(0.0, |q| mi[r * n + q]))
                    .collect()
            })
            .collect();
        let tang = s
            .joints
            .iter()
            .zip(&w.states)
            .zip(w.jd.iter().zip(&w.jv))
            .map(|((j, st), (&d, &v))| {
                let t = j.law.trial(st, d, d, v);
                (t.kt, t.ct)
            })
            .collect();
        let nj = s.joints.len();
        Ok(Self {
            fd: z(),
            j0: z(),
            j1: z(),
            xp: z(),
            vp: z(),
            tmp: z(),
            tang,
            start: vec![(0.0, 0.0); nj],
            end: vec![(0.0, 0.0); nj],
            dt: vec![(0.0, 0.0); nj],
            ft: vec![0.0; nj],
            end_j: vec![(0.0, 0.0); nj],
            kinks: s
                .joints
                .iter()
                .any(|j| matches!(j.law, JointLaw::Masing { .. })),
            crossed: vec![false; nj],
            mi,
            mic,
            mik,
            mcol,
            mf0: z(),
            mfd: z(),
            mf1: z(),
            big_h: 0.0,
            cv: z(),
            ca: z(),
            cv_ok: false,
        })
    }

    /// The committed point's tangents from the trials just committed (and `C v`, `C a` there
    /// no longer known).
    pub(super) fn committed(&mut self, sc: &Scratch) {
        for (tg, tr) in self.tang.iter_mut().zip(&sc.trials) {
            *tg = (tr.kt, tr.ct);
        }
        self.cv_ok = false;
    }

    /// The load's rate over interval `i` (length `big_h`), and `M⁻¹` of it and of the load at
    /// the interval's start (the load is linear over the interval).
    pub(super) fn interval(&mut self, s: &Structure, inp: &Inputs<'_>, i: usize, big_h: f64) {
        load(s, inp, i, 1.0, &mut self.fd);
        load(s, inp, i, 0.0, &mut self.tmp);
        for (f, f0) in self.fd.iter_mut().zip(&self.tmp) {
            *f = (*f - f0) / big_h;
        }
        matvec(&self.mi, &self.tmp, s.n, &mut self.mf0);
        matvec(&self.mi, &self.fd, s.n, &mut self.mfd);
        self.big_h = big_h;
    }
}

/// `out = p − A u − B w` (`A`, `B` row-major `n × n`).
// Row-major index arithmetic below n (the buffers are n and n × n long).
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
fn affine(p: &[f64], (a, u): (&[f64], &[f64]), (b, w): (&[f64], &[f64]), out: &mut [f64]) {
    let n = out.len();
    for (r, o) in out.iter_mut().enumerate() {
        let (ra, rb) = (&a[r * n..(r + 1) * n], &b[r * n..(r + 1) * n]);
        let mut acc = p[r];
        for c in 0..n {
            acc -= ra[c] * u[c] + rb[c] * w[c];
        }
        *o = acc;
    }
}

/// `M⁻¹ (ḟ − C a − K v − Σ (k_t ḋ + c_t d̈))` with the joints' tangents (`hm.start` into
/// `hm.j0`, or `hm.end_j` into `hm.j1`), as products with the `M⁻¹` matrices.
fn jerk(s: &Structure, hm: &mut Herm, (v, a): (&[f64], &[f64]), at_start: bool) {
    let (tang, out) = if at_start {
        (&hm.start, &mut hm.j0)
    } else {
        (&hm.end_j, &mut hm.j1)
    };
    affine(&hm.mfd, (&hm.mic, a), (&hm.mik, v), out);
    for ((j, &(kt, ct)), col) in s.joints.iter().zip(tang).zip(&hm.mcol) {
        let g = kt * rel(j, v) + ct * rel(j, a);
        for (o, m) in out.iter_mut().zip(col) {
            *o -= g * m;
        }
    }
}

/// The root in `(0, 1)` of the cubic Hermite interpolant with values `v0`, `v1` and scaled
/// slopes `d0`, `d1` at 0 and 1 (a relative velocity over a piece), by Newton from `s`.
fn reversal(s: f64, (v0, d0): (f64, f64), (v1, d1): (f64, f64)) -> f64 {
    let mut t = s;
    for _ in 0..3 {
        let (t2, t3) = (t * t, t * t * t);
        let val = (2.0 * t3 - 3.0 * t2 + 1.0) * v0
            + (t3 - 2.0 * t2 + t) * d0
            + (3.0 * t2 - 2.0 * t3) * v1
            + (t3 - t2) * d1;
        let der = (6.0 * t2 - 6.0 * t) * (v0 - v1)
            + (3.0 * t2 - 4.0 * t + 1.0) * d0
            + (3.0 * t2 - 2.0 * t) * d1;
        let next = t - val / der;
        if !(next > 0.0 && next < 1.0) {
            return s;
        }
        t = next;
    }
    t
}

/// A Hermite piece over `(tau1, h)` of interval `i` from `w`: on success its end is in
/// `sc.x1/v1/a1/f1`, each joint's force there in `sc.trials` (carried along its tangents), and
/// `(error estimate, event fraction (1: none), Newton iterations)` is returned; `None` if
/// Newton failed.
// The piece's context (structure, state, buffers, input, span, scales, options) as it is;
// row-major index arithmetic below n and the joint count.
#[allow(clippy::too_many_arguments, clippy::arithmetic_side_effects)]
pub(super) fn piece(
    s: &Structure,
    w: &Work,
    sc: &mut Scratch,
    hm: &mut Herm,
    inp: &Inputs<'_>,
    i: usize,
    (tau1, h, step): (f64, f64, f64),
    scale: (f64, f64),
    opts: &Options,
) -> Option<(f64, f64, u64)> {
    let n = s.n;
    load(s, inp, i, tau1, &mut sc.f1);
    let t1 = tau1 * hm.big_h;
    for ((o, f0), fd) in hm.mf1.iter_mut().zip(&hm.mf0).zip(&hm.mfd) {
        *o = f0 + t1 * fd;
    }
    // Newton starts from a + h j (the jerk with the committed tangents): closer than a by h
    hm.start.copy_from_slice(&hm.tang);
    jerk(s, hm, (&w.v, &w.a), true);
    for ((a1, a0), j0) in sc.a1.iter_mut().zip(&w.a).zip(&hm.j0) {
        *a1 = a0 + h * j0;
    }
    // Newton ends without a last trial once its residual is below `HERMITE_QUICK` (as the
    // one-DOF path; a Masing joint's crossing of a closure is then read from its trial's
    // memory walk)
    let quick = crate::structure::hermite_quick(opts.rtol);
    let it = newton_step(s, w, (h, quick, true), sc, opts)?;
    let mut theta = 1.0_f64;
    let min_piece = 1e-3 / step;
    for (jn, j) in s.joints.iter().enumerate() {
        let (d1, v1) = (rel(j, &sc.x1), rel(j, &sc.v1));
        let (d0, v0) = (w.jd[jn], w.jv[jn]);
        let (st, tr) = (&w.states[jn], &sc.trials[jn]);
        // (a stick-slip transition placed on the cubic through the ends' relative
        // displacements and velocities, as the one-DOF path; events at most `min_piece` in
        // left to this piece, so that they do not hide a later one)
        let mut th = j.law.slip_after(st, d0, d1, min_piece).unwrap_or(1.0);
        if th < 1.0 && v0 * v1 >= 0.0 {
            let dk = d0 + th * (d1 - d0);
            th = reversal(th, (d0 - dk, h * v0), (d1 - dk, h * v1));
        }
        if th <= min_piece {
            th = 1.0;
        }
        if v0 * v1 < 0.0 {
            let lin = v0 / (v0 - v1);
            if th >= lin {
                th = reversal(lin, (v0, h * rel(j, &w.a)), (v1, h * rel(j, &sc.a1)));
            }
        }
        hm.start[jn] = j.law.start_tangent(st, d0, d1, tr).unwrap_or(hm.tang[jn]);
        hm.end[jn] = (tr.kt, tr.ct);
        hm.end_j[jn] = hm.end[jn];
        hm.dt[jn] = (d1, v1);
        hm.ft[jn] = tr.f;
        hm.crossed[jn] = hm.kinks && j.law.closed(st, tr);
        if hm.kinks {
            if let Some((xk, dk)) = j.law.kink(st, d1) {
                // a Masing branch closing (its tangent jumps by dk): as the one-DOF path
                let lin = (xk - d0) / (d1 - d0);
                let tk = reversal(lin, (d0 - xk, h * v0), (d1 - xk, h * v1));
                if tk <= min_piece {
                    hm.start[jn].0 += dk;
                } else if tk >= 1.0 - min_piece {
                    hm.end_j[jn].0 -= dk;
                } else {
                    th = th.min(tk);
                }
            }
        }
        if th > min_piece {
            theta = theta.min(th);
        }
    }
    if hm.start != hm.tang {
        jerk(s, hm, (&w.v, &w.a), true);
    }
    let (h2, h3) = (h * h, h * h * h);
    for _ in 0..2 {
        jerk(s, hm, (&sc.v1, &sc.a1), false);
        hm.xp.copy_from_slice(&sc.x1);
        hm.vp.copy_from_slice(&sc.v1);
        for d in 0..n {
            let (a0, a1, j0, j1) = (w.a[d], sc.a1[d], hm.j0[d], hm.j1[d]);
            sc.v1[d] = w.v[d] + 0.5 * h * (a0 + a1) + h2 / 12.0 * (j0 - j1);
            sc.x1[d] = w.x[d]
                + h * w.v[d]
                + h2 / 20.0 * (7.0 * a0 + 3.0 * a1)
                + h3 / 60.0 * (3.0 * j0 - 2.0 * j1);
        }
        // the joints carried along their tangents
        for (jn, j) in s.joints.iter().enumerate() {
            let ((kt, ct), (d, v)) = (hm.end[jn], hm.dt[jn]);
            sc.trials[jn].f = hm.ft[jn] + kt * (rel(j, &sc.x1) - d) + ct * (rel(j, &sc.v1) - v);
        }
        equilibrium(sc, hm);
    }
    if hm.kinks {
        // a corrected end across a closure the Newmark end had not crossed (or back): the
        // joint tried anew there, so that its memory is the end's
        let mut again = false;
        for (jn, j) in s.joints.iter().enumerate() {
            let st = &w.states[jn];
            let d1 = rel(j, &sc.x1);
            if j.law.kink(st, d1).is_some() != hm.crossed[jn] {
                let tr = j.law.trial(st, w.jd[jn], d1, rel(j, &sc.v1));
                hm.end[jn] = (tr.kt, tr.ct);
                hm.end_j[jn] = hm.end[jn];
                sc.trials[jn] = tr;
                again = true;
            }
        }
        if again {
            equilibrium(sc, hm);
        }
    }
    let (mut ex, mut ev, mut sx, mut sv) = (0.0_f64, 0.0_f64, scale.0, scale.1);
    for d in 0..n {
        ex = ex.max((sc.x1[d] - hm.xp[d]).abs());
        ev = ev.max((sc.v1[d] - hm.vp[d]).abs());
        sx = sx.max(sc.x1[d].abs());
        sv = sv.max(sc.v1[d].abs());
    }
    let rel_err = |e: f64, sz: f64| if e == 0.0 { 0.0 } else { e / sz };
    let err = rel_err(ex, sx).max(rel_err(ev, sv));
    Some((if err.is_nan() { f64::INFINITY } else { err }, theta, it))
}

/// `sc.a1 = M⁻¹ (f − C v − K x − G)` at the end in `sc` (`hm.mf1`: `M⁻¹ f` there), the joints'
/// forces `sc.trials[].f`, as products with the `M⁻¹` matrices.
fn equilibrium(sc: &mut Scratch, hm: &Herm) {
    affine(&hm.mf1, (&hm.mic, &sc.v1), (&hm.mik, &sc.x1), &mut sc.a1);
    for (tr, col) in sc.trials.iter().zip(&hm.mcol) {
        for (o, m) in sc.a1.iter_mut().zip(col) {
            *o -= tr.f * m;
        }
    }
}

/// `∫ g dt` over a piece of length `h` by the two-point Hermite rule: `g` and `ġ` at both ends.
#[inline(always)]
fn rule(h: f64, (g0, dg0): (f64, f64), (g1, dg1): (f64, f64)) -> f64 {
    0.5 * h * (g0 + g1) + h * h / 12.0 * (dg0 - dg1)
}

/// Commit a Hermite piece (its end in `sc`): state, joints (their work by the Hermite rule of
/// `F ḋ`), energies (the Hermite rule of the input and damping powers).
// Row-major index arithmetic: rows d < n of the n × n C checked in `Structure::new`.
#[allow(clippy::arithmetic_side_effects)]
pub(super) fn accept(
    s: &Structure,
    w: &mut Work,
    sc: &Scratch,
    hm: &mut Herm,
    h: f64,
) -> Result<(), CoreError> {
    let n = s.n;
    let (mut p0, mut dp0, mut p1, mut dp1) = (0.0, 0.0, 0.0, 0.0);
    let (mut q0, mut dq0, mut q1, mut dq1) = (0.0, 0.0, 0.0, 0.0);
    let known = hm.cv_ok;
    for d in 0..n {
        let fd = hm.fd[d];
        p0 += w.f[d] * w.v[d];
        dp0 += fd * w.v[d] + w.f[d] * w.a[d];
        p1 += sc.f1[d] * sc.v1[d];
        dp1 += fd * sc.v1[d] + sc.f1[d] * sc.a1[d];
        let row = &s.c[d * n..(d + 1) * n];
        let dot = |u: &[f64]| -> f64 { row.iter().zip(u).map(|(c, x)| c * x).sum() };
        let (cv0, ca0) = if known {
            (hm.cv[d], hm.ca[d])
        } else {
            (dot(&w.v), dot(&w.a))
        };
        let (cv1, ca1) = (dot(&sc.v1), dot(&sc.a1));
        (hm.cv[d], hm.ca[d]) = (cv1, ca1);
        q0 += w.v[d] * cv0;
        dq0 += w.a[d] * cv0 + w.v[d] * ca0;
        q1 += sc.v1[d] * cv1;
        dq1 += sc.a1[d] * cv1 + sc.v1[d] * ca1;
    }
    w.e_in += rule(h, (p0, dp0), (p1, dp1));
    w.e_damp += rule(h, (q0, dq0), (q1, dq1));
    for (jn, j) in s.joints.iter().enumerate() {
        let tr = &sc.trials[jn];
        let (v0, a0, v1, a1) = (w.jv[jn], rel(j, &w.a), rel(j, &sc.v1), rel(j, &sc.a1));
        let ((kt0, ct0), (kt1, ct1)) = (hm.start[jn], hm.end[jn]);
        let f0 = w.jf[jn];
        let d1 = rel(j, &sc.x1);
        if matches!(j.law, JointLaw::Masing { .. }) {
            // the Hermite rule in d (rate-independent; as the one-DOF path's `masing_work`),
            // with the tangents of the branch the piece is on at both ends
            let (dd, k1) = (d1 - w.jd[jn], hm.end_j[jn].0);
            w.jwork[jn] += 0.5 * dd * (f0 + tr.f) + dd * dd / 12.0 * (kt0 - k1);
        } else {
            let g0 = (f0 * v0, (kt0 * v0 + ct0 * a0) * v0 + f0 * a0);
            let g1 = (tr.f * v1, (kt1 * v1 + ct1 * a1) * v1 + tr.f * a1);
            w.jwork[jn] += rule(h, g0, g1);
        }
        j.law.commit(&mut w.states[jn], w.jd[jn], d1, tr)?;
        w.jf[jn] = tr.f;
        w.jd[jn] = d1;
        w.jv[jn] = v1;
    }
    hm.committed(sc);
    hm.cv_ok = true;
    w.x.copy_from_slice(&sc.x1);
    w.v.copy_from_slice(&sc.v1);
    w.a.copy_from_slice(&sc.a1);
    w.f.copy_from_slice(&sc.f1);
    Ok(())
}
