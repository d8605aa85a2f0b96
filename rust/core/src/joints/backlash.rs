//! A clearance of total width `gap` in series with a law (a dead band). The law's
//! displacement `y` obeys `|x - y| <= gap/2`; the force is 0 while the gap is open, `>= 0` in
//! contact at `x - y = gap/2` and `<= 0` at `x - y = -gap/2` (a complementarity problem,
//! solved at every sample on the law's non-decreasing trial force).

use super::{check_nonneg, illinois, AnyLaw, AnyState, Law};
use crate::error::CoreError;

#[derive(Debug, Clone, PartialEq)]
pub struct Backlash {
    /// Half the gap.
    pub h: f64,
    pub law: AnyLaw,
}

#[derive(Debug, Clone, PartialEq)]
pub struct BacklashState {
    pub y: f64,
    pub s: AnyState,
    pub f: f64,
}

impl Backlash {
    pub fn new(gap: f64, law: AnyLaw) -> Result<Self, CoreError> {
        check_nonneg("gap", gap)?;
        Ok(Self { h: 0.5 * gap, law })
    }
}

impl Law for Backlash {
    type State = BacklashState;
    fn start(&self, x0: f64) -> BacklashState {
        BacklashState {
            y: x0,
            s: self.law.start(x0),
            f: 0.0,
        }
    }
    fn step(&self, st: &mut BacklashState, dt: Option<f64>, x: f64) -> f64 {
        let law = &self.law;
        let s0 = &st.s;
        let mut phi = |y: f64| -> f64 {
            let mut s = s0.clone();
            law.step(&mut s, dt, y)
        };
        let lo = x - self.h;
        let hi = x + self.h;
        let f_lo = phi(lo);
        let y = if f_lo >= 0.0 {
            lo
        } else {
            let f_hi = phi(hi);
            if f_hi <= 0.0 {
                hi
            } else {
                let ftol = 1e-14 * st.f.abs().max(f_lo.abs()).max(f_hi.abs());
                illinois(&mut phi, lo, f_lo, hi, f_hi, ftol)
            }
        };
        let mut s = st.s.clone();
        let f = law.step(&mut s, dt, y);
        st.y = y;
        st.s = s;
        st.f = f;
        f
    }
}
