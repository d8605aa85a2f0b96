//! Continuous Iwan models, exact: Masing's rules (branch `F_r + 2 f((x - x_r)/2)`) with the
//! wiping-out memory of reversal points on the model's virgin curve `f`. A parallel-series
//! Iwan model with any slip-displacement density obeys these rules exactly, so no
//! discretisation of the density is needed.
//!
//! Curves: [`SegalmanCurve`] (Segalman's four-parameter power law, J. Appl. Mech. 72, 2005;
//! the uniform density is `χ = 0`, `β = 0`) and [`ExpCurve`] (`h0 (1 - exp(-ac u))`).

use super::{check_nonneg, sign, Law};
use crate::error::{check_positive, CoreError};

/// An odd virgin curve.
pub trait Virgin {
    fn f(&self, u: f64) -> f64;
}

/// Segalman's virgin curve `f(u) = K_T u - R u^(χ+2) / ((χ+1)(χ+2))` for `u < φmax`,
/// `F_S` beyond (density `R φ^χ` on `(0, φmax)` plus `S δ(φ - φmax)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegalmanCurve {
    pub f_s: f64,
    pub k_t: f64,
    pub phi_max: f64,
    pub c: f64,
    pub n: f64,
}

impl SegalmanCurve {
    pub fn new(f_s: f64, k_t: f64, chi: f64, beta: f64) -> Result<Self, CoreError> {
        check_positive("F_S", f_s)?;
        check_positive("K_T", k_t)?;
        if !(chi.is_finite() && chi > -1.0 && chi <= 1.0) {
            return Err(CoreError::InvalidParameter {
                name: "chi",
                value: chi,
                reason: "must be in (-1, 1]",
            });
        }
        check_nonneg("beta", beta)?;
        let phi_max = f_s * (1.0 + beta) / (k_t * (beta + (chi + 1.0) / (chi + 2.0)));
        let r = f_s * (chi + 1.0) / (phi_max.powf(chi + 2.0) * (beta + (chi + 1.0) / (chi + 2.0)));
        let c = r / ((chi + 1.0) * (chi + 2.0));
        if !(phi_max.is_finite() && phi_max > 0.0 && c.is_finite()) {
            return Err(CoreError::InvalidParameter {
                name: "F_S",
                value: f_s,
                reason: "with K_T gives a slip displacement out of the double-precision range",
            });
        }
        Ok(Self {
            f_s,
            k_t,
            phi_max,
            c,
            n: chi + 2.0,
        })
    }
}

impl Virgin for SegalmanCurve {
    #[inline(always)]
    fn f(&self, u: f64) -> f64 {
        let a = u.abs();
        let v = if a >= self.phi_max {
            self.f_s
        } else {
            self.k_t * a - self.c * a.powf(self.n)
        };
        if u >= 0.0 {
            v
        } else {
            -v
        }
    }
}

/// The exponential curve `h0 (1 - exp(-ac |u|)) sgn u` of the Masing model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpCurve {
    pub h0: f64,
    pub ac: f64,
}

impl Virgin for ExpCurve {
    #[inline(always)]
    fn f(&self, u: f64) -> f64 {
        let v = self.h0 * (1.0 - (-self.ac * u.abs()).exp());
        if u >= 0.0 {
            v
        } else {
            -v
        }
    }
}

/// Masing's rules with reversal memory on a virgin curve.
#[derive(Debug, Clone, PartialEq)]
pub struct MasingStack<C> {
    pub curve: C,
}

/// Reversal points `(x_r, F_r)` still remembered, the last sample and the direction.
#[derive(Debug, Clone, PartialEq)]
pub struct StackState {
    pub x0: f64,
    pub xp: f64,
    pub fp: f64,
    pub dir: f64,
    pub stack: Vec<(f64, f64)>,
}

impl MasingStack<SegalmanCurve> {
    pub fn segalman(f_s: f64, k_t: f64, chi: f64, beta: f64) -> Result<Self, CoreError> {
        Ok(Self {
            curve: SegalmanCurve::new(f_s, k_t, chi, beta)?,
        })
    }
}

impl MasingStack<ExpCurve> {
    pub fn exponential(h0: f64, ac: f64) -> Result<Self, CoreError> {
        check_positive("h0", h0)?;
        check_positive("ac", ac)?;
        Ok(Self {
            curve: ExpCurve { h0, ac },
        })
    }
}

impl<C: Virgin> Law for MasingStack<C> {
    type State = StackState;
    fn start(&self, x0: f64) -> StackState {
        StackState {
            x0,
            xp: x0,
            fp: 0.0,
            dir: 0.0,
            stack: Vec::new(),
        }
    }
    #[inline]
    fn step(&self, st: &mut StackState, _dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        if dx == 0.0 {
            return st.fp;
        }
        let s = sign(dx);
        if st.dir != 0.0 && s != st.dir {
            st.stack.push((st.xp, st.fp));
        }
        st.dir = s;
        loop {
            let n = st.stack.len();
            if n >= 2 && (x - st.stack[n.wrapping_sub(2)].0) * s >= 0.0 {
                st.stack.truncate(n.wrapping_sub(2));
                continue;
            }
            if n == 1 && (x - (2.0 * st.x0 - st.stack[0].0)) * s >= 0.0 {
                st.stack.clear();
                continue;
            }
            break;
        }
        let f = match st.stack.last() {
            Some(&(xr, fr)) => fr + 2.0 * self.curve.f(0.5 * (x - xr)),
            None => self.curve.f(x - st.x0),
        };
        st.xp = x;
        st.fp = f;
        f
    }
}
