//! Linear structures with hysteretic joints (issue 10):
//! `M x'' + C x' + K x + Σ F_j = f + K r y + C r ẏ`, integrated by implicit Newmark (average
//! acceleration) with Newton iterations on the joint forces.
//!
//! - [`joint`]: the joint laws (Masing, Jenkins, Iwan, Bouc-Wen, Kelvin-Voigt, nonlinear normal
//!   contact stiffness), their tangents, events and stored energy.
//! - [`newmark`]: the integrator, sample-exact outputs, energy bookkeeping.
//! - [`dense`]: allocation-free LU for the Newton systems.
//! - `sdof`: the integrator specialised to one DOF (scalars throughout).
//!
//! This module holds what both integrators share (the structure, inputs, options, outputs)
//! and the one front, [`simulate`] / [`simulate_into`], that checks the inputs and picks the
//! integrator; `newmark` and `sdof` depend on it, not on each other.

pub(crate) mod dense;
pub mod joint;
pub mod newmark;
mod sdof;

pub use joint::{Joint, JointLaw, JointState, MasingCurve, Trial};

use crate::error::{check_finite, check_same_len, CoreError};

/// A linear structure with joints: dense row-major `n × n` matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    n: usize,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    joints: Vec<Joint>,
}

impl Structure {
    /// `m`, `c`, `k`: row-major `n × n`. `M` must be nonsingular (checked when simulating).
    pub fn new(
        n: usize,
        m: &[f64],
        c: &[f64],
        k: &[f64],
        joints: Vec<Joint>,
    ) -> Result<Self, CoreError> {
        if n == 0 {
            return Err(CoreError::Empty { name: "M" });
        }
        let nn = n.checked_mul(n).ok_or(CoreError::InvalidParameter {
            name: "n",
            value: n as f64,
            reason: "too many degrees of freedom",
        })?;
        for (name, a) in [("M", m), ("C", c), ("K", k)] {
            check_same_len(name, a.len(), "n*n", nn)?;
            check_finite(name, a)?;
        }
        for j in &joints {
            let bad = j.dof >= n || j.dof2.is_some_and(|d| d >= n || d == j.dof);
            if bad {
                return Err(CoreError::InvalidParameter {
                    name: "joint dof",
                    value: j.dof as f64,
                    reason: "joint degrees of freedom must be < n and distinct",
                });
            }
        }
        Ok(Self {
            n,
            m: m.to_vec(),
            c: c.to_vec(),
            k: k.to_vec(),
            joints,
        })
    }

    pub fn n(&self) -> usize {
        self.n
    }

    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }
}

/// Iteration controls.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Newton converges when the residual norm is below `rtol` times the size of the forces.
    pub rtol: f64,
    /// Newton iterations per step before the step is halved.
    pub max_iter: usize,
    /// Step halvings allowed per sample interval before the run stops with a failure.
    pub max_halvings: usize,
    /// Event sub-steps allowed per sample interval.
    pub max_events: usize,
    /// Error control: `Some(tol)` steps each sample interval in pieces whose step-doubling
    /// error estimate (a Newmark step against two half steps, per piece, relative to the
    /// largest displacement and velocity so far) is at most `tol`, and keeps the Richardson
    /// extrapolation of the pair (fourth order); `None`: fixed steps (`substeps` equal
    /// Newmark steps per sample interval, the second-order scheme of old).
    pub tol: Option<f64>,
    /// Equal Newmark steps per sample interval when `tol` is `None` (at least 1).
    pub substeps: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            max_iter: 30,
            max_halvings: 12,
            max_events: 16,
            tol: None,
            substeps: 1,
        }
    }
}

/// Why a simulation stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Status {
    Success,
    /// Newton did not converge even on the smallest sub-step.
    NoConvergence {
        time: f64,
        step: f64,
    },
    /// The state became NaN or infinite.
    NonFinite {
        time: f64,
    },
}

impl Status {
    /// scipy-style: 0 success, -1 failure.
    pub fn code(&self) -> i32 {
        match self {
            Status::Success => 0,
            _ => -1,
        }
    }

    pub fn message(&self) -> String {
        match self {
            Status::Success => "The integration reached the last sample.".into(),
            Status::NoConvergence { time, step } => format!(
                "Newton iterations did not converge at t = {time} (smallest step {step:e})."
            ),
            Status::NonFinite { time } => format!("The response became non-finite at t = {time}."),
        }
    }
}

/// Base motion: `(y, ẏ, K r, C r)`, displacement and velocity at the samples and the coupling
/// vectors (`n` each).
pub type Base<'a> = (&'a [f64], &'a [f64], &'a [f64], &'a [f64]);

/// Excitation sampled at the time points `t`.
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a> {
    pub t: &'a [f64],
    /// Row-major `len(t) × n` external forces, or `None`.
    pub force: Option<&'a [f64]>,
    /// `(y, ẏ, K r, C r)`: base displacement and velocity at `t`, coupling vectors (`n` each).
    pub base: Option<Base<'a>>,
}

/// Sampled response; arrays are row-major (sample-major), `n_out` rows are valid.
#[derive(Debug, Clone, PartialEq)]
pub struct Response {
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    /// `len(t) × n_joints` joint forces.
    pub joint_force: Vec<f64>,
    /// `len(t) × n_joints` cumulative work done on each joint.
    pub joint_work: Vec<f64>,
    /// `len(t) × n_joints` cumulative dissipated energy (work minus stored energy).
    pub joint_dissipated: Vec<f64>,
    /// Cumulative input work of the external and base forces.
    pub input_work: Vec<f64>,
    /// Cumulative energy dissipated by C.
    pub damping_work: Vec<f64>,
    pub status: Status,
    pub n_out: usize,
    /// Accepted steps (sample intervals plus event and halving sub-steps).
    pub n_steps: u64,
    /// Newton iterations in total.
    pub n_iter: u64,
}

/// Output buffers for [`simulate_into`] (row-major like [`Response`]'s arrays): `x`, `v`,
/// `a` of `len(t) × n`; the joint arrays `len(t) × n_joints`; the energies `len(t)`. An empty
/// buffer is an output the caller does not want (it is not computed). Rows past the run's
/// `n_out` are left as they were.
#[derive(Debug)]
pub struct Buffers<'a> {
    pub x: &'a mut [f64],
    pub v: &'a mut [f64],
    pub a: &'a mut [f64],
    pub joint_force: &'a mut [f64],
    pub joint_work: &'a mut [f64],
    pub joint_dissipated: &'a mut [f64],
    pub input_work: &'a mut [f64],
    pub damping_work: &'a mut [f64],
}

/// How a run ended (the non-array part of [`Response`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    pub status: Status,
    pub n_out: usize,
    pub n_steps: u64,
    pub n_iter: u64,
}

impl Summary {
    fn new() -> Self {
        Self {
            status: Status::Success,
            n_out: 0,
            n_steps: 0,
            n_iter: 0,
        }
    }
}

impl Response {
    /// Zeroed arrays for `nt` samples of `n` DOFs and `nj` joints (sizes already checked).
    fn zeros(nt: usize, total: usize, total_j: usize) -> Self {
        Self {
            x: vec![0.0; total],
            v: vec![0.0; total],
            a: vec![0.0; total],
            joint_force: vec![0.0; total_j],
            joint_work: vec![0.0; total_j],
            joint_dissipated: vec![0.0; total_j],
            input_work: vec![0.0; nt],
            damping_work: vec![0.0; nt],
            status: Status::Success,
            n_out: 0,
            n_steps: 0,
            n_iter: 0,
        }
    }

    fn buffers(&mut self) -> Buffers<'_> {
        Buffers {
            x: &mut self.x,
            v: &mut self.v,
            a: &mut self.a,
            joint_force: &mut self.joint_force,
            joint_work: &mut self.joint_work,
            joint_dissipated: &mut self.joint_dissipated,
            input_work: &mut self.input_work,
            damping_work: &mut self.damping_work,
        }
    }

    fn set(&mut self, sum: Summary) {
        self.status = sum.status;
        self.n_out = sum.n_out;
        self.n_steps = sum.n_steps;
        self.n_iter = sum.n_iter;
    }
}

/// A Hermite piece's Newton solve (see `sdof::adaptive`) ends after its update once the
/// residual is below this fraction of the forces ([`hermite_quick`]: less with an `rtol` tighter
/// than the default), without another joint evaluation (the joints
/// carried along their tangents, or tried anew where the update moved an end across a
/// reversal, a Masing closure or a slip point: [`JointLaw::holds`]). The residual left is of
/// the order of its square, 1e-4 of the forces, which the piece's two Hermite corrections then
/// remove with the Newmark end's own error (each re-solves the equilibrium; their fixed point
/// does not depend on where they start). Ending at `min(1e-3, √rtol)`, as the step-doubling
/// pairs do, took 1.8–2.2 Newton iterations per piece where this takes 1.0–1.3, at the same
/// error against the references of `benches/bench_structure.py --stepping` (stop 39).
pub(crate) const HERMITE_QUICK: f64 = 1e-2;

/// The residual (relative to the forces) below which a Hermite piece's Newton solve ends after
/// its update: [`HERMITE_QUICK`], or `1e3 √rtol` where that is less (the default `rtol =
/// 1e-10` gives `HERMITE_QUICK`; a tighter `rtol` still costs iterations and moves the result
/// toward the tightest solve's).
#[inline]
pub(crate) fn hermite_quick(rtol: f64) -> f64 {
    HERMITE_QUICK.min(1e3 * rtol.sqrt())
}

/// The factor on the piece length after an estimate `err` (`0.9 (tol / err)^(1/3)` within
/// `[0.2, 4]`; the cube root only where it matters).
#[inline]
pub(crate) fn grow(tol: f64, err: f64) -> f64 {
    if err * 88.0 <= tol {
        4.0
    } else {
        (0.9 * (tol / err).cbrt()).clamp(0.2, 4.0)
    }
}

/// A bound on the structure's fastest rate, `ω_max + ζω_max` in 1/s: the row-sum norms of
/// `M⁻¹ K` and `M⁻¹ C` with each joint's initial stiffness (and a Kelvin-Voigt joint's
/// damping) added, `√‖M⁻¹K‖ + ‖M⁻¹C‖ / 2`. Error control keeps the plain half steps (not their
/// extrapolation, which is not A-stable) for pieces longer than `2 /` this: the stiff part is
/// not resolved there, and the trapezoidal rule steps over it stably. `∞` if `M` is singular.
// Row-major n × n index arithmetic, n * n checked in `Structure::new`.
#[allow(clippy::arithmetic_side_effects)]
pub(crate) fn stiff_rate(s: &Structure) -> f64 {
    let n = s.n;
    let (mut k, mut c) = (s.k.clone(), s.c.clone());
    for j in &s.joints {
        let kj = j.law.initial_stiffness().abs();
        let cj = match j.law {
            JointLaw::KelvinVoigt { c, .. } => c.abs(),
            _ => 0.0,
        };
        for (mat, g) in [(&mut k, kj), (&mut c, cj)] {
            mat[j.dof * n + j.dof] += g;
            if let Some(q) = j.dof2 {
                mat[q * n + q] += g;
                mat[j.dof * n + q] -= g;
                mat[q * n + j.dof] -= g;
            }
        }
    }
    let mut lu = dense::Lu::new(n);
    if lu.factor(&s.m, n).is_err() {
        return f64::INFINITY;
    }
    // the row sums of |M⁻¹ A|, column by column
    let norm = |a: &[f64], lu: &dense::Lu| -> f64 {
        let mut rows = vec![0.0_f64; n];
        let mut col = vec![0.0_f64; n];
        for jc in 0..n {
            for (r, v) in col.iter_mut().enumerate() {
                *v = a[r * n + jc];
            }
            lu.solve(&mut col);
            for (acc, v) in rows.iter_mut().zip(&col) {
                *acc += v.abs();
            }
        }
        rows.iter().fold(0.0_f64, |m, v| m.max(*v))
    };
    norm(&k, &lu).sqrt() + 0.5 * norm(&c, &lu)
}

/// `(len(t)·n, len(t)·n_joints)`, the output sizes, or an error if they overflow.
fn sizes(s: &Structure, nt: usize) -> Result<(usize, usize), CoreError> {
    let too_many = CoreError::InvalidParameter {
        name: "t",
        value: nt as f64,
        reason: "too many samples",
    };
    let total = nt.checked_mul(s.n).ok_or(too_many.clone())?;
    let total_j = nt.checked_mul(s.joints.len()).ok_or(too_many)?;
    Ok((total, total_j))
}

/// Simulate `structure` under `inputs` from `(x0, v0)` at `t[0]` (joints start in their virgin
/// state at d = 0 and are loaded monotonically to the initial position).
///
/// Malformed input is an `Err`; a step that cannot converge ends the run with a failure
/// status and `n_out` valid samples (the response up to there).
pub fn simulate(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: &[f64],
    v0: &[f64],
    opts: &Options,
) -> Result<Response, CoreError> {
    let nt = inp.t.len();
    let (total, total_j) = sizes(s, nt)?;
    let mut out = Response::zeros(nt, total, total_j);
    let sum = simulate_into(s, inp, x0, v0, opts, &mut out.buffers())?;
    out.set(sum);
    Ok(out)
}

/// [`simulate`] writing the samples into the caller's buffers (e.g. arrays the caller then
/// hands on without a copy); their sizes must be as [`Buffers`] says.
pub fn simulate_into(
    s: &Structure,
    inp: &Inputs<'_>,
    x0: &[f64],
    v0: &[f64],
    opts: &Options,
    out: &mut Buffers<'_>,
) -> Result<Summary, CoreError> {
    let n = s.n;
    let nt = inp.t.len();
    if nt == 0 {
        return Err(CoreError::Empty { name: "t" });
    }
    crate::normal::forcing::check_time(inp.t)?;
    check_same_len("x0", x0.len(), "n", n)?;
    check_same_len("v0", v0.len(), "n", n)?;
    check_finite("x0", x0)?;
    check_finite("v0", v0)?;
    let (total, total_j) = sizes(s, nt)?;
    for (name, len, want) in [
        ("x buffer", out.x.len(), total),
        ("v buffer", out.v.len(), total),
        ("a buffer", out.a.len(), total),
        ("joint_force buffer", out.joint_force.len(), total_j),
        ("joint_work buffer", out.joint_work.len(), total_j),
        (
            "joint_dissipated buffer",
            out.joint_dissipated.len(),
            total_j,
        ),
        ("input_work buffer", out.input_work.len(), nt),
        ("damping_work buffer", out.damping_work.len(), nt),
    ] {
        if len != 0 {
            check_same_len(name, len, "output size", want)?;
        }
    }
    if let Some(f) = inp.force {
        check_same_len("force", f.len(), "len(t)*n", total)?;
        check_finite("force", f)?;
    }
    if let Some((y, yd, kr, cr)) = inp.base {
        check_same_len("base", y.len(), "t", nt)?;
        check_same_len("base_velocity", yd.len(), "t", nt)?;
        check_same_len("K r", kr.len(), "n", n)?;
        check_same_len("C r", cr.len(), "n", n)?;
        check_finite("base", y)?;
        check_finite("base_velocity", yd)?;
    }
    if !(opts.rtol.is_finite() && opts.rtol > 0.0) || opts.max_iter == 0 {
        return Err(CoreError::InvalidParameter {
            name: "rtol",
            value: opts.rtol,
            reason: "rtol must be > 0 and max_iter >= 1",
        });
    }
    if let Some(tol) = opts.tol {
        if !(tol.is_finite() && tol > 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "tol",
                value: tol,
                reason: "the error tolerance must be finite and > 0",
            });
        }
    }
    if opts.substeps == 0 {
        return Err(CoreError::InvalidParameter {
            name: "substeps",
            value: 0.0,
            reason: "substeps must be >= 1",
        });
    }
    if n == 1 {
        // One DOF: the same scheme on scalars (no matrices, no LU), generic over the joint set
        // (checked against the dense path by the tests in `sdof`).
        return sdof::simulate(s, inp, x0[0], v0[0], opts, out);
    }
    newmark::simulate_dense(s, inp, x0, v0, opts, out)
}
