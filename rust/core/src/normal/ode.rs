//! Integrator for the scalar contact ODE `δ' = f(t, δ)` driven by a sampled pressure.
//!
//! Method: RODAS4 (Hairer & Wanner, *Solving ODEs II*, §VI.4), a 6-stage Rosenbrock method of
//! order 4 with an embedded order-3 solution, L-stable and stiffly accurate. Rosenbrock
//! methods need one Jacobian per step and no Newton iteration; for a scalar ODE each stage is
//! one division. The stiff time constant ψ / (2π ω) is far below the sample interval of real
//! recordings (0.014 s against 0.025 s at 256 samples per period, ω = 1 1/s, ψ = 0.0887), where
//! explicit RK4 on the sample grid is at its stability limit; an L-stable method is not.
//!
//! Driving: the step never crosses a sample time, so the forcing seen by a step is one smooth
//! cubic (see [`super::forcing`]) and the solution is produced exactly at every sample (no
//! dense-output interpolation error). Within a sample interval the step adapts to
//! `|err| ≤ atol + rtol·|δ|` (err = the embedded estimate), with equal sub-steps.
//! Memory: the two output arrays only.
//!
//! The tests are in `ode/tests.rs`.

use super::forcing::{Forcing, Segment};
use super::model::ContactModel;
use super::taylor::Taylor;
use crate::error::{check_positive, CoreError};

/// RODAS4 coefficients in the `(A, C, γ_i, α_i)` form used by KPP / Hairer's `RODAS`
/// (`γ = 0.25`; `M = [A61..A65, 1]`, error = last stage).
mod rodas4 {
    pub const GAMMA: f64 = 0.25;
    pub const ALPHA: [f64; 6] = [0.0, 0.386, 0.210, 0.630, 1.0, 1.0];
    pub const GAMMA_I: [f64; 6] = [0.25, -0.1043, 0.1035, -0.036_200_000_000_000_23, 0.0, 0.0];
    pub const A: [[f64; 5]; 6] = [
        [0.0; 5],
        [1.544, 0.0, 0.0, 0.0, 0.0],
        [
            0.946_678_528_081_582_6,
            0.255_701_169_898_328_4,
            0.0,
            0.0,
            0.0,
        ],
        [
            3.314_825_187_068_521,
            2.896_124_015_972_201,
            0.998_641_913_997_781_7,
            0.0,
            0.0,
        ],
        [
            1.221_224_509_226_641,
            6.019_134_481_288_629,
            12.537_083_329_320_87,
            -0.687_886_036_105_895,
            0.0,
        ],
        [
            1.221_224_509_226_641,
            6.019_134_481_288_629,
            12.537_083_329_320_87,
            -0.687_886_036_105_895,
            1.0,
        ],
    ];
    pub const C: [[f64; 5]; 6] = [
        [0.0; 5],
        [-5.6688, 0.0, 0.0, 0.0, 0.0],
        [
            -2.430_093_356_833_875,
            -0.206_359_915_709_191_5,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.107_352_905_815_137_5,
            -9.594_562_251_023_355,
            -20.470_286_148_096_16,
            0.0,
            0.0,
        ],
        [
            7.496_443_313_967_647,
            -10.246_804_314_643_52,
            -33.999_903_528_199_05,
            11.708_908_932_061_6,
            0.0,
        ],
        [
            8.083_246_795_921_522,
            -7.981_132_988_064_893,
            -31.521_594_328_743_71,
            16.319_305_431_231_36,
            -6.058_818_238_834_054,
        ],
    ];
}

/// Tolerances and step controls.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub rtol: f64,
    pub atol: f64,
    /// First trial step (default: the first sample interval).
    pub first_step: Option<f64>,
    /// Upper bound on the number of step attempts (0: none).
    pub max_steps: u64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: 1e-14,
            first_step: None,
            max_steps: 0,
        }
    }
}

impl Options {
    pub fn validate(&self) -> Result<(), CoreError> {
        check_positive("rtol", self.rtol)?;
        check_positive("atol", self.atol)?;
        if self.rtol < 1e-14 {
            return Err(CoreError::InvalidParameter {
                name: "rtol",
                value: self.rtol,
                reason: "must be >= 1e-14 (below rounding error)",
            });
        }
        if let Some(h) = self.first_step {
            check_positive("first_step", h)?;
        }
        Ok(())
    }
}

/// Work counters, as scipy's `OdeResult` reports them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Right-hand-side evaluations.
    pub nfev: u64,
    /// Jacobian evaluations (one per step attempt).
    pub njev: u64,
    /// "Decompositions" (scalar: one per step attempt).
    pub nlu: u64,
    pub n_accepted: u64,
    pub n_rejected: u64,
}

/// Why a solve stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Status {
    /// Reached the last sample.
    Success,
    /// The step needed to meet the tolerance fell below rounding level.
    StepSizeTooSmall { time: f64, step: f64 },
    /// `max_steps` attempts were used up.
    MaxSteps { time: f64 },
    /// A step's implicit equation had no solution the iteration could find (fixed-grid
    /// integrator, [`super::grid::simulate_grid`]).
    NoConvergence { time: f64 },
    /// The solution reached a state where the stiffness `k_s` is not positive (the model is
    /// undefined there), at `name = at` (δ or p) with `k_s = value`.
    NonPositiveStiffness {
        time: f64,
        name: &'static str,
        at: f64,
        value: f64,
    },
}

impl Status {
    /// scipy-style status code: 0 success, -1 failure.
    pub fn code(&self) -> i32 {
        match self {
            Status::Success => 0,
            _ => -1,
        }
    }

    pub fn message(&self) -> String {
        match self {
            Status::Success => {
                "The solver successfully reached the end of the integration interval.".into()
            }
            Status::StepSizeTooSmall { time, step } => {
                format!("Required step size is less than spacing between numbers (step {step:e} at t = {time}).")
            }
            Status::MaxSteps { time } => format!("Maximum number of steps reached at t = {time}."),
            Status::NoConvergence { time } => format!(
                "The fixed-grid step did not converge at t = {time}: the model has no \
                 solution near the previous state there."
            ),
            Status::NonPositiveStiffness {
                time,
                name,
                at,
                value,
            } => format!(
                "The solution left the model's domain at t = {time:.6}: the stiffness is not \
                 positive (k_s = {value:.4e}) at {name} = {at:.4e}."
            ),
        }
    }
}

/// Result of a solve: how it ended, how many samples were written, the work done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    pub status: Status,
    /// Samples of `delta`/`velocity` that hold the solution (all of them on success).
    pub n_out: usize,
    pub stats: Stats,
}

/// One RODAS4 attempt from `(t, y)` over `h` inside one forcing segment.
/// Returns `(y_new, err_norm)`, or `None` if a stage left the model's domain (`k_s ≤ 0`).
#[inline]
fn rodas4_step(
    model: &ContactModel,
    seg: &super::forcing::Segment,
    t: f64,
    y: f64,
    f0: f64,
    jac: f64,
    dfdt: f64,
    h: f64,
    opts: &Options,
    stats: &mut Stats,
) -> Option<(f64, f64)> {
    use rodas4::{A, ALPHA, C, GAMMA, GAMMA_I};
    stats.njev = stats.njev.saturating_add(1);
    stats.nlu = stats.nlu.saturating_add(1);
    let g = 1.0 / (h * GAMMA) - jac;
    if !(g.is_finite() && g != 0.0) {
        return None;
    }
    let ginv = 1.0 / g;
    let hinv = 1.0 / h;
    let mut k = [0.0_f64; 6];
    k[0] = (f0 + h * GAMMA_I[0] * dfdt) * ginv;
    for i in 1..6 {
        let mut yi = y;
        let mut ci = 0.0;
        for j in 0..i {
            yi += A[i][j] * k[j];
            ci += C[i][j] * k[j];
        }
        let p = seg.value(t + ALPHA[i] * h);
        stats.nfev = stats.nfev.saturating_add(1);
        let fi = model.f(p, yi)?;
        k[i] = (fi + ci * hinv + h * GAMMA_I[i] * dfdt) * ginv;
    }
    // Stiffly accurate: y_new = Y6 + K6; the embedded solution is Y6, so err = K6.
    let mut y_new = y;
    for j in 0..5 {
        y_new += A[5][j] * k[j];
    }
    y_new += k[5];
    let scale = opts.atol + opts.rtol * y.abs().max(y_new.abs());
    let err = (k[5] / scale).abs();
    if !(y_new.is_finite() && err.is_finite()) {
        return None;
    }
    Some((y_new, err))
}

/// Integrate `model` driven by `forcing` from `delta0` at the first sample, writing δ and δ'
/// at every sample time into `delta` and `velocity` (each `forcing.len()` long).
///
/// Malformed input is an `Err` (a starting state `delta0` where `k_s ≤ 0` among it); a solve
/// that cannot meet the tolerance, or whose solution reaches a state where `k_s ≤ 0`, returns
/// `Ok(Outcome)` with a failure status and the `n_out` samples computed up to there.
pub fn simulate(
    model: &ContactModel,
    forcing: &Forcing<'_>,
    delta0: f64,
    opts: &Options,
    delta: &mut [f64],
    velocity: &mut [f64],
) -> Result<Outcome, CoreError> {
    simulate_with(model, forcing, delta0, opts, Method::Auto, delta, velocity)
}

/// Which step the solve takes inside a sample interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Taylor series (see [`super::taylor`]) where the interval's rate `r·Δt` allows a few
    /// sub-steps at most ([`TAYLOR_MAX_SUBSTEPS`] of `r·h ≤` [`TAYLOR_RATE`]); RODAS4 for a
    /// stiffer interval, or where the series does not converge (e.g. near `k_s = 0`).
    #[default]
    Auto,
    /// RODAS4 throughout (the method before issue 33).
    Rodas4,
}

/// Largest `r·h` of one Taylor sub-step when an interval is first split.
pub const TAYLOR_RATE: f64 = 4.0;
/// Most Taylor sub-steps per sample interval before the interval is left to RODAS4.
pub const TAYLOR_MAX_SUBSTEPS: usize = 64;

/// The forcing cubic `c` (in `s ∈ [0, 1]` of its interval) re-expanded on the sub-step
/// `s = s0 + σ v`, `v ∈ [0, 1]`.
#[inline]
fn shift_cubic(c: &[f64; 4], s0: f64, sigma: f64) -> [f64; 4] {
    let [c0, c1, c2, c3] = *c;
    let s2 = sigma * sigma;
    [
        c0 + s0 * (c1 + s0 * (c2 + s0 * c3)),
        sigma * (c1 + s0 * (2.0 * c2 + 3.0 * c3 * s0)),
        s2 * (c2 + 3.0 * c3 * s0),
        s2 * sigma * c3,
    ]
}

/// One sample interval (length `h`) by `m` equal Taylor steps from `y`: `δ` at its end, the
/// highest order used and `δ'` at its start, or `None` if a step failed.
#[inline]
fn taylor_interval(
    tay: &mut Taylor,
    c: &[f64; 4],
    h: f64,
    rate_h: f64,
    m: usize,
    mut y: f64,
    opts: &Options,
    stats: &mut Stats,
) -> Option<(f64, usize, f64)> {
    let sigma = 1.0 / m as f64;
    let rs = rate_h * sigma;
    let mut max_order = 0;
    let mut v0 = 0.0;
    for j in 0..m {
        let e = if m == 1 {
            *c
        } else {
            shift_cubic(c, j as f64 * sigma, sigma)
        };
        let tol = opts.atol + opts.rtol * y.abs();
        let (y1, order) = tay.step(&e, rs, y, tol)?;
        if j == 0 {
            v0 = tay.first_term() / (h * sigma); // dδ/dv at v = 0, v = (t − t_i)/(σ h)
        }
        stats.nfev = stats.nfev.saturating_add(order as u64);
        max_order = max_order.max(order);
        y = y1;
    }
    Some((y, max_order, v0))
}

/// What [`taylor_try`] made of an interval.
enum TaylorTry {
    /// Done: `δ` at the interval's end `y1` and `δ'` at its start `v0`.
    Done { y1: f64, v0: f64 },
    /// Left to the RODAS4 steps (too stiff for the sub-step limit, or every try failed).
    Fallback,
    /// The step budget `opts.max_steps` ran out.
    MaxSteps,
}

/// The interval from `tc` to `t_end` on `seg` by Taylor sub-steps from `y`: the proposed
/// count `m_prop` (at least what the rate needs), doubled after each failure up to
/// [`TAYLOR_MAX_SUBSTEPS`]; updates the proposal for the next interval, the attempts and the
/// statistics.
fn taylor_try(
    tay: &mut Taylor,
    model: &ContactModel,
    seg: &Segment,
    (tc, t_end): (f64, f64),
    y: f64,
    opts: &Options,
    (m_prop, attempts): (&mut usize, &mut u64),
    stats: &mut Stats,
) -> TaylorTry {
    let rate_h = model.rate() * (t_end - tc);
    let need = (rate_h / TAYLOR_RATE).ceil();
    if need <= TAYLOR_MAX_SUBSTEPS as f64 {
        let mut m = (*m_prop).max(need as usize).max(1);
        while m <= TAYLOR_MAX_SUBSTEPS {
            *attempts = attempts.saturating_add(m as u64);
            if opts.max_steps > 0 && *attempts > opts.max_steps {
                return TaylorTry::MaxSteps;
            }
            if let Some((y1, order, v0)) =
                taylor_interval(tay, &seg.c, seg.h, rate_h, m, y, opts, stats)
            {
                stats.n_accepted = stats.n_accepted.saturating_add(m as u64);
                // Keep the orders moderate: the work grows as the order squared.
                *m_prop = if order > 18 {
                    m.saturating_mul(2).min(TAYLOR_MAX_SUBSTEPS)
                } else if order < 10 {
                    (m / 2).max(1)
                } else {
                    m
                };
                return TaylorTry::Done { y1, v0 };
            }
            stats.n_rejected = stats.n_rejected.saturating_add(1);
            m = m.saturating_mul(2);
        }
    }
    TaylorTry::Fallback
}

/// [`simulate_with`]'s argument checks: the options, the output lengths, a finite `delta0`.
fn check_inputs(
    forcing: &Forcing<'_>,
    delta0: f64,
    opts: &Options,
    delta: &[f64],
    velocity: &[f64],
) -> Result<(), CoreError> {
    opts.validate()?;
    let n = forcing.len();
    crate::error::check_same_len("t", n, "delta (output)", delta.len())?;
    crate::error::check_same_len("t", n, "velocity (output)", velocity.len())?;
    if !delta0.is_finite() {
        return Err(CoreError::InvalidParameter {
            name: "delta0",
            value: delta0,
            reason: "must be finite",
        });
    }
    Ok(())
}

/// [`simulate`] with the interval method chosen (`Method::Rodas4`: the pre-issue-33 solver,
/// kept as the independent reference of the tests).
pub fn simulate_with(
    model: &ContactModel,
    forcing: &Forcing<'_>,
    delta0: f64,
    opts: &Options,
    method: Method,
    delta: &mut [f64],
    velocity: &mut [f64],
) -> Result<Outcome, CoreError> {
    check_inputs(forcing, delta0, opts, delta, velocity)?;
    let t = forcing.times();
    let mut stats = Stats::default();
    let mut y = delta0;
    let mut h_prop = opts.first_step.unwrap_or(t[1] - t[0]);
    let mut attempts: u64 = 0;
    let mut last_rejected = false;
    let mut taylor = match method {
        Method::Auto => Taylor::new(model.stiffness()),
        Method::Rodas4 => None,
    };
    // Taylor sub-steps per interval proposed for the next one.
    let mut m_prop: usize = 1;

    // Interval i runs from t[i] to t_end = t[i + 1].
    'intervals: for (i, &t_end) in t[1..].iter().enumerate() {
        let seg = forcing.segment(i);
        let mut tc = t[i];
        if let Some(tay) = taylor.as_mut() {
            let tried = taylor_try(
                tay,
                model,
                &seg,
                (tc, t_end),
                y,
                opts,
                (&mut m_prop, &mut attempts),
                &mut stats,
            );
            match tried {
                TaylorTry::Done { y1, v0 } => {
                    delta[i] = y;
                    velocity[i] = v0;
                    y = y1;
                    continue 'intervals;
                }
                TaylorTry::MaxSteps => {
                    return Ok(Outcome {
                        status: Status::MaxSteps { time: tc },
                        n_out: i.saturating_add(1),
                        stats,
                    });
                }
                TaylorTry::Fallback => {}
            }
        }
        // Output at the start of the interval: δ and δ' = f(t_i, δ_i).
        let (p_i, dp_i) = seg.value_deriv(tc);
        let e = match model.eval(p_i, dp_i, y) {
            Ok(e) => e,
            Err(e) if i > 0 => return stopped(e, tc, i, stats),
            Err(e) => return Err(e), // delta0 itself is outside the model's domain
        };
        stats.nfev = stats.nfev.saturating_add(1);
        delta[i] = y;
        velocity[i] = e.f;
        let (mut f0, mut jac, mut dfdt) = (e.f, e.jac, e.dfdt);
        let mut first = true;
        while tc < t_end {
            if !first {
                let (p, dp) = seg.value_deriv(tc);
                let e = match model.eval(p, dp, y) {
                    Ok(e) => e,
                    Err(e) => return stopped(e, tc, i.saturating_add(1), stats),
                };
                stats.nfev = stats.nfev.saturating_add(1);
                (f0, jac, dfdt) = (e.f, e.jac, e.dfdt);
            }
            first = false;
            loop {
                attempts = attempts.saturating_add(1);
                if opts.max_steps > 0 && attempts > opts.max_steps {
                    return Ok(Outcome {
                        status: Status::MaxSteps { time: tc },
                        n_out: i.saturating_add(1),
                        stats,
                    });
                }
                let remaining = t_end - tc;
                // Equal sub-steps that end exactly on the sample.
                let n_sub = (remaining / h_prop).ceil().max(1.0);
                let (h, lands) = if n_sub <= 1.0 {
                    (remaining, true)
                } else {
                    (remaining / n_sub, false)
                };
                if h <= 4.0 * f64::EPSILON * tc.abs().max(remaining) {
                    return Ok(Outcome {
                        status: Status::StepSizeTooSmall { time: tc, step: h },
                        n_out: i.saturating_add(1),
                        stats,
                    });
                }
                match rodas4_step(model, &seg, tc, y, f0, jac, dfdt, h, opts, &mut stats) {
                    Some((y_new, err)) if err <= 1.0 => {
                        stats.n_accepted = stats.n_accepted.saturating_add(1);
                        y = y_new;
                        tc = if lands { t_end } else { tc + h };
                        let mut fac = (0.9 / err.max(1e-10).sqrt().sqrt()).clamp(0.2, 6.0);
                        if last_rejected {
                            fac = fac.min(1.0);
                        }
                        last_rejected = false;
                        // A step shortened to land on a sample must not shrink the proposal.
                        h_prop = if lands { h_prop.max(h * fac) } else { h * fac };
                        break;
                    }
                    Some((_, err)) => {
                        stats.n_rejected = stats.n_rejected.saturating_add(1);
                        last_rejected = true;
                        h_prop = h * (0.9 / err.sqrt().sqrt()).clamp(0.1, 0.9);
                    }
                    None => {
                        stats.n_rejected = stats.n_rejected.saturating_add(1);
                        last_rejected = true;
                        h_prop = h * 0.25;
                    }
                }
            }
        }
    }
    finish(model, forcing, y, delta, velocity, stats)
}

/// The last sample of a solve that reached it: `δ` and `δ' = f(t, δ)` written there, the
/// outcome a success (or a stop if `δ` is outside the model's domain).
fn finish(
    model: &ContactModel,
    forcing: &Forcing<'_>,
    y: f64,
    delta: &mut [f64],
    velocity: &mut [f64],
    mut stats: Stats,
) -> Result<Outcome, CoreError> {
    let n = forcing.len();
    let t = forcing.times();
    let last = n.saturating_sub(1); // n >= 2 (Forcing::new)
    let p = forcing.values()[last];
    let e = match model.eval(p, forcing.sample_deriv(last), y) {
        Ok(e) => e,
        Err(e) => return stopped(e, t[last], last, stats),
    };
    stats.nfev = stats.nfev.saturating_add(1);
    delta[last] = y;
    velocity[last] = e.f;
    Ok(Outcome {
        status: Status::Success,
        n_out: n,
        stats,
    })
}

/// An accepted step left `y` where the model is undefined (`k_s ≤ 0`): the solve ends there
/// with the samples already written, as a failure status rather than an error.
fn stopped(e: CoreError, time: f64, n_out: usize, stats: Stats) -> Result<Outcome, CoreError> {
    match e {
        CoreError::NonPositiveStiffness { name, at, value } => Ok(Outcome {
            status: Status::NonPositiveStiffness {
                time,
                name,
                at,
                value,
            },
            n_out,
            stats,
        }),
        other => Err(other),
    }
}

#[cfg(test)]
mod tests;
