//! Error-controlled stepping for one DOF: Hermite-corrected Newmark steps, or step doubling
//! with Richardson extrapolation.
//!
//! Hermite pieces (joint sets whose [`Joints::hermite`] allows them, pieces shorter than
//! `HERMITE_RATE /` the fastest rate): one Newmark step, whose end is then corrected twice by
//! the two-point Hermite rule `v1 = v0 + h/2 (a0 + a1) + h²/12 (j0 − j1)`, `x1 = x0 + h v0 +
//! h²/20 (7 a0 + 3 a1) + h³/60 (3 j0 − 2 j1)` with the jerk `m j = ḟ − (c + c_t) a − (k +
//! k_t) v` (the load's rate over the interval; the joints' tangents at the start are their
//! right limit along the piece), the joints carried along their tangents from the Newmark end
//! and the acceleration put back in equilibrium after each correction. The Newmark end is
//! second order; each correction gains an order (the first is limited by the Newmark end's
//! acceleration, `h/2 δa`), the second is fourth order, and the change it made is the error
//! estimate (held to `tol` relative to the displacement and velocity sizes, the length
//! following `(tol / err)^(1/4)`). One Newton solve per piece (ended after its update once
//! the residual is below `HERMITE_QUICK` of the forces, without a last trial: the joints
//! carried along their tangents by that update, or tried anew where it moved the end across
//! the start, a Masing closure or a slip point) and no further joint evaluations: about the
//! cost of a fixed step. Energies are
//! the Hermite rule's integrals of the powers. Velocity reversals are placed at the root of
//! the cubic through the ends' velocities and accelerations.
//!
//! Where the law is not smooth along a monotone move, the rule loses orders the estimate does
//! not see (measured: error not falling with `tol`), so the non-smooth points are handled:
//! - a Masing branch closing (its tangent jumps, so the jerk jumps by `Δk ḋ / m`): the piece
//!   ends there (the root of the cubic through the ends' displacements and velocities); a
//!   closure within `1e-3` of the interval from a piece's end takes that end's tangent from the
//!   branch the piece is on, and an end that the corrections moved across a closure (or back)
//!   has its joints tried anew there (SDOF Masing on the bench: 1.9e-4 -> 3.5e-6 RMS);
//! - a Bouc-Wen `z` (`ν = 1`) crossing 0 (its rate `dz/dd` has a kink, the force's second time
//!   derivative jumps by `Δ α ḋ²`): the piece is not split, the rule's known error on the jump,
//!   `d e(u)` with `d` the jump of the displacement's fourth derivative and `u` the time from
//!   the crossing to the end, is added to the corrected end (750 Hz Bouc-Wen: 6.2e-5 -> 1.5e-5
//!   RMS at the same pieces; splitting there instead cost 1.43 -> 1.52 of a fixed step's
//!   cost at 3 kHz, stop 37).
//!
//! Step-doubling pieces ([`crate::joints`] laws, stiff pieces):
//! Each piece of a sample interval is taken twice, as one Newmark step of length `h` and as two
//! of `h/2` (the second from the midpoint, its joint trials from the piece's committed start:
//! pieces never contain a reversal or a stick-slip transition, so the path is monotone and
//! the hysteretic state at the end is the same). Average-acceleration Newmark is the
//! trapezoidal rule, whose error has an expansion in even powers of `h`; the difference of the
//! pair, divided by 3, estimates the local error of the half steps, and their Richardson
//! extrapolation `(4 y_{h/2} − y_h) / 3` cancels the leading term: the kept state is fourth
//! order. Its acceleration is the one in equilibrium there, the joints are tried at the
//! extrapolated displacement from their committed state (their history carried exactly), and
//! the energy increments are extrapolated the same way (Romberg on the trapezoidal sums).
//!
//! A piece is accepted when the estimate is at most `tol` relative to the largest displacement
//! and velocity so far; the next piece length follows the usual `(tol / err)^(1/3)` rule, and
//! pieces always end on the samples (the inputs have a kink there).

use super::{load, newton, record, Ends, Joints, Point, State, Step};
use crate::error::CoreError;
use crate::structure::{Buffers, Inputs, Options, Status, Summary};

/// A Newton solve of the pair ends, without a last trial, once its residual is below this
/// fraction of the forces (see `newton`): the error left is of the order of its square, and
/// such a solve's joint trials are never committed (the extrapolated point is tried anew).
pub(super) const QUICK: f64 = 1e-3;

/// The shortest piece (a fraction of the sample interval) error control cuts to.
const MIN_FRAC: f64 = 1.0 / 64.0;

/// Hermite pieces are taken while `h ×` the structure's fastest rate is at most this (their
/// corrections are explicit: a fixed-point iteration that converges for `|h λ| < 2`).
const HERMITE_RATE: f64 = 1.0;

/// The factor on the piece length after a Hermite piece's estimate `err` (fourth order in `h`:
/// `0.9 (tol / err)^(1/4)` within `[0.2, 4]`).
#[inline]
fn grow4(tol: f64, err: f64) -> f64 {
    if err * 391.0 <= tol {
        4.0
    } else {
        (0.9 * (tol / err).sqrt().sqrt()).clamp(0.2, 4.0)
    }
}

/// A step-doubling piece, extrapolated (not yet committed): the step to keep, the coarse and
/// fine ends, the midpoint, the error estimate, the event inside (1: none) and iterations.
struct Piece {
    /// The extrapolation weight used (1/3; 0: the plain half steps kept).
    ext: f64,
    st: Step,
    xc: f64,
    vc: f64,
    xm: f64,
    vm: f64,
    fm: f64,
    xf: f64,
    vf: f64,
    err: f64,
    theta: f64,
    iters: u64,
}

/// Step doubling over `[tau, tau1]` of interval `i` (length `h`) from `w`; `None` if Newton
/// failed on any of the three steps. `scale`: the displacement and velocity sizes.
// The piece's context (structure, state, input, span, scales, options) as it is.
#[allow(clippy::too_many_arguments)]
fn piece<J: Joints>(
    jt: &mut J,
    mck: (f64, f64, f64),
    w: &State,
    inp: &Inputs<'_>,
    i: usize,
    (tau, tau1, h): (f64, f64, f64),
    (scale, ext): ((f64, f64), f64),
    opts: &Options,
) -> Option<Piece> {
    let (m, c, k) = mck;
    let f1 = load(inp, i, tau1);
    let fm = load(inp, i, 0.5 * (tau + tau1));
    // Quadratic convergence leaves a residual of the order of the square of the last one (in
    // units of the forces): ending at `√rtol` keeps the solve's error within `rtol`.
    let quick = jt.quick().min(opts.rtol.sqrt());
    let (coarse, i1) = newton(jt, mck, w, (w.x, quick), h, f1, opts)?;
    jt.keep(0, coarse.moved);
    let (half, i2) = newton(jt, mck, w, (w.x, quick), 0.5 * h, fm, opts)?;
    jt.keep(1, half.moved);
    let mid = State {
        x: half.x1,
        v: half.v1,
        a: half.a1,
        f: fm,
        e_in: 0.0,
        e_damp: 0.0,
        g: half.joints.f,
        kt: half.joints.kt,
        ct: half.joints.ct,
    };
    let (fine, i3) = newton(jt, mck, &mid, (w.x, quick), 0.5 * h, f1, opts)?;
    jt.keep(2, fine.moved);
    // events: the joints' own (from the committed start to the fine end), and a velocity
    // reversal of the fine path in either half
    let mut theta = jt.event(w.x, fine.x1, w.v, fine.v1);
    if w.v * mid.v < 0.0 {
        theta = theta.min(0.5 * w.v / (w.v - mid.v));
    } else if mid.v * fine.v1 < 0.0 {
        theta = theta.min(0.5 + 0.5 * mid.v / (mid.v - fine.v1));
    }
    let (xr, vr) = (
        fine.x1 + (fine.x1 - coarse.x1) * ext,
        fine.v1 + (fine.v1 - coarse.v1) * ext,
    );
    let (sx, sv) = (
        scale.0.max(fine.x1.abs()).max(coarse.x1.abs()),
        scale.1.max(fine.v1.abs()).max(coarse.v1.abs()),
    );
    let rel = |e: f64, s: f64| if e == 0.0 { 0.0 } else { e / s };
    let err =
        rel((fine.x1 - coarse.x1).abs() / 3.0, sx).max(rel((fine.v1 - coarse.v1).abs() / 3.0, sv));
    // the joints at the extrapolated point, tried from their committed state
    let pt = Point {
        x1: xr,
        v1: vr,
        xp: xr,
        b: 0.0,
        a1: 0.0,
    };
    let js = jt.trial(w.x, &pt);
    let ar = (f1 - c * vr - k * xr - js.f) / m;
    let st = Step {
        dx: xr - w.x,
        x1: xr,
        v1: vr,
        a1: ar,
        f1,
        joints: js,
        moved: (0.0, 0.0),
    };
    Some(Piece {
        ext,
        st,
        xc: coarse.x1,
        vc: coarse.v1,
        xm: mid.x,
        vm: mid.v,
        fm,
        xf: fine.x1,
        vf: fine.v1,
        err: if err.is_nan() { f64::INFINITY } else { err },
        theta,
        iters: i1.saturating_add(i2).saturating_add(i3),
    })
}

/// A Hermite piece (not yet committed): the state to keep, how far it lies from the joints'
/// last trial, the start's tangents, the error estimate, the event inside (1: none) and the
/// Newton iterations.
struct Herm {
    st: Step,
    moved: (f64, f64),
    kt0: f64,
    /// The tangent jumps of a Masing closure next to the start and the end, added to the
    /// joints' start and end tangents (see [`Ends::dk`]).
    dk: (f64, f64),
    err: f64,
    theta: f64,
    iters: u64,
}

/// One Newmark step over `[tau, tau1]` of interval `i` (length `h`, load rate `fd` there) from
/// `w`, corrected twice by the two-point Hermite rule (see the module notes); `None` if Newton
/// failed. `scale`: the displacement and velocity sizes.
// The piece's context (joints, structure, state, input, span, load rate, scales, options).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn hermite<J: Joints>(
    jt: &mut J,
    (m, c, k): (f64, f64, f64),
    w: &State,
    inp: &Inputs<'_>,
    i: usize,
    (tau1, h): (f64, f64),
    (fd, scale): (f64, (f64, f64)),
    (opts, min_piece, (kinks, kinks_z)): (&Options, f64, (bool, bool)),
) -> Option<Herm> {
    let f1 = load(inp, i, tau1);
    // (the corrections' chain multiplies by it: a division there is 3-4 times the latency)
    let im = 1.0 / m;
    // Newton ends without a last trial once its residual is below `HERMITE_QUICK` of the
    // forces (not for difference-quotient tangents): the joints are carried along their
    // tangents by its last update, as the corrections below carry them, and the corrections
    // remove the residual left with the Newmark end's own error
    let quick = if jt.quick() > 0.0 {
        crate::structure::hermite_quick(opts.rtol)
    } else {
        0.0
    };
    let (st, iters) = newton(jt, (m, c, k), w, (w.x, quick), h, f1, opts)?;
    // A stick-slip transition (linear in the displacement while stuck): where the cubic
    // through the ends' displacements and velocities reaches it (the fraction of the move is
    // not that of the time: a piece ended there would land short, again and again). Events at
    // most `min_piece` in are left to this piece (they would hide a later one, e.g. a
    // reversal).
    let mut theta = jt.slip(w.x, st.x1, min_piece);
    if theta < 1.0 && w.v * st.v1 >= 0.0 {
        let xk = w.x + theta * (st.x1 - w.x);
        theta = cubic_root(theta, (w.x - xk, h * w.v), (st.x1 - xk, h * st.v1));
    }
    if theta <= min_piece {
        theta = 1.0;
    }
    if w.v * st.v1 < 0.0 {
        // a velocity reversal: where the cubic through the ends' velocities and accelerations
        // has its root (the linear guess is off by O(h²), and the monotone path a trial
        // assumes then overshoots a joint's reversal by O(h⁴) in d)
        let lin = w.v / (w.v - st.v1);
        if theta >= lin {
            theta = cubic_root(lin, (w.v, h * w.a), (st.v1, h * st.a1));
        }
    }
    let (mut kt0, ct0) = jt.start_tangent(w.x, st.x1).unwrap_or((w.kt, w.ct));
    let (mut kt1, ct1) = (st.joints.kt, st.joints.ct);
    // (the crossing as the joints' last trial saw it: a quick Newton end lies a little off)
    let kink = if kinks {
        jt.kink(st.x1 - st.moved.0)
    } else {
        None
    };
    let mut dks = (0.0, 0.0);
    if let Some((xk, dk)) = kink {
        // a tangent jump (a Masing branch closing, `dk`): where the cubic through the ends'
        // displacements and velocities reaches it. Inside the piece, the piece ends there
        // (the jerk jumps by `dk ḋ / m`, which the Hermite rule cannot follow); within
        // `min_piece` of an end, that end's tangent is the one of the branch the piece is on.
        let lin = (xk - w.x) / (st.x1 - w.x);
        let th = cubic_root(lin, (w.x - xk, h * w.v), (st.x1 - xk, h * st.v1));
        if th <= min_piece {
            kt0 += dk;
            dks.0 = dk;
        } else if th >= 1.0 - min_piece {
            kt1 -= dk;
            dks.1 = -dk;
        } else {
            theta = theta.min(th);
        }
    }
    // A Bouc-Wen z crossing 0 inside the piece: the joint force's second time derivative
    // jumps there (by `q ḋ²`), so does the displacement's fourth, by `d = −q ḋ² / m`; the
    // Hermite rule, exact for quartics, is off by `d e(u)` (`u` the time from the crossing to
    // the end: the rule's error on `d (t − t_k)₊⁴ / 24`), which is added to its ends.
    let zero = if kinks_z {
        jt.zero_jump(w.x, st.x1, h, (w.v, st.v1))
    } else {
        None
    };
    let (ex, ev) = match zero {
        Some((th, q)) if th > 0.0 && th < 1.0 => {
            let vk = cubic_value(th, (w.v, h * w.a), (st.v1, h * st.a1));
            let d = -q * vk * vk * im;
            let u = (1.0 - th) * h;
            let (u2, h2) = (u * u, h * h);
            (
                d * u * (u2 * u / 24.0 - 3.0 * h2 * u / 40.0 + h2 * h / 30.0),
                d * u * (u2 / 6.0 - h * u / 4.0 + h2 / 12.0),
            )
        }
        _ => (0.0, 0.0),
    };
    let j0 = (fd - (c + ct0) * w.a - (k + kt0) * w.v) * im;
    let (xt, vt, gt) = (st.x1, st.v1, st.joints.f);
    let (mut x1, mut v1, mut a1, mut g1) = (xt, vt, st.a1, gt);
    let (mut xp, mut vp) = (x1, v1);
    let (h2, h3) = (h * h, h * h * h);
    for _ in 0..2 {
        let j1 = (fd - (c + ct1) * a1 - (k + kt1) * v1) * im;
        (xp, vp) = (x1, v1);
        v1 = w.v + 0.5 * h * (w.a + a1) + h2 / 12.0 * (j0 - j1) + ev;
        x1 = w.x
            + h * w.v
            + h2 / 20.0 * (7.0 * w.a + 3.0 * a1)
            + h3 / 60.0 * (3.0 * j0 - 2.0 * j1)
            + ex;
        // the joints carried along their tangents from the Newmark end (the move is of the
        // order of the step's local error: the linearisation's error is of its square)
        g1 = gt + st.joints.kt * (x1 - xt) + ct1 * (v1 - vt);
        a1 = (f1 - c * v1 - k * x1 - g1) * im;
    }
    let mut joints = st.joints;
    let mut moved = (st.moved.0 + (x1 - xt), st.moved.1 + (v1 - vt));
    if kinks && jt.kink(x1).is_some() != kink.is_some() {
        // the corrections moved the end across a closure the Newmark end had not crossed (or
        // back): the joints tried anew at the end, so that their memory is the end's
        let pt = Point {
            x1,
            v1,
            xp: x1,
            b: 0.0,
            a1: 0.0,
        };
        joints = jt.trial(w.x, &pt);
        g1 = joints.f;
        a1 = (f1 - c * v1 - k * x1 - g1) * im;
        moved = (0.0, 0.0);
        dks.1 = 0.0;
    }
    let (sx, sv) = (scale.0.max(x1.abs()), scale.1.max(v1.abs()));
    let rel = |e: f64, s: f64| if e == 0.0 { 0.0 } else { e / s };
    let err = rel((x1 - xp).abs(), sx).max(rel((v1 - vp).abs(), sv));
    joints.f = g1;
    let out = Step {
        dx: x1 - w.x,
        x1,
        v1,
        a1,
        f1,
        joints,
        moved: (0.0, 0.0),
    };
    Some(Herm {
        st: out,
        moved,
        kt0,
        dk: dks,
        err: if err.is_nan() { f64::INFINITY } else { err },
        theta,
        iters,
    })
}

/// The root in `(0, 1)` of the cubic Hermite interpolant with values `v0`, `v1` and scaled
/// slopes `d0`, `d1` at 0 and 1 (the velocity over a piece), by Newton from `s` (kept if
/// Newton leaves the interval).
#[inline]
pub(super) fn cubic_root(s: f64, (v0, d0): (f64, f64), (v1, d1): (f64, f64)) -> f64 {
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

/// The cubic Hermite interpolant with values `v0`, `v1` and scaled slopes `d0`, `d1` at 0
/// and 1, at `t`.
#[inline]
fn cubic_value(t: f64, (v0, d0): (f64, f64), (v1, d1): (f64, f64)) -> f64 {
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * v0
        + (t3 - 2.0 * t2 + t) * d0
        + (3.0 * t2 - 2.0 * t3) * v1
        + (t3 - t2) * d1
}

/// `∫ g dt` over a piece of length `h` by the two-point Hermite rule: `g` and `ġ` at both ends.
#[inline(always)]
fn hermite_rule(h: f64, (g0, dg0): (f64, f64), (g1, dg1): (f64, f64)) -> f64 {
    0.5 * h * (g0 + g1) + h * h / 12.0 * (dg0 - dg1)
}

/// Commit a Hermite piece: the state, the joints (shifted to its end, their work by the Hermite
/// rule) and the energies (input and damping work by the Hermite rule).
#[inline(always)]
fn accept_hermite<J: Joints>(
    jt: &mut J,
    c: f64,
    w: &mut State,
    p: &Herm,
    (h, fd): (f64, f64),
) -> Result<(), CoreError> {
    let s = &p.st;
    let (v0, a0, v1, a1) = (w.v, w.a, s.v1, s.a1);
    w.e_in += hermite_rule(
        h,
        (w.f * v0, fd * v0 + w.f * a0),
        (s.f1 * v1, fd * v1 + s.f1 * a1),
    );
    w.e_damp += c * hermite_rule(h, (v0 * v0, 2.0 * v0 * a0), (v1 * v1, 2.0 * v1 * a1));
    jt.shift(p.moved);
    let e = Ends {
        h,
        v0,
        a0,
        v1,
        a1,
        kt0: p.kt0,
        dk: p.dk,
    };
    jt.commit_hermite(w.x, s.x1, &e)?;
    w.x = s.x1;
    w.v = v1;
    (w.g, w.kt, w.ct) = (s.joints.f, s.joints.kt, s.joints.ct);
    w.a = a1;
    w.f = s.f1;
    Ok(())
}

/// Commit an accepted piece: the state, the joints (their work extrapolated) and the energies
/// (input and damping work: Romberg on the trapezoidal sums of the pair).
fn accept<J: Joints>(jt: &mut J, c: f64, w: &mut State, p: &Piece) -> Result<(), CoreError> {
    let (x0, v0, f0, f1) = (w.x, w.v, w.f, p.st.f1);
    let rich = |coarse: f64, fine: f64| fine + (fine - coarse) * p.ext;
    let e_in = rich(
        (p.xc - x0) * 0.5 * (f0 + f1),
        (p.xm - x0) * 0.5 * (f0 + p.fm) + (p.xf - p.xm) * 0.5 * (p.fm + f1),
    );
    let e_damp = c * rich(
        (p.xc - x0) * 0.5 * (v0 + p.vc),
        (p.xm - x0) * 0.5 * (v0 + p.vm) + (p.xf - p.xm) * 0.5 * (p.vm + p.vf),
    );
    w.e_in += e_in;
    w.e_damp += e_damp;
    jt.commit_doubled(x0, (p.xc, p.xm, p.xf), p.ext, p.st.x1)?;
    w.x = p.st.x1;
    w.v = p.st.v1;
    (w.g, w.kt, w.ct) = (p.st.joints.f, p.st.joints.kt, p.st.joints.ct);
    w.a = p.st.a1;
    w.f = f1;
    Ok(())
}

/// The piece length (a fraction of the interval, whose length is `big_h`) to try from `tau`:
/// the wanted length `want` (in seconds), or the rest of the interval cut into equal pieces
/// no longer than it.
fn next_frac(tau: f64, want: f64, big_h: f64) -> f64 {
    // (compared in seconds: no division where the rest is taken whole, the common case)
    let rest = (1.0 - tau).max(0.0);
    if want >= rest * big_h {
        return rest;
    }
    rest / (rest * big_h / want).ceil().max(1.0)
}

/// The error-controlled integration loop (state `w` at `t[0]`, already recorded).
// The run's context, handed on from the fixed-step front as it is.
#[allow(clippy::too_many_arguments)]
pub(super) fn run<J: Joints>(
    inp: &Inputs<'_>,
    mck: (f64, f64, f64),
    (tol, rate): (f64, f64),
    opts: &Options,
    jt: &mut J,
    mut w: State,
    mut sum: Summary,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    let mut scale = (w.x.abs(), w.v.abs());
    // the wanted piece length in seconds (carried from interval to interval)
    let mut want = f64::INFINITY;
    // a piece this short is kept whatever its estimate (a kink the pair cannot resolve)
    let min_frac = MIN_FRAC;
    // the estimate of the last rejected try, or of the last piece kept plain (NaN: none)
    let mut rejected = f64::NAN;
    // Hermite pieces where every joint allows them
    let hermite_ok = jt.hermite();
    // joints whose tangent can jump inside a monotone move (Masing closures), and Bouc-Wen
    // joints (their z crossing 0)
    let kinds = (jt.kinks(), jt.zero_crossings());
    for (i, pair) in inp.t.windows(2).enumerate() {
        let big_h = pair[1] - pair[0];
        let mut tau = 0.0_f64;
        let mut halvings = 0usize;
        let mut events = 0usize;
        let mut frac = next_frac(tau, want, big_h);
        let mut shortened = false;
        // the load's rate over the interval (linear between samples)
        let fd = (load(inp, i, 1.0) - load(inp, i, 0.0)) / big_h;
        while tau < 1.0 {
            let step = frac.min(1.0 - tau);
            let h = step * big_h;
            let tau1 = if step >= 1.0 - tau { 1.0 } else { tau + step };
            let span = (tau, tau1, h);
            if hermite_ok && h * rate <= HERMITE_RATE {
                let ctx = (opts, 1e-3 / step, kinds);
                let Some(p) = hermite(jt, mck, &w, inp, i, (tau1, h), (fd, scale), ctx) else {
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
                sum.n_iter = sum.n_iter.saturating_add(p.iters);
                if events < opts.max_events && p.theta < 1.0 {
                    let min_piece = 1e-3 / step;
                    if p.theta > min_piece && p.theta < 1.0 - min_piece {
                        events = events.saturating_add(1);
                        frac = step * p.theta;
                        shortened = true;
                        continue;
                    }
                }
                let factor = grow4(tol, p.err);
                // (as below: a piece whose estimate did not fall as a shorter one's should, or
                // at the shortest length, is kept)
                if p.err > tol && !(p.err > 0.5 * rejected || step <= min_frac) {
                    rejected = p.err;
                    frac = step * factor.min(0.8);
                    continue;
                }
                rejected = f64::NAN;
                accept_hermite(jt, mck.1, &mut w, &p, (h, fd))?;
                sum.n_steps = sum.n_steps.saturating_add(1);
                scale = (scale.0.max(w.x.abs()), scale.1.max(w.v.abs()));
                if !(w.x.is_finite() && w.v.is_finite()) {
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
            let ext = if h * rate > 2.0 { 0.0 } else { 1.0 / 3.0 };
            let Some(mut p) = piece(jt, mck, &w, inp, i, span, (scale, ext), opts) else {
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
            sum.n_iter = sum.n_iter.saturating_add(p.iters);
            if events < opts.max_events && p.theta < 1.0 {
                let min_piece = 1e-3 / step;
                if p.theta > min_piece && p.theta < 1.0 - min_piece {
                    events = events.saturating_add(1);
                    frac = step * p.theta;
                    shortened = true;
                    continue;
                }
            }
            let factor = crate::structure::grow(tol, p.err);
            if p.err > tol {
                // A shorter piece that did not cut the estimate as h³ would (by 2 for a
                // piece at most 0.8 as long): a stiff or non-smooth part the pair cannot
                // resolve; so is a piece at the shortest length. Keep the plain half steps
                // there (the trapezoidal rule is A-stable, its extrapolation is not).
                let stuck = p.err > 0.5 * rejected || step <= min_frac;
                if !stuck {
                    rejected = p.err;
                    frac = step * factor.min(0.8);
                    continue;
                }
                if let Some(q) = piece(jt, mck, &w, inp, i, span, (scale, 0.0), opts) {
                    sum.n_iter = sum.n_iter.saturating_add(q.iters);
                    p = q;
                }
            }
            // A piece kept plain: refining did not pay; the next piece tries a longer one and
            // is kept plain too unless its estimate halves (`rejected` carried on).
            let (factor, carried) = if p.ext == 0.0 {
                (2.0, p.err)
            } else {
                (factor, f64::NAN)
            };
            rejected = carried;
            accept(jt, mck.1, &mut w, &p)?;
            sum.n_steps = sum.n_steps.saturating_add(1);
            scale = (scale.0.max(w.x.abs()), scale.1.max(w.v.abs()));
            if !(w.x.is_finite() && w.v.is_finite()) {
                sum.status = Status::NonFinite {
                    time: inp.t[i] + tau1 * big_h,
                };
                return Ok(sum);
            }
            // an event-shortened piece says nothing of the length the error wants
            if !shortened {
                want = (h * factor).max(f64::MIN_POSITIVE);
            }
            shortened = false;
            tau = tau1;
            frac = next_frac(tau, want, big_h);
        }
        let next = i.saturating_add(1); // < nt
        record(jt, &w, out, next);
        sum.n_out = next.saturating_add(1);
    }
    Ok(sum)
}
