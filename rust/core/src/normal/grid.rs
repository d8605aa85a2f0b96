//! Fixed-grid exponential integrator of the contact ODE (eq. 17) on the record's own samples.
//!
//! `δ' = a (n − δ)` with `a = 2π ω / ψ` and `n(t, δ) = p(t) / k_s` the quasi-static
//! displacement. Along the solution `N(t) = n(t, δ(t))` is smooth on the forcing's time
//! scale (the fast time constant `1/a` only damps), so the step from `t₀` to `t₁ = t₀ + h`
//! integrates the stiff linear part exactly and continues `N` by the cubic Hermite
//! interpolant of its values and slopes at both ends (`u = (t − t₀)/h`, `λ = a h`):
//!
//! `δ₁ = e^{−λ} δ₀ + λ ∫₀¹ e^{−λ(1−u)} N(u) du
//!      = e^{−λ} δ₀ + λ (W₀ N₀ + V₀ h N'₀ + W₁ N₁ + V₁ h N'₁)`
//!
//! with `W`, `V` combinations of the moments `I_k(λ) = ∫₀¹ e^{−λ(1−u)} uᵏ du`, and
//! `N' = ∂n/∂t + (∂n/∂δ) δ'`. `N₁`, `N'₁` depend on `δ₁`: the step solves that scalar
//! equation by Newton's method (exact derivative: quadratic convergence from a quadratic
//! extrapolation of the last states; one step when `k_s` does not depend on δ). An interval
//! whose iteration fails is retried in shorter steps.
//!
//! Error control: each step compares its cubic `N` with the quintic Hermite that also matches
//! `N''` (exact along the solution, from `p''` of the forcing's segment) at both ends. Their
//! difference `u²(1−u)²(α + βu)` is the leading term of the cubic's interpolation error; its
//! effect on δ₁ (the step's weights of that term, over the Newton derivative, which carries
//! the magnification `k_s / k_t` where the tangent stiffness `k_t` is small) is the local
//! error estimate. A sample interval with a step above [`ERROR_TOL`] of the displacement
//! scale is redone in twice as many steps (up to [`RETRY_FACTOR`] times as many), and the
//! next interval starts at that count (halved when well below the tolerance). Measured
//! against RODAS4 at rtol 1e-11 over the diagnosis' laws: the error stays within 1.1e-4 of
//! the displacement range, also where `k_s` dips to a third of `k`.
//!
//! Properties:
//! - For a constant `k_s`, `N = p / k` is the forcing's own cubic and the step is the exact
//!   solution under that forcing (the Kelvin-Voigt response the diagnosis fits).
//! - L-stable: the stiff decay is integrated exactly, so any `λ` is stable.
//! - The local error is the interpolation error of `N`, `O(h⁴ N'''')`, about
//!   `(ω h)⁴ / 384` of the displacement per step; every sample interval is split into at
//!   least `substeps` equal steps over the same cubic forcing, and more where the error
//!   estimate asks for them.
//! - Work: a few multiplications and 1–3 Newton iterations per step; the moments are computed
//!   once when the steps are equal (to 1e-9), else per interval.
//!
//! [`super::ode::simulate`] (RODAS4 with error control) is the accurate reference route.

use super::forcing::{Forcing, Interp, Segment};
use super::model::{ContactModel, Stiffness};
use super::ode::{Outcome, Stats, Status};
use crate::error::{check_same_len, CoreError};

/// Newton iterations per step at most: an interval with a step that needs more is retried in
/// shorter steps ([`RETRY_FACTOR`]), and ends the solve ([`Status::NoConvergence`]) if that
/// fails too.
const MAX_NEWTON: u32 = 20;

/// Steps equal to this fraction share one set of weights.
const UNIFORM_STEPS: f64 = 1e-9;

/// The start-up layer lasts while `a (t − t0)` is below this (`e^{−40}` is 4e-18)...
const LAYER_SPAN: f64 = 40.0;
/// ... and its steps have `λ = a h` at most this ...
const LAYER_LAMBDA: f64 = 0.25;
/// ... in at most this many steps per sample interval.
const LAYER_MAX_SUBSTEPS: f64 = 4096.0;

/// A step whose cubic `N` has a u³ term above this fraction of the displacement scale is
/// retried in shorter steps (see `simulate_grid`).
const JUMP: f64 = 0.1;

/// A step whose error estimate (see `advance`) is above this fraction of the displacement
/// scale is retried in shorter steps. The error over a record stays within about 4 times
/// this (measured: 1.1e-4 of the range at most over 979 random laws and records; 5.1e-4 at
/// 1e-4; 3.7e-5 at 1e-5, which takes 1.5 times the steps on a noisy record at 111 samples per
/// period where this takes 1.02-1.1 times).
const ERROR_TOL: f64 = 3e-5;

/// After an interval that needed more steps than asked, the next one starts with as many,
/// or half as many when its worst estimate was below this fraction of the tolerance.
const COARSEN: f64 = 1.0 / 32.0;

/// An interval whose iteration fails is retried in up to this many times as many steps.
const RETRY_FACTOR: f64 = 64.0;
/// Steps per sample interval at most.
const MAX_SUBSTEPS: f64 = 1_048_576.0;

/// Largest step exponent used: `e^{−600}` has forgotten the initial state (no underflow).
const MAX_LAMBDA: f64 = 600.0;

/// `I_k(λ) = ∫₀¹ e^{−λ(1−u)} uᵏ du`, k = 0..3: the recursion `I_k = (1 − k I_{k−1}) / λ` from
/// `I₀ = (1 − e^{−λ})/λ` where `λ ≥ 2` (an error grows by at most 3/2 per step), else the
/// series `k! Σ_j (−λ)^j / (k+j+1)!` (30 terms: `2^30 / 31!` is below 1e-24).
pub fn exp_moments(lam: f64) -> [f64; 4] {
    let mut out = [0.0; 4];
    if lam >= 2.0 {
        let mut i_k = -(-lam).exp_m1() / lam;
        out[0] = i_k;
        for (k, o) in (1_u32..).zip(out.iter_mut().skip(1)) {
            i_k = (1.0 - f64::from(k) * i_k) / lam;
            *o = i_k;
        }
    } else {
        for (k, o) in (0_u32..).zip(out.iter_mut()) {
            // term_0 = k! / (k+1)!, term_j = term_{j-1} (−λ) / (k+j+1)
            let kf = f64::from(k);
            let mut term = 1.0 / (kf + 1.0);
            let mut acc = term;
            for j in 1_u32..30 {
                term *= -lam / (kf + f64::from(j) + 1.0);
                acc += term;
            }
            *o = acc;
        }
    }
    out
}

/// `λ ∫₀¹ e^{−λ s} s² (1 − s)^j ds` for j = 2, 3 (`s = 1 − u`): the weights of the step's
/// error estimate. Series `Σ_i (−λ)^i / i! · B_i` (`B_i = ∫ s^{2+i} (1−s)^j ds`, a Beta
/// function) where `λ < 2`; else the moments `K_k = ∫₀¹ e^{−λ s} s^k ds` by the upward
/// recursion `K_k = (k K_{k−1} − e^{−λ}) / λ` (an error grows by at most `k/λ ≤ 5/2` per
/// step), whose combination does not cancel for large λ (`K_k ≈ k!/λ^{k+1}`).
fn error_moments(lam: f64) -> [f64; 2] {
    if lam < 2.0 {
        // B(a, b) = (a−1)! (b−1)! / (a+b−1)!, a = 3 + i, b = j + 1
        let mut out = [0.0; 2];
        for (j, o) in [2_u32, 3].into_iter().zip(out.iter_mut()) {
            let jf = f64::from(j);
            // B_0 = 2! j! / (j+3)!, B_{i+1} = B_i (3+i) / (j+4+i); term_i = B_i (−λ)^i / i!
            let mut term = 2.0 * (1..=j).map(f64::from).product::<f64>()
                / (1..=j.saturating_add(3)).map(f64::from).product::<f64>();
            let mut acc = term;
            for i in 0_u32..30 {
                let fi = f64::from(i);
                term *= -lam / (fi + 1.0) * (3.0 + fi) / (jf + 4.0 + fi);
                acc += term;
            }
            *o = lam * acc;
        }
        return out;
    }
    let e = (-lam.min(MAX_LAMBDA)).exp();
    let mut k = [0.0; 6];
    k[0] = -(-lam).exp_m1() / lam;
    let mut prev = k[0];
    for (i, ki) in k.iter_mut().enumerate().skip(1) {
        *ki = (i as f64 * prev - e) / lam;
        prev = *ki;
    }
    [
        lam * (k[2] - 2.0 * k[3] + k[4]),
        lam * (k[2] - 3.0 * k[3] + 3.0 * k[4] - k[5]),
    ]
}

/// The step's constants: `e^{−λ}`, `λ W₀, λ V₀, λ W₁, λ V₁`, and the error weights
/// `ea = λ ∫ e^{−λ(1−u)} u²(1−u)² du`, `eb = λ ∫ e^{−λ(1−u)} u³(1−u)² du`.
#[derive(Debug, Clone, Copy)]
struct Weights {
    decay: f64,
    w0: f64,
    v0: f64,
    w1: f64,
    v1: f64,
    ea: f64,
    eb: f64,
}

impl Weights {
    fn new(lam: f64) -> Self {
        let l = lam.min(MAX_LAMBDA);
        let [i0, i1, i2, i3] = exp_moments(lam);
        let [ea, eb] = error_moments(lam);
        Self {
            decay: (-l).exp(),
            w0: lam * (i0 - 3.0 * i2 + 2.0 * i3),
            v0: lam * (i1 - 2.0 * i2 + i3),
            w1: lam * (3.0 * i2 - 2.0 * i3),
            v1: lam * (i3 - i2),
            ea,
            eb,
        }
    }
}

/// `N`, `N'` and their derivatives with respect to δ at `(p, dp/dt, δ)`.
#[derive(Debug, Clone, Copy)]
struct Quasi {
    n: f64,
    /// `N'`, per second
    m: f64,
    dn: f64,
    dm: f64,
    /// `δ' = a (n − δ)`.
    f: f64,
    /// `1/k_s` and `k_s'`, `k_s''` for a δ-dependent `k_s` (zero otherwise), for
    /// [`curvature`].
    ik: f64,
    k1: f64,
    k2: f64,
}

/// `n = p / k_s`, `N' = ∂n/∂t + ∂n/∂δ · δ'` and their exact derivatives in δ. Only a
/// δ-dependent stiffness makes them depend on δ (then `n = p / k(δ)`); for a constant or
/// pressure-dependent one the step's equation is linear in δ₁.
#[inline]
fn quasi(model: &ContactModel, p: f64, dp: f64, delta: f64) -> Result<Quasi, CoreError> {
    let a = model.rate();
    if let Stiffness::Delta(c) = model.stiffness() {
        let (k, k1, k2) = horner2(c, delta);
        if !(k > 0.0 && k.is_finite()) {
            return Err(CoreError::NonPositiveStiffness {
                name: "delta",
                at: delta,
                value: k,
            });
        }
        let ik = 1.0 / k;
        let n = p * ik;
        let f = a * (n - delta);
        let dn = -n * k1 * ik; // ∂n/∂δ = −p k'/k²
        let dn2 = -p * (k2 - 2.0 * k1 * k1 * ik) * ik * ik; // ∂²n/∂δ²
        let nt = dp * ik; // ∂n/∂t
        let ntd = -dp * k1 * ik * ik; // ∂²n/∂t∂δ
        return Ok(Quasi {
            n,
            m: nt + dn * f,
            dn,
            dm: ntd + dn2 * f + dn * a * (dn - 1.0),
            f,
            ik,
            k1,
            k2,
        });
    }
    let e = model.eval(p, dp, delta)?;
    let nt = e.dfdt / a;
    Ok(Quasi {
        n: e.f / a + delta,
        m: nt,
        dn: 0.0,
        dm: 0.0,
        f: e.f,
        ik: 0.0,
        k1: 0.0,
        k2: 0.0,
    })
}

/// `k`, `k'`, `k''` of the polynomial `c` at `x` in one Horner pass.
#[inline]
fn horner2(c: &[f64], x: f64) -> (f64, f64, f64) {
    let (mut k, mut k1, mut k2) = (0.0, 0.0, 0.0);
    for &ci in c.iter().rev() {
        k2 = k2 * x + 2.0 * k1;
        k1 = k1 * x + k;
        k = k * x + ci;
    }
    (k, k1, k2)
}

/// `N''` along the solution at `(p, dp/dt, d²p/dt²)`, `q` the values there (`N'` in
/// `q.m`, `δ'` in `q.f`): with `n = p g(δ)`, `g = 1/k_s`,
/// `N'' = p'' g + 2 p' g' δ' + p g'' δ'² + p g' δ''` and `δ'' = a (N' − δ')`; for a
/// pressure-dependent `k_s`, `N = n(p)` and `N'' = n_pp p'² + n_p p''`. Not finite where
/// `k_s ≤ 0` (the caller takes that as a failed estimate).
#[inline(always)]
fn curvature(model: &ContactModel, p: f64, dp: f64, dp2: f64, q: &Quasi) -> f64 {
    match model.stiffness() {
        Stiffness::Constant(k) => dp2 / k,
        Stiffness::Delta(_) => {
            let ik2 = q.ik * q.ik;
            let g1 = -q.k1 * ik2;
            let g2 = (2.0 * q.k1 * q.k1 * q.ik - q.k2) * ik2;
            let d2 = model.rate() * (q.m - q.f);
            dp2 * q.ik + 2.0 * dp * g1 * q.f + p * (g2 * q.f * q.f + g1 * d2)
        }
        Stiffness::Pressure(c) => {
            let (k, k1, k2) = horner2(c, p);
            let ik = 1.0 / k;
            let np = (k - p * k1) * ik * ik;
            let npp = -(p * k2 * k + 2.0 * k1 * (k - p * k1)) * ik * ik * ik;
            npp * dp * dp + np * dp2
        }
    }
}

/// `d²p/dt²` of the segment at `t`.
#[inline]
fn second_deriv(seg: &Segment, t: f64) -> f64 {
    let s = (t - seg.t0) * seg.inv_h;
    (2.0 * seg.c[2] + 6.0 * s * seg.c[3]) * seg.inv_h * seg.inv_h
}

/// The integration state between steps: δ and its end values, and the predictor's history
/// (the states before the last two, how many equal steps led to them).
#[derive(Debug, Clone, Copy)]
struct State {
    y: f64,
    q0: Quasi,
    /// `N''` at `y` under the current segment's `p''`, and `p`, `dp/dt` there.
    m2: f64,
    p: f64,
    dp: f64,
    y_prev: f64,
    y_prev2: f64,
    h_last: f64,
    equal_run: u32,
}

/// `n` equal steps of length `h` over one sample interval `[t0, t_end]` of the forcing `seg`.
/// `Ok(Ok(worst))`: done, `worst` the largest over the steps of the error estimate over
/// `etol` and of the cubic `N`'s third-order term over `jump` (a fast transient the steps do
/// not follow): above 1 (or NaN) the interval is not resolved. `Ok(Err(status))` when a
/// step's iteration fails (the state is then partly advanced).
///
/// The error estimate: the step's cubic Hermite `N` against the quintic Hermite that also
/// matches `N''` at both ends (the same data and one derivative more). Their difference is
/// `u²(1−u)²(α + βu)`; it changes the step's right-hand side by `α ea + β eb`, and δ₁ by that
/// over the Newton derivative `dg` (which carries the δ-dependence of `N₁`: a small
/// tangent stiffness magnifies the error by `k_s / k_t`).
fn advance(
    model: &ContactModel,
    seg: &Segment,
    t0: f64,
    t_end: f64,
    n: usize,
    h: f64,
    wt: &Weights,
    tol: f64,
    inv_etol: f64,
    inv_jump: f64,
    st: &mut State,
    stats: &mut Stats,
) -> Result<Result<f64, Status>, CoreError> {
    let a = model.rate();
    let mut worst = 0.0_f64;
    // a constant k_s makes N the forcing's cubic over k: the step is exact, nothing to estimate
    let estimate = !matches!(model.stiffness(), Stiffness::Constant(_));
    // N'' at the interval's start under this segment's p'' (p and p' are continuous)
    if estimate {
        st.m2 = curvature(model, st.p, st.dp, second_deriv(seg, t0), &st.q0);
    }
    for s in 1..=n {
        let t1 = if s == n { t_end } else { t0 + s as f64 * h };
        let (p1, dp1) = seg.value_deriv(t1);
        let y = st.y;
        let base = wt.decay * y + wt.w0 * st.q0.n + wt.v0 * h * st.q0.m;
        // Newton from the quadratic extrapolation of the last three states when the steps
        // are equal (off by O(h³)), else from the last state
        let mut y1 = if st.equal_run >= 2 && h == st.h_last {
            3.0 * (y - st.y_prev) + st.y_prev2
        } else {
            y
        };
        let mut iters = 0_u32;
        let mut prev = f64::INFINITY; // the previous Newton step's size
        let (mut q1, mut y_it, mut inv_dg);
        loop {
            y_it = y1;
            q1 = match quasi(model, p1, dp1, y1) {
                Ok(q) => q,
                Err(CoreError::NonPositiveStiffness { name, at, value }) => {
                    return Ok(Err(Status::NonPositiveStiffness {
                        time: t1,
                        name,
                        at,
                        value,
                    }))
                }
                Err(e) => return Err(e),
            };
            stats.nfev = stats.nfev.saturating_add(1);
            let g = y1 - base - wt.w1 * q1.n - wt.v1 * h * q1.m;
            inv_dg = 1.0 / (1.0 - wt.w1 * q1.dn - wt.v1 * h * q1.dm);
            let step = g * inv_dg;
            if !step.is_finite() {
                return Ok(Err(Status::NoConvergence { time: t1 }));
            }
            y1 -= step;
            iters = iters.saturating_add(1);
            // converged: the step is below the tolerance (or the rounding of the step's terms),
            // or the equation is linear in δ₁ (k_s independent of δ: the step was exact), or
            // the quadratic convergence puts the next step, about |s|³/|s_prev|², below it
            let floor = 8.0 * f64::EPSILON * (y.abs() + q1.n.abs() + y1.abs());
            let eps = tol.max(floor);
            let s_abs = step.abs();
            let linear = q1.dn == 0.0 && q1.dm == 0.0;
            if s_abs <= eps
                || linear
                || (prev.is_finite()
                    && 4.0 * s_abs < prev
                    && s_abs * s_abs * s_abs <= eps * prev * prev)
            {
                break;
            }
            prev = s_abs;
            if iters >= MAX_NEWTON {
                return Ok(Err(Status::NoConvergence { time: t1 }));
            }
        }
        // the state carried on: the end values at the last iterate, moved to the converged δ
        // to first order (the last Newton step is small: its square is below the tolerance)
        let dy = y1 - y_it;
        q1.n += q1.dn * dy;
        q1.m += q1.dm * dy;
        q1.f = a * (q1.n - y1);
        // the step's cubic N = N₀ + h N'₀ u + c2 u² + c3 u³ (c3 is O(h³ N''') on a smooth
        // solution), and the quintic's extra term u²(1−u)²(α + βu) from N'' at both ends
        let c3 = 2.0 * (st.q0.n - q1.n) + h * (st.q0.m + q1.m);
        let mut ratio = c3.abs() * inv_jump;
        let mut m2_1 = 0.0;
        if estimate {
            m2_1 = curvature(model, p1, dp1, second_deriv(seg, t1), &q1);
            let c2 = 3.0 * (q1.n - st.q0.n) - h * (2.0 * st.q0.m + q1.m);
            let hh = h * h;
            let alpha = 0.5 * hh * st.m2 - c2;
            let beta = 0.5 * hh * m2_1 - c2 - 3.0 * c3 - alpha;
            let est = (alpha * wt.ea + beta * wt.eb) * inv_dg;
            ratio = ratio.max(est.abs() * inv_etol);
        }
        // NaN (k_s <= 0 at the converged end, an overflow) counts as unresolved and stays
        if ratio > worst || ratio.is_nan() {
            worst = ratio;
        }
        stats.n_accepted = stats.n_accepted.saturating_add(1);
        st.equal_run = if h == st.h_last {
            st.equal_run.saturating_add(1)
        } else {
            1
        };
        st.h_last = h;
        st.y_prev2 = st.y_prev;
        st.y_prev = y;
        st.y = y1;
        st.q0 = q1;
        st.m2 = m2_1;
        st.p = p1;
        st.dp = dp1;
    }
    Ok(Ok(worst))
}

/// The shortest and longest sample step of `t`.
fn step_range(t: &[f64]) -> (f64, f64) {
    t.windows(2).fold((f64::INFINITY, 0.0_f64), |(lo, hi), w| {
        let d = w[1] - w[0];
        (lo.min(d), hi.max(d))
    })
}

/// The checks of [`simulate_grid`]'s options.
fn check_options(delta0: f64, substeps: usize, tol: f64) -> Result<(), CoreError> {
    if !delta0.is_finite() {
        return Err(CoreError::InvalidParameter {
            name: "delta0",
            value: delta0,
            reason: "must be finite",
        });
    }
    if substeps == 0 || substeps as f64 > MAX_SUBSTEPS {
        return Err(CoreError::InvalidParameter {
            name: "substeps",
            value: substeps as f64,
            reason: "must be between 1 and 2^20",
        });
    }
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(CoreError::InvalidParameter {
            name: "tol",
            value: tol,
            reason: "must be positive and finite",
        });
    }
    Ok(())
}

/// Substeps of an interval in the start-up layer (`a_span = a · span`): enough for
/// `λ <= LAYER_LAMBDA`, at least `m_sub`, at most `LAYER_MAX_SUBSTEPS`.
fn layer_substeps(a_span: f64, m_sub: f64) -> f64 {
    let need = (a_span / LAYER_LAMBDA).ceil();
    if need > m_sub {
        need.min(LAYER_MAX_SUBSTEPS)
    } else {
        m_sub
    }
}

/// Step and weights of `m_i` equal steps over `span`: those of the last refined interval
/// when the record's steps are uniform and it had as many (kept in `cache`).
fn refined_weights(
    cache: &mut Option<(f64, Weights)>,
    uniform: bool,
    a: f64,
    span: f64,
    m_i: f64,
) -> (f64, Weights) {
    if let Some((m_w, w_w)) = cache.filter(|&(m_w, _)| uniform && m_w == m_i) {
        return (span / m_w, w_w);
    }
    let wt = Weights::new(a * span / m_i);
    if uniform {
        *cache = Some((m_i, wt));
    }
    (span / m_i, wt)
}

/// Integrate `model` driven by `forcing` from `delta0` at the first sample on the samples'
/// own grid (each interval in `substeps` equal steps), writing δ and δ' at every sample into
/// `delta` and `velocity`.
///
/// `tol` is the absolute tolerance (m) of each step's Newton iteration. Malformed input is an
/// `Err`; a solution that reaches `k_s ≤ 0` or a step whose iteration does not converge ends
/// the solve with a failure status and the samples computed up to there, as
/// [`super::ode::simulate`] does. `stats.n_accepted` counts steps, `stats.nfev` model
/// evaluations.
pub fn simulate_grid(
    model: &ContactModel,
    forcing: &Forcing<'_>,
    delta0: f64,
    substeps: usize,
    tol: f64,
    delta: &mut [f64],
    velocity: &mut [f64],
) -> Result<Outcome, CoreError> {
    let n = forcing.len();
    check_same_len("t", n, "delta (output)", delta.len())?;
    check_same_len("t", n, "velocity (output)", velocity.len())?;
    check_options(delta0, substeps, tol)?;
    let t = forcing.times();
    let a = model.rate();
    let m_sub = substeps as f64;
    // equal steps: one set of weights for the whole record. Sample times stored as
    // `k / fs` differ from equal steps by rounding (1e-11 of a step at 1e6 samples); a step
    // 1e-9 off changes the weights by that fraction, far below the method's error
    let (lo, hi) = step_range(t);
    let uniform = hi - lo <= UNIFORM_STEPS * hi;
    let h_uni = 0.5 * (lo + hi) / m_sub;
    // the displacement scale max|p| / k_s(0), and the largest u³ term of a step's cubic N
    // taken as resolved: smooth records give (ω h)³/6 of the scale, 1e-4 at 64 samples per
    // period, and 0.3 % noise on p about 1e-2
    let p_max = forcing.values().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let scale = p_max / model.k_s(0.0, 0.0).abs();
    let jump = JUMP * scale;
    let etol = ERROR_TOL * scale;
    let w_uni = Weights::new(a * h_uni);

    let mut stats = Stats::default();
    let (p_first, dp_first) = forcing.segment(0).value_deriv(t[0]);
    let q_first = quasi(model, p_first, dp_first, delta0)?;
    stats.nfev = 1;
    delta[0] = delta0;
    velocity[0] = q_first.f;
    let mut st = State {
        y: delta0,
        q0: q_first,
        m2: 0.0,
        p: p_first,
        dp: dp_first,
        y_prev: delta0,
        y_prev2: delta0,
        h_last: 0.0,
        equal_run: 0,
    };

    let pv = forcing.values();
    let cubic = forcing.interp() == Interp::Cubic;
    let delta_law = matches!(model.stiffness(), Stiffness::Delta(_));
    let mut slope0 = forcing.slope(0);
    // equal steps and no given dp/dt: the interior slopes of numpy.gradient are central
    // differences (the general three-point formula with equal spacing, without its divisions)
    let inv_2h = 0.5 / (0.5 * (lo + hi));
    let central = uniform && !forcing.has_dpdt();
    let last = n.saturating_sub(1);
    // how many times the asked steps the last interval needed (a power of two)
    let mut refine = 1.0_f64;
    // the weights of the last refined equal steps
    let mut w_refined: Option<(f64, Weights)> = None;
    for (i, w) in t.windows(2).enumerate() {
        let span = w[1] - w[0];
        // the cubic Hermite segment (Forcing::segment), the slope at its start carried over
        let j = i.saturating_add(1);
        let slope1 = if central && j < last {
            (pv[j.saturating_add(1)] - pv[i]) * inv_2h
        } else {
            forcing.slope(j)
        };
        let seg = if cubic {
            Segment::hermite(w[0], span, pv[i], pv[j], slope0, slope1)
        } else {
            forcing.segment(i)
        };
        slope0 = slope1;
        // the start-up layer: a δ0 off the slow manifold decays as e^{−a (t − t0)}, which a
        // cubic N cannot follow over a step of λ ≫ 1; its steps are cut to λ ≤ LAYER_LAMBDA
        // (only a δ-dependent k_s puts δ into N; otherwise N is the forcing's cubic over p)
        let in_layer = delta_law && a * (w[0] - t[0]) < LAYER_SPAN;
        let m_base = if in_layer {
            layer_substeps(a * span, m_sub)
        } else {
            m_sub
        };
        // an interval whose iteration fails (a poor start far from the step's solution, an
        // iterate where k_s <= 0), whose error estimate is above the tolerance or whose N
        // jumps (a near-singular k_s: δ moves by much of its range within a sample) is
        // retried from its start in twice as many steps, up to RETRY_FACTOR times as many;
        // a failure there ends the solve
        let saved = st;
        let cap = (m_base * RETRY_FACTOR).min(MAX_SUBSTEPS);
        let mut m_i = (m_base * refine).min(cap);
        loop {
            let (h, wt) = if uniform && m_i == m_sub {
                (h_uni, w_uni)
            } else {
                refined_weights(&mut w_refined, uniform, a, span, m_i)
            };
            let out = advance(
                model,
                &seg,
                w[0],
                w[1],
                m_i as usize,
                h,
                &wt,
                tol,
                1.0 / etol,
                1.0 / jump,
                &mut st,
                &mut stats,
            )?;
            match out {
                Ok(worst) if worst <= 1.0 => {
                    refine = if worst < COARSEN {
                        (0.5 * m_i / m_base).max(1.0)
                    } else {
                        m_i / m_base
                    };
                    break;
                }
                Ok(_) if 2.0 * m_i > cap => {
                    refine = m_i / m_base;
                    break; // as fine as it goes: keep it
                }
                Err(status) if 2.0 * m_i > cap => {
                    return Ok(Outcome {
                        status,
                        n_out: j,
                        stats,
                    });
                }
                Ok(_) | Err(_) => {
                    stats.n_rejected = stats.n_rejected.saturating_add(1);
                    st = saved;
                    m_i *= 2.0;
                }
            }
        }
        delta[j] = st.y;
        velocity[j] = st.q0.f;
    }
    Ok(Outcome {
        status: Status::Success,
        n_out: n,
        stats,
    })
}

#[cfg(test)]
mod tests;
