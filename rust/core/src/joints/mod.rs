//! Joint laws driven by displacement, `x(t) -> F(t)`, with exact non-local memory.
//!
//! Every law implements [`Law`]: `start(x0)` gives the relaxed state at displacement `x0`,
//! `step(state, dt, x)` advances it to the next sample and returns the force. Conventions
//! (shared with the plain-Python reference `contactlab/joints/_reference.py`, which these
//! kernels equal to rounding):
//!
//! - the displacement between two samples is a straight line in time, so a rate-dependent law
//!   sees the constant velocity `(x_n - x_{n-1}) / dt` over a step and is integrated exactly
//!   along it; `dt = None` is the quasi-static first step from `x0` (velocity 0 in the rate
//!   terms) and every step of a rate-independent law driven without times;
//! - a step with `dx == 0` changes no rate-independent state.
//!
//! Laws: [`jenkins::Jenkins`], [`maxwell::MaxwellSlip`], [`maxwell::Gms`] (generalised
//! Maxwell-slip), [`iwan::MasingStack`] (continuous Iwan models: uniform, Segalman's power law,
//! the exponential Masing curve), [`dahl::Dahl`], [`lugre::LuGre`], [`boucwen::BoucWen`],
//! [`compose::KelvinVoigt`], [`compose::Parallel`], [`compose::Series`] and
//! [`backlash::Backlash`]; [`AnyLaw`] is the tree of them a user composes, [`Operator`] a law
//! with its carried state for streamed chunks.

pub mod backlash;
pub mod boucwen;
pub mod compose;
pub mod dahl;
pub mod iwan;
pub mod jenkins;
pub mod lugre;
pub mod maxwell;
pub mod sens;

use crate::error::{check_finite, check_same_len, CoreError};

/// A displacement-driven joint law.
pub trait Law {
    /// The internal state carried from sample to sample.
    type State: Clone;
    /// The relaxed state (force 0, no history) at displacement `x0`.
    fn start(&self, x0: f64) -> Self::State;
    /// Advance the state to displacement `x`, `dt` after the previous sample (`None`: a
    /// quasi-static step), and return the force.
    fn step(&self, st: &mut Self::State, dt: Option<f64>, x: f64) -> f64;
}

/// `sign(v)` with `sign(0) = 0` (not `f64::signum`, which gives ±1 for ±0).
#[inline(always)]
pub(crate) fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Return `Err(InvalidParameter)` unless `value` is finite and `>= 0`.
pub(crate) fn check_nonneg(name: &'static str, value: f64) -> Result<(), CoreError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(CoreError::InvalidParameter {
            name,
            value,
            reason: "must be finite and >= 0",
        })
    }
}

/// Check that `t` is finite and strictly increasing, and after `t_prev`.
pub fn check_time(t: &[f64], t_prev: Option<f64>) -> Result<(), CoreError> {
    check_finite("t", t)?;
    if let (Some(p), Some(&t0)) = (t_prev, t.first()) {
        if t0 <= p {
            return Err(CoreError::InvalidParameter {
                name: "t[0]",
                value: t0,
                reason: "must exceed the previous chunk's last time",
            });
        }
    }
    for (i, w) in t.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(CoreError::NotIncreasing {
                name: "t",
                index: i.saturating_add(1),
                value: w[1],
                prev: w[0],
            });
        }
    }
    Ok(())
}

/// Run `law` over a chunk: `out[i]` is the force at `x[i]` (times `t`, or none), continuing
/// `st` and the last time `t_prev`. Inputs are not checked here (see [`Operator::push`]).
#[inline]
pub fn run<L: Law>(
    law: &L,
    st: &mut L::State,
    t_prev: &mut Option<f64>,
    t: Option<&[f64]>,
    x: &[f64],
    out: &mut [f64],
) {
    match t {
        None => {
            for (o, &xi) in out.iter_mut().zip(x) {
                *o = law.step(st, None, xi);
            }
        }
        Some(t) => {
            let mut tp = *t_prev;
            for ((o, &xi), &ti) in out.iter_mut().zip(x).zip(t) {
                *o = law.step(st, tp.map(|p| ti - p), xi);
                tp = Some(ti);
            }
            *t_prev = tp;
        }
    }
}

/// The laws a user composes: leaves and composites (a tree).
#[derive(Debug, Clone, PartialEq)]
pub enum AnyLaw {
    Jenkins(jenkins::Jenkins),
    MaxwellSlip(maxwell::MaxwellSlip),
    Gms(maxwell::Gms),
    Segalman(iwan::MasingStack<iwan::SegalmanCurve>),
    MasingExp(iwan::MasingStack<iwan::ExpCurve>),
    Dahl(dahl::Dahl),
    LuGre(lugre::LuGre),
    BoucWen(boucwen::BoucWen),
    KelvinVoigt(compose::KelvinVoigt),
    Parallel(compose::Parallel),
    Series(Box<compose::Series>),
    Backlash(Box<backlash::Backlash>),
}

/// The state of an [`AnyLaw`] (the same variant).
#[derive(Debug, Clone, PartialEq)]
pub enum AnyState {
    Jenkins(jenkins::JenkinsState),
    MaxwellSlip(maxwell::MaxwellState),
    Gms(maxwell::GmsState),
    Stack(iwan::StackState),
    Dahl(dahl::DahlState),
    LuGre(lugre::LuGreState),
    BoucWen(boucwen::BoucWenState),
    KelvinVoigt(compose::KvState),
    Parallel(compose::ParallelState),
    Series(Box<compose::SeriesState>),
    Backlash(Box<backlash::BacklashState>),
}

impl Law for AnyLaw {
    type State = AnyState;

    fn start(&self, x0: f64) -> AnyState {
        match self {
            Self::Jenkins(l) => AnyState::Jenkins(l.start(x0)),
            Self::MaxwellSlip(l) => AnyState::MaxwellSlip(l.start(x0)),
            Self::Gms(l) => AnyState::Gms(l.start(x0)),
            Self::Segalman(l) => AnyState::Stack(l.start(x0)),
            Self::MasingExp(l) => AnyState::Stack(l.start(x0)),
            Self::Dahl(l) => AnyState::Dahl(l.start(x0)),
            Self::LuGre(l) => AnyState::LuGre(l.start(x0)),
            Self::BoucWen(l) => AnyState::BoucWen(l.start(x0)),
            Self::KelvinVoigt(l) => AnyState::KelvinVoigt(l.start(x0)),
            Self::Parallel(l) => AnyState::Parallel(l.start(x0)),
            Self::Series(l) => AnyState::Series(Box::new(l.start(x0))),
            Self::Backlash(l) => AnyState::Backlash(Box::new(l.start(x0))),
        }
    }

    fn step(&self, st: &mut AnyState, dt: Option<f64>, x: f64) -> f64 {
        match (self, st) {
            (Self::Jenkins(l), AnyState::Jenkins(s)) => l.step(s, dt, x),
            (Self::MaxwellSlip(l), AnyState::MaxwellSlip(s)) => l.step(s, dt, x),
            (Self::Gms(l), AnyState::Gms(s)) => l.step(s, dt, x),
            (Self::Segalman(l), AnyState::Stack(s)) => l.step(s, dt, x),
            (Self::MasingExp(l), AnyState::Stack(s)) => l.step(s, dt, x),
            (Self::Dahl(l), AnyState::Dahl(s)) => l.step(s, dt, x),
            (Self::LuGre(l), AnyState::LuGre(s)) => l.step(s, dt, x),
            (Self::BoucWen(l), AnyState::BoucWen(s)) => l.step(s, dt, x),
            (Self::KelvinVoigt(l), AnyState::KelvinVoigt(s)) => l.step(s, dt, x),
            (Self::Parallel(l), AnyState::Parallel(s)) => l.step(s, dt, x),
            (Self::Series(l), AnyState::Series(s)) => l.step(s, dt, x),
            (Self::Backlash(l), AnyState::Backlash(s)) => l.step(s, dt, x),
            // a state of another law: never built (Operator pairs them); no panic
            _ => f64::NAN,
        }
    }
}

impl AnyLaw {
    /// Build a law from its registry name, its parameters in the order of the Python class's
    /// `param_names` (own parameters only for a composite), and its children.
    pub fn build(kind: &str, p: &[f64], children: Vec<AnyLaw>) -> Result<Self, CoreError> {
        let need = |n: usize| -> Result<(), CoreError> {
            if p.len() == n {
                Ok(())
            } else {
                Err(CoreError::InvalidLaw {
                    kind: kind.to_string(),
                    reason: format!("takes {n} parameters, got {}", p.len()),
                })
            }
        };
        let leaf = |c: &Vec<AnyLaw>| -> Result<(), CoreError> {
            if c.is_empty() {
                Ok(())
            } else {
                Err(CoreError::InvalidLaw {
                    kind: kind.to_string(),
                    reason: "takes no child laws".to_string(),
                })
            }
        };
        if kind != "series" && kind != "parallel" && kind != "backlash" {
            leaf(&children)?;
        }
        Ok(match kind {
            "jenkins" => {
                need(2)?;
                Self::Jenkins(jenkins::Jenkins::new(p[0], p[1])?)
            }
            "iwan" => {
                need(2)?;
                Self::Segalman(iwan::MasingStack::segalman(p[1], p[0], 0.0, 0.0)?)
            }
            "segalman" => {
                need(4)?;
                Self::Segalman(iwan::MasingStack::segalman(p[0], p[1], p[2], p[3])?)
            }
            "masing" => {
                need(3)?;
                if p[2] != 2.0 {
                    return Err(CoreError::InvalidLaw {
                        kind: kind.to_string(),
                        reason: format!(
                            "only Masing's rule (scale 2) is a joint-law kernel, got scale {}",
                            p[2]
                        ),
                    });
                }
                Self::MasingExp(iwan::MasingStack::exponential(p[0], p[1])?)
            }
            "maxwell_slip" => {
                if p.is_empty() || p.len() % 2 != 0 {
                    return Err(CoreError::InvalidLaw {
                        kind: kind.to_string(),
                        reason: format!(
                            "takes k and fs of each element (an even count), got {}",
                            p.len()
                        ),
                    });
                }
                let n = p.len() / 2;
                Self::MaxwellSlip(maxwell::MaxwellSlip::new(&p[..n], &p[n..])?)
            }
            "gms" => {
                if p.len() < 8 || p.len() % 2 != 0 {
                    return Err(CoreError::InvalidLaw {
                        kind: kind.to_string(),
                        reason: format!(
                            "takes k, alpha of each element then Fc, Fs, vs, C, delta, sigma2, got {} values",
                            p.len()
                        ),
                    });
                }
                let (ka, q) = p.split_at(p.len().saturating_sub(6));
                let (k, a) = ka.split_at(ka.len() / 2);
                Self::Gms(maxwell::Gms::new(k, a, q[0], q[1], q[2], q[3], q[4], q[5])?)
            }
            "dahl" => {
                need(3)?;
                Self::Dahl(dahl::Dahl::new(p[0], p[1], p[2])?)
            }
            "lugre" => {
                need(7)?;
                Self::LuGre(lugre::LuGre::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6])?)
            }
            "bouc_wen" => {
                need(5)?;
                Self::BoucWen(boucwen::BoucWen::new(p[0], p[1], p[2], p[3], p[4])?)
            }
            "kelvin_voigt" => {
                need(2)?;
                Self::KelvinVoigt(compose::KelvinVoigt::new(p[0], p[1])?)
            }
            "parallel" => {
                need(2)?;
                Self::Parallel(compose::Parallel::new(children, p[0], p[1])?)
            }
            "series" => {
                need(0)?;
                compose::Series::chain(children)?
            }
            "backlash" => {
                need(1)?;
                let mut it = children.into_iter();
                match (it.next(), it.next()) {
                    (Some(law), None) => {
                        Self::Backlash(Box::new(backlash::Backlash::new(p[0], law)?))
                    }
                    _ => {
                        return Err(CoreError::InvalidLaw {
                            kind: kind.to_string(),
                            reason: "takes exactly one child law".to_string(),
                        })
                    }
                }
            }
            _ => {
                return Err(CoreError::InvalidLaw {
                    kind: kind.to_string(),
                    reason: "is not a known law".to_string(),
                })
            }
        })
    }

    /// The law of a flat encoding `[code, n_params, params..., n_children, children...]`
    /// (depth first; `code` indexes [`FLAT_KINDS`]), as `contactlab.structure.joints`
    /// writes it for a structure joint.
    pub fn from_flat(flat: &[f64]) -> Result<Self, CoreError> {
        let mut pos = 0usize;
        let law = Self::walk_flat(flat, &mut pos, 0)?;
        if pos != flat.len() {
            return Err(flat_error("has values after the last law"));
        }
        Ok(law)
    }

    fn walk_flat(flat: &[f64], pos: &mut usize, depth: usize) -> Result<Self, CoreError> {
        if depth > 64 {
            return Err(flat_error("is nested too deeply"));
        }
        let code = flat_count(flat, pos, FLAT_KINDS.len().saturating_sub(1))?;
        let kind = FLAT_KINDS
            .get(code)
            .ok_or_else(|| flat_error("has an unknown kind code"))?;
        let np = flat_count(flat, pos, flat.len())?;
        let mut params = Vec::with_capacity(np);
        for _ in 0..np {
            params.push(flat_take(flat, pos)?);
        }
        let nc = flat_count(flat, pos, flat.len())?;
        let mut children = Vec::with_capacity(nc);
        for _ in 0..nc {
            children.push(Self::walk_flat(flat, pos, depth.saturating_add(1))?);
        }
        Self::build(kind, &params, children)
    }

    /// True when the force depends on the velocity (times are then required).
    pub fn rate_dependent(&self) -> bool {
        match self {
            Self::Gms(_) | Self::LuGre(_) => true,
            Self::KelvinVoigt(l) => l.c > 0.0,
            Self::Parallel(l) => l.c > 0.0 || l.laws.iter().any(Self::rate_dependent),
            Self::Series(l) => l.a.rate_dependent() || l.b.rate_dependent(),
            Self::Backlash(l) => l.law.rate_dependent(),
            _ => false,
        }
    }

    /// True when a step solves a force balance (a composite with a root search).
    fn solves(&self) -> bool {
        match self {
            Self::Series(_) | Self::Backlash(_) => true,
            Self::Parallel(l) => l.laws.iter().any(Self::solves),
            _ => false,
        }
    }

    /// Run a chunk with a loop specialised to the law at the top of the tree.
    pub fn run_chunk(
        &self,
        st: &mut AnyState,
        t_prev: &mut Option<f64>,
        t: Option<&[f64]>,
        x: &[f64],
        out: &mut [f64],
    ) {
        match (self, st) {
            (Self::Jenkins(l), AnyState::Jenkins(s)) => run(l, s, t_prev, t, x, out),
            (Self::MaxwellSlip(l), AnyState::MaxwellSlip(s)) => run(l, s, t_prev, t, x, out),
            (Self::Gms(l), AnyState::Gms(s)) => run(l, s, t_prev, t, x, out),
            (Self::Segalman(l), AnyState::Stack(s)) => run(l, s, t_prev, t, x, out),
            (Self::MasingExp(l), AnyState::Stack(s)) => run(l, s, t_prev, t, x, out),
            (Self::Dahl(l), AnyState::Dahl(s)) => run(l, s, t_prev, t, x, out),
            (Self::LuGre(l), AnyState::LuGre(s)) => run(l, s, t_prev, t, x, out),
            (Self::BoucWen(l), AnyState::BoucWen(s)) => run(l, s, t_prev, t, x, out),
            (law, s) => run(law, s, t_prev, t, x, out),
        }
    }
}

/// Kind codes of [`AnyLaw::from_flat`] (the table of `contactlab.structure.joints.LAW_CODES`).
pub const FLAT_KINDS: [&str; 13] = [
    "jenkins",
    "iwan",
    "segalman",
    "masing",
    "maxwell_slip",
    "gms",
    "dahl",
    "lugre",
    "bouc_wen",
    "kelvin_voigt",
    "parallel",
    "series",
    "backlash",
];

fn flat_error(reason: &str) -> CoreError {
    CoreError::InvalidLaw {
        kind: "flat encoding".to_string(),
        reason: reason.to_string(),
    }
}

fn flat_take(flat: &[f64], pos: &mut usize) -> Result<f64, CoreError> {
    let v = flat
        .get(*pos)
        .copied()
        .ok_or_else(|| flat_error("ends early"))?;
    *pos = pos.saturating_add(1);
    Ok(v)
}

/// A count (or code) in `0..=max`, stored as a float.
fn flat_count(flat: &[f64], pos: &mut usize, max: usize) -> Result<usize, CoreError> {
    let v = flat_take(flat, pos)?;
    if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= max as f64 {
        Ok(v as usize)
    } else {
        Err(flat_error(
            "has a count or kind code that is not a small non-negative integer",
        ))
    }
}

/// A law with its carried state: the streaming form (chunked pushes equal one pass).
#[derive(Debug, Clone, PartialEq)]
pub struct Operator {
    law: AnyLaw,
    x0: f64,
    state: AnyState,
    t_prev: Option<f64>,
    /// Whether the chunks so far came with times (`None` before the first chunk).
    timed: Option<bool>,
}

impl Operator {
    /// The operator of `law`, relaxed at displacement `x0`.
    pub fn new(law: AnyLaw, x0: f64) -> Result<Self, CoreError> {
        check_finite("x0", &[x0])?;
        let state = law.start(x0);
        Ok(Self {
            law,
            x0,
            state,
            t_prev: None,
            timed: None,
        })
    }

    /// The law.
    pub fn law(&self) -> &AnyLaw {
        &self.law
    }

    /// Back to the relaxed state at `x0`.
    pub fn reset(&mut self) {
        self.state = self.law.start(self.x0);
        self.t_prev = None;
        self.timed = None;
    }

    /// Forces of the next chunk into `out`; on an error the carried state is unchanged.
    pub fn push(&mut self, t: Option<&[f64]>, x: &[f64], out: &mut [f64]) -> Result<(), CoreError> {
        check_same_len("out", out.len(), "x", x.len())?;
        check_finite("x", x)?;
        if let Some(t) = t {
            check_same_len("t", t.len(), "x", x.len())?;
            if self.timed == Some(false) {
                return Err(CoreError::InvalidState {
                    reason: "an earlier chunk came without times: pass None for every chunk",
                });
            }
            check_time(t, self.t_prev)?;
        } else {
            if self.law.rate_dependent() {
                return Err(CoreError::InvalidState {
                    reason: "the law is rate-dependent: pass the sample times t",
                });
            }
            if self.timed == Some(true) {
                return Err(CoreError::InvalidState {
                    reason: "an earlier chunk came with times: pass t for every chunk",
                });
            }
        }
        if x.is_empty() {
            return Ok(());
        }
        let mut st = self.state.clone();
        let mut tp = self.t_prev;
        self.law.run_chunk(&mut st, &mut tp, t, x, out);
        if let Some(index) = out.iter().position(|v| !v.is_finite()) {
            if out[index].is_nan() && self.law.solves() {
                return Err(CoreError::NoSolution {
                    what: "series/backlash joint",
                    index,
                });
            }
            return Err(CoreError::OutOfRange {
                what: "force",
                index,
                value: out[index],
            });
        }
        self.state = st;
        self.t_prev = tp;
        self.timed = Some(t.is_some());
        Ok(())
    }
}

/// Forces of a whole history from the relaxed state at `x0`.
pub fn force(law: &AnyLaw, t: Option<&[f64]>, x: &[f64], x0: f64) -> Result<Vec<f64>, CoreError> {
    let mut op = Operator::new(law.clone(), x0)?;
    let mut out = vec![0.0; x.len()];
    op.push(t, x, &mut out)?;
    Ok(out)
}

/// A root of the non-decreasing `phi` in `[a, b]` with `fa <= 0 <= fb`: Illinois false
/// position, bisection when the secant leaves the bracket (the reference's `illinois`).
pub(crate) fn illinois(
    phi: &mut dyn FnMut(f64) -> f64,
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
    ftol: f64,
) -> f64 {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let mut side = 0i8;
    let mut c = a;
    for _ in 0..200 {
        c = b - fb * (b - a) / (fb - fa);
        if !(a < c && c < b) {
            c = 0.5 * (a + b);
            if !(a < c && c < b) {
                return c;
            }
        }
        let fc = phi(c);
        if fc.abs() <= ftol {
            return c;
        }
        if fc > 0.0 {
            b = c;
            fb = fc;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            a = c;
            fa = fc;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
        if b - a <= 4.0 * f64::EPSILON * a.abs().max(b.abs()) {
            return c;
        }
    }
    c
}

#[cfg(test)]
mod tests;
