//! Dahl's friction law `dF/dx = σ0 |1 - F/Fc sgn ẋ|^α sgn(1 - F/Fc sgn ẋ)`, solved in closed
//! form along each monotone step (rate-independent).

use super::{sign, Law};
use crate::error::{check_positive, CoreError};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dahl {
    pub sigma0: f64,
    pub fc: f64,
    pub alpha: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlState {
    pub xp: f64,
    pub f: f64,
}

impl Dahl {
    pub fn new(sigma0: f64, fc: f64, alpha: f64) -> Result<Self, CoreError> {
        check_positive("sigma0", sigma0)?;
        check_positive("Fc", fc)?;
        check_positive("alpha", alpha)?;
        Ok(Self { sigma0, fc, alpha })
    }
}

impl Law for Dahl {
    type State = DahlState;
    fn start(&self, x0: f64) -> DahlState {
        DahlState { xp: x0, f: 0.0 }
    }
    #[inline(always)]
    fn step(&self, st: &mut DahlState, _dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        st.xp = x;
        if dx == 0.0 {
            return st.f;
        }
        let s = sign(dx);
        let a = self.sigma0 / self.fc;
        let u = dx.abs();
        // y = 1 - s F / Fc obeys dy/du = -a y^α
        if self.alpha == 1.0 {
            // F -> s Fc exponentially in the travelled distance (y e^{-a u}, y Fc = Fc - s F,
            // written without a division)
            st.f = s * (self.fc - (self.fc - s * st.f) * (-a * u).exp());
            return st.f;
        }
        let y = 1.0 - s * st.f / self.fc;
        let al = self.alpha;
        let yn = if y <= 0.0 {
            y
        } else if al == 1.0 {
            y * (-a * u).exp()
        } else if al < 1.0 {
            let w = y.powf(1.0 - al) - (1.0 - al) * a * u;
            if w > 0.0 {
                w.powf(1.0 / (1.0 - al))
            } else {
                0.0
            }
        } else {
            (y.powf(1.0 - al) + (al - 1.0) * a * u).powf(-1.0 / (al - 1.0))
        };
        st.f = s * self.fc * (1.0 - yn);
        st.f
    }
}
