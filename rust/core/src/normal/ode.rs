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

use super::forcing::Forcing;
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
            let rate_h = model.rate() * (t_end - tc);
            let need = (rate_h / TAYLOR_RATE).ceil();
            if need <= TAYLOR_MAX_SUBSTEPS as f64 {
                let mut m = m_prop.max(need as usize).max(1);
                while m <= TAYLOR_MAX_SUBSTEPS {
                    attempts = attempts.saturating_add(m as u64);
                    if opts.max_steps > 0 && attempts > opts.max_steps {
                        return Ok(Outcome {
                            status: Status::MaxSteps { time: tc },
                            n_out: i.saturating_add(1),
                            stats,
                        });
                    }
                    if let Some((y1, order, v0)) =
                        taylor_interval(tay, &seg.c, seg.h, rate_h, m, y, opts, &mut stats)
                    {
                        delta[i] = y;
                        velocity[i] = v0;
                        y = y1;
                        stats.n_accepted = stats.n_accepted.saturating_add(m as u64);
                        // Keep the orders moderate: the work grows as the order squared.
                        m_prop = if order > 18 {
                            m.saturating_mul(2).min(TAYLOR_MAX_SUBSTEPS)
                        } else if order < 10 {
                            (m / 2).max(1)
                        } else {
                            m
                        };
                        continue 'intervals;
                    }
                    stats.n_rejected = stats.n_rejected.saturating_add(1);
                    m = m.saturating_mul(2);
                }
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
mod tests {
    use super::super::forcing::Interp;
    use super::super::model::Stiffness;
    use super::*;
    use std::f64::consts::PI;

    fn sine(n: usize, per: usize, w: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let dt = 2.0 * PI / w / per as f64;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let p = t.iter().map(|&v| 0.4 * (w * v).sin()).collect();
        let d = t.iter().map(|&v| 0.4 * w * (w * v).cos()).collect();
        (t, p, d)
    }

    #[test]
    fn kelvin_voigt_reaches_analytic_steady_state() {
        let (k, psi, w) = (1.206, 0.0887, 1.0);
        let m = ContactModel::new(Stiffness::Constant(k), psi, w).unwrap();
        // 512 samples per period: the cubic interpolant's own error (~(ωΔt)⁴/384) is then
        // small enough that δ' = (2πω/ψ)(p/k − δ), which amplifies δ errors by 2π/ψ, is
        // within 1e-8 too.
        let (t, p, d) = sine(512 * 6 + 1, 512, w);
        let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
        let mut y = vec![0.0; t.len()];
        let mut v = vec![0.0; t.len()];
        let opts = Options {
            rtol: 1e-10,
            atol: 1e-16,
            ..Options::default()
        };
        let out = simulate(&m, &fo, 0.0, &opts, &mut y, &mut v).unwrap();
        assert_eq!(out.status, Status::Success);
        let g = psi / (2.0 * PI);
        let amp = 0.4 / k / (1.0 + g * g).sqrt();
        let phi = g.atan();
        let (mut ed, mut ev) = (0.0_f64, 0.0_f64);
        for i in 512 * 2..t.len() {
            let exact = amp * (w * t[i] - phi).sin();
            ed = ed.max((y[i] - exact).abs() / amp);
            let vexact = amp * w * (w * t[i] - phi).cos();
            ev = ev.max((v[i] - vexact).abs() / (amp * w));
        }
        assert!(ed < 1e-8 && ev < 1e-8, "relative error {ed} {ev}");
    }

    #[test]
    fn order_four_convergence() {
        // Fixed large sample interval, tight tolerance off: compare two coarse tolerances.
        let m = ContactModel::new(
            Stiffness::Delta(vec![1.32596, 1.59811, 2.92127, 2.87416]),
            0.0887,
            1.0,
        )
        .unwrap();
        let (t, p, d) = sine(256 * 3 + 1, 256, 1.0);
        let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
        let run = |rtol: f64| {
            let mut y = vec![0.0; t.len()];
            let mut v = vec![0.0; t.len()];
            let o = Options {
                rtol,
                atol: rtol * 1e-3,
                ..Options::default()
            };
            let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
            (y, out)
        };
        let (yref, _) = run(1e-13);
        for rtol in [1e-6, 1e-8, 1e-10] {
            let (y, out) = run(rtol);
            let err = y
                .iter()
                .zip(&yref)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let scale = yref.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            assert!(
                err / scale < 50.0 * rtol,
                "rtol {rtol}: err {}",
                err / scale
            );
            assert!(out.stats.n_accepted >= (t.len() - 1) as u64);
        }
    }

    #[test]
    fn taylor_matches_rodas4_on_noisy_input_and_a_far_start() {
        // Table 2 centre curve (SI), 1 % noise on p, started 0.3 µm off equilibrium: the
        // Taylor route (split where the start-up needs it) against RODAS4, both at rtol 1e-11.
        let m = ContactModel::new(
            Stiffness::Delta(vec![1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30]),
            0.0887,
            1.0,
        )
        .unwrap();
        let (t, mut p, _) = sine(256 * 3 + 1, 256, 1.0);
        let mut state: u64 = 7;
        for v in &mut p {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            *v = *v * 1e6 + 0.4e6 * 0.01 * 3.46 * u;
        }
        let fo = Forcing::new(&t, &p, None, Interp::Cubic).unwrap();
        let scale = 0.4e6 / 1.32596e12;
        let o = Options {
            rtol: 1e-11,
            atol: 1e-11 * scale,
            ..Options::default()
        };
        let run = |method| {
            let (mut y, mut v) = (vec![0.0; t.len()], vec![0.0; t.len()]);
            let out = simulate_with(&m, &fo, 0.3e-6, &o, method, &mut y, &mut v).unwrap();
            assert_eq!(out.status, Status::Success);
            (y, v, out)
        };
        let (ya, va, oa) = run(Method::Auto);
        let (yr, vr, _) = run(Method::Rodas4);
        let dmax = yr.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let vmax = vr.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        for i in 0..t.len() {
            assert!((ya[i] - yr[i]).abs() < 1e-9 * dmax, "δ at {i}");
            assert!((va[i] - vr[i]).abs() < 1e-8 * vmax, "δ' at {i}");
        }
        assert_eq!(oa.stats.njev, 0, "every interval by Taylor steps");
        assert!(oa.stats.n_rejected > 0, "the far start was split");
    }

    #[test]
    fn stiff_limit_is_stable_on_the_sample_grid() {
        // ψ tiny: time constant 1e-6 of the sample interval; the L-stable method must not blow up.
        let m = ContactModel::new(Stiffness::Constant(2.0), 1e-7, 1.0).unwrap();
        let (t, p, d) = sine(513, 64, 1.0);
        let fo = Forcing::new(&t, &p, Some(&d), Interp::Cubic).unwrap();
        let mut y = vec![0.0; t.len()];
        let mut v = vec![0.0; t.len()];
        let out = simulate(&m, &fo, 1.0, &Options::default(), &mut y, &mut v).unwrap();
        assert_eq!(out.status, Status::Success);
        for i in 64..t.len() {
            assert!((y[i] - p[i] / 2.0).abs() < 1e-6);
        }
    }

    #[test]
    fn leaving_the_domain_returns_the_partial_solution() {
        // k_s(δ) = 1 + 5e6 δ vanishes at δ = -0.2e-6 inside the response; a loose tolerance
        // lets an accepted step land beyond it.
        let m = ContactModel::new(Stiffness::Delta(vec![1e12, 5e18]), 0.1, 1.0).unwrap();
        let w = 1.0;
        let per = 16;
        let n = 2 * per + 1;
        let dt = 2.0 * PI / w / per as f64;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let p: Vec<f64> = t.iter().map(|&v| 0.4e6 * (w * v).sin()).collect();
        let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
        let mut y = vec![f64::NAN; n];
        let mut v = vec![f64::NAN; n];
        let o = Options {
            rtol: 0.1,
            atol: 1e-8,
            ..Options::default()
        };
        let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
        let Status::NonPositiveStiffness {
            name, at, value, ..
        } = out.status
        else {
            panic!("expected NonPositiveStiffness, got {:?}", out.status);
        };
        assert_eq!(name, "delta");
        assert!(at < -0.2e-6 && value <= 0.0);
        assert_eq!(out.status.code(), -1);
        assert!(out.status.message().contains("not positive"));
        assert!(out.n_out > 1 && out.n_out < n);
        // Everything reported lies inside the domain and was computed.
        for &d in &y[..out.n_out] {
            assert!(d.is_finite() && 1e12 + 5e18 * d > 0.0);
        }
    }

    #[test]
    fn starting_outside_the_domain_is_an_error() {
        let m = ContactModel::new(Stiffness::Delta(vec![1e12, 5e18]), 0.1, 1.0).unwrap();
        let (t, p, _) = sine(33, 16, 1.0);
        let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
        let (mut y, mut v) = (vec![0.0; t.len()], vec![0.0; t.len()]);
        let r = simulate(&m, &fo, -1e-6, &Options::default(), &mut y, &mut v);
        assert!(matches!(r, Err(CoreError::NonPositiveStiffness { .. })));
    }

    #[test]
    fn max_steps_reports_failure() {
        let m = ContactModel::new(Stiffness::Constant(2.0), 0.1, 1.0).unwrap();
        let (t, p, _) = sine(100, 64, 1.0);
        let fo = Forcing::new(&t, &p, None, Interp::Linear).unwrap();
        let mut y = vec![0.0; t.len()];
        let mut v = vec![0.0; t.len()];
        let o = Options {
            max_steps: 10,
            ..Options::default()
        };
        let out = simulate(&m, &fo, 0.0, &o, &mut y, &mut v).unwrap();
        assert!(matches!(out.status, Status::MaxSteps { .. }));
        assert!(out.n_out < t.len());
    }
}
