//! The contact models as an ODE for δ (Konowalski 2009, eqs. 8, 13, 17):
//!
//! `p = k_s δ + (ψ k_s / (2π ω)) δ'`  ⇔  `δ' = (2π ω / ψ) (p / k_s − δ)`
//!
//! with `k_s` constant (Kelvin-Voigt, eq. 8 with eq. 13), a polynomial of δ (eq. 6:
//! `k_s = a1 + a2 δ + a3 δ² + a4 δ³`) or a polynomial of the dynamic pressure p (eq. 16:
//! `k_s = b1 p³ + b2 p² + b3 p + b4`). ω is the excitation's angular frequency.

use std::f64::consts::PI;

use super::poly;
use crate::error::{check_finite, check_positive, CoreError};

/// How the secant stiffness `k_s` depends on the state.
#[derive(Debug, Clone, PartialEq)]
pub enum Stiffness {
    /// `k_s = k` (linear Kelvin-Voigt).
    Constant(f64),
    /// `k_s(δ)`, ascending coefficients `[a1, a2, a3, …]` (eq. 6).
    Delta(Vec<f64>),
    /// `k_s(p)`, ascending coefficients `[b4, b3, b2, b1]` (eq. 16 read right to left).
    Pressure(Vec<f64>),
}

/// A contact model `δ' = r (p / k_s − δ)`, `r = 2π ω / ψ`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactModel {
    stiffness: Stiffness,
    psi: f64,
    omega: f64,
    rate: f64,
}

/// Right-hand side at one point: `f`, `∂f/∂δ`, `∂f/∂t`.
#[derive(Debug, Clone, Copy)]
pub struct RhsEval {
    pub f: f64,
    pub jac: f64,
    pub dfdt: f64,
}

impl ContactModel {
    pub fn new(stiffness: Stiffness, psi: f64, omega: f64) -> Result<Self, CoreError> {
        check_positive("psi", psi)?;
        check_positive("omega", omega)?;
        match &stiffness {
            Stiffness::Constant(k) => check_positive("k", *k)?,
            Stiffness::Delta(c) | Stiffness::Pressure(c) => {
                if c.is_empty() {
                    return Err(CoreError::Empty {
                        name: "stiffness coefficients",
                    });
                }
                check_finite("stiffness coefficients", c)?;
            }
        }
        let rate = 2.0 * PI * omega / psi;
        if !rate.is_finite() {
            return Err(CoreError::InvalidParameter {
                name: "psi",
                value: psi,
                reason: "2π ω / ψ overflows",
            });
        }
        Ok(Self {
            stiffness,
            psi,
            omega,
            rate,
        })
    }

    pub fn stiffness(&self) -> &Stiffness {
        &self.stiffness
    }

    pub fn psi(&self) -> f64 {
        self.psi
    }

    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// `2π ω / ψ`, the inverse time constant.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// `k_s` at state `(p, δ)`.
    #[inline]
    pub fn k_s(&self, p: f64, delta: f64) -> f64 {
        match &self.stiffness {
            Stiffness::Constant(k) => *k,
            Stiffness::Delta(c) => poly::eval(c, delta),
            Stiffness::Pressure(c) => poly::eval(c, p),
        }
    }

    fn non_positive(&self, p: f64, delta: f64, k: f64) -> CoreError {
        let (name, at) = match self.stiffness {
            Stiffness::Pressure(_) => ("p", p),
            _ => ("delta", delta),
        };
        CoreError::NonPositiveStiffness { name, at, value: k }
    }

    /// `f(p, δ)`; `None` where `k_s ≤ 0` (or not finite).
    #[inline]
    pub fn f(&self, p: f64, delta: f64) -> Option<f64> {
        let k = self.k_s(p, delta);
        if k > 0.0 && k.is_finite() {
            Some(self.rate * (p / k - delta))
        } else {
            None
        }
    }

    /// `f`, `∂f/∂δ` and `∂f/∂t` (through `dp/dt`) at `(p, dp/dt, δ)`.
    #[inline]
    pub fn eval(&self, p: f64, dpdt: f64, delta: f64) -> Result<RhsEval, CoreError> {
        let r = self.rate;
        match &self.stiffness {
            Stiffness::Constant(k) => Ok(RhsEval {
                f: r * (p / k - delta),
                jac: -r,
                dfdt: r * dpdt / k,
            }),
            Stiffness::Delta(c) => {
                let (k, dk) = poly::eval_with_deriv(c, delta);
                if !(k > 0.0 && k.is_finite()) {
                    return Err(self.non_positive(p, delta, k));
                }
                Ok(RhsEval {
                    f: r * (p / k - delta),
                    jac: -r * (1.0 + p * dk / (k * k)),
                    dfdt: r * dpdt / k,
                })
            }
            Stiffness::Pressure(c) => {
                let (k, dk) = poly::eval_with_deriv(c, p);
                if !(k > 0.0 && k.is_finite()) {
                    return Err(self.non_positive(p, delta, k));
                }
                Ok(RhsEval {
                    f: r * (p / k - delta),
                    jac: -r,
                    dfdt: r * dpdt * (k - p * dk) / (k * k),
                })
            }
        }
    }

    /// The equilibrium displacement under a constant pressure: `k_s δ = p`.
    pub fn equilibrium(&self, p: f64) -> Result<f64, CoreError> {
        match &self.stiffness {
            Stiffness::Constant(k) => Ok(p / k),
            Stiffness::Pressure(c) => {
                let k = poly::eval(c, p);
                if k > 0.0 && k.is_finite() {
                    Ok(p / k)
                } else {
                    Err(self.non_positive(p, 0.0, k))
                }
            }
            Stiffness::Delta(c) => {
                // Newton on g(δ) = k_s(δ) δ − p from the linearised guess p / k_s(0).
                let k0 = c[0];
                if k0.is_nan() || k0 <= 0.0 {
                    return Err(self.non_positive(p, 0.0, k0));
                }
                let mut d = p / k0;
                for _ in 0..100 {
                    let (k, dk) = poly::eval_with_deriv(c, d);
                    let g = k * d - p;
                    let dg = k + d * dk;
                    if dg.is_nan() || dg <= 0.0 || k.is_nan() || k <= 0.0 {
                        break;
                    }
                    let step = g / dg;
                    d -= step;
                    if step.abs() <= 1e-15 * d.abs().max(f64::MIN_POSITIVE) {
                        return Ok(d);
                    }
                }
                let k = poly::eval(c, d);
                if (k * d - p).abs() <= 1e-12 * p.abs().max(k0 * d.abs()) && k > 0.0 {
                    Ok(d)
                } else {
                    Err(CoreError::InvalidParameter {
                        name: "p",
                        value: p,
                        reason: "no equilibrium k_s(δ) δ = p with positive, increasing k_s(δ) δ near δ = p / k_s(0)",
                    })
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_parameters() {
        assert!(ContactModel::new(Stiffness::Constant(1.0), 0.0, 1.0).is_err());
        assert!(ContactModel::new(Stiffness::Constant(1.0), -0.1, 1.0).is_err());
        assert!(ContactModel::new(Stiffness::Constant(1.0), 0.1, f64::NAN).is_err());
        assert!(ContactModel::new(Stiffness::Constant(-1.0), 0.1, 1.0).is_err());
        assert!(ContactModel::new(Stiffness::Delta(vec![]), 0.1, 1.0).is_err());
        assert!(
            ContactModel::new(Stiffness::Pressure(vec![1.0, f64::INFINITY]), 0.1, 1.0).is_err()
        );
    }

    #[test]
    fn jacobian_and_time_derivative_match_finite_differences() {
        for st in [
            Stiffness::Delta(vec![1.3, 1.6, 2.9, 2.9]),
            Stiffness::Pressure(vec![1.2, 0.4, -0.3, 0.2]),
            Stiffness::Constant(1.2),
        ] {
            let m = ContactModel::new(st, 0.09, 1.0).unwrap();
            let (p, dp, d) = (0.3, 0.7, 0.2);
            let e = m.eval(p, dp, d).unwrap();
            let eps = 1e-7;
            let jd = (m.f(p, d + eps).unwrap() - m.f(p, d - eps).unwrap()) / (2.0 * eps);
            let jt = (m.f(p + dp * eps, d).unwrap() - m.f(p - dp * eps, d).unwrap()) / (2.0 * eps);
            assert!((e.jac - jd).abs() < 1e-6 * jd.abs().max(1.0));
            assert!((e.dfdt - jt).abs() < 1e-6 * jt.abs().max(1.0));
        }
    }

    #[test]
    fn equilibrium_solves_centre_curve() {
        let c = vec![1.32596, 1.59811, 2.92127, 2.87416];
        let m = ContactModel::new(Stiffness::Delta(c.clone()), 0.09, 1.0).unwrap();
        for p in [-0.4, -0.1, 0.0, 0.2, 0.4] {
            let d = m.equilibrium(p).unwrap();
            assert!((poly::eval(&c, d) * d - p).abs() < 1e-13);
        }
    }

    #[test]
    fn non_positive_stiffness_is_an_error() {
        let m = ContactModel::new(Stiffness::Delta(vec![1.0, 10.0]), 0.1, 1.0).unwrap();
        assert!(matches!(
            m.eval(0.0, 0.0, -0.2),
            Err(CoreError::NonPositiveStiffness { name: "delta", .. })
        ));
    }
}
