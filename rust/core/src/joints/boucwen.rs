//! Bouc-Wen hysteresis in displacement-driven form: `F = z`,
//! `dz/dx = α - β (γ s |z|^(ν-1) z + δ |z|^ν)`, `s = sgn(ẋ)` (the form of the hysteretic
//! benchmark of Noël & Schoukens 2016). RK4 in `x` on sub-steps of at most 5 % of the
//! saturation displacement `z_c / α`, `z_c = (α / (β (|γ| + |δ|)))^(1/ν)` (divided by
//! `max(ν, 1)`), at most 100 000 sub-steps a sample.

use super::{check_nonneg, sign, Law};
use crate::error::{check_finite, check_positive, CoreError};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoucWen {
    pub alpha: f64,
    pub beta: f64,
    pub gamma: f64,
    pub delta: f64,
    pub nu: f64,
    /// Largest sub-step, m (infinite for a linear law).
    pub h: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoucWenState {
    pub xp: f64,
    pub z: f64,
}

impl BoucWen {
    pub fn new(alpha: f64, beta: f64, gamma: f64, delta: f64, nu: f64) -> Result<Self, CoreError> {
        check_positive("alpha", alpha)?;
        check_nonneg("beta", beta)?;
        check_finite("gamma", &[gamma])?;
        check_finite("delta", &[delta])?;
        check_positive("nu", nu)?;
        if beta * (gamma + delta) < 0.0 {
            return Err(CoreError::InvalidParameter {
                name: "beta",
                value: beta,
                reason: "with gamma + delta < 0 makes the force grow without bound",
            });
        }
        let q = beta * (gamma.abs() + delta.abs());
        let h = if q > 0.0 {
            0.05 * (alpha / q).powf(1.0 / nu) / alpha / nu.max(1.0)
        } else {
            f64::INFINITY
        };
        if h.is_nan() || h <= 0.0 {
            return Err(CoreError::InvalidParameter {
                name: "beta",
                value: beta,
                reason: "gives a saturation displacement out of the double-precision range",
            });
        }
        Ok(Self {
            alpha,
            beta,
            gamma,
            delta,
            nu,
            h,
        })
    }

    #[inline(always)]
    fn rate(&self, z: f64, s: f64) -> f64 {
        let p = z.abs().powf(self.nu);
        self.alpha - self.beta * (self.gamma * s * sign(z) * p + self.delta * p)
    }
}

impl Law for BoucWen {
    type State = BoucWenState;
    fn start(&self, x0: f64) -> BoucWenState {
        BoucWenState { xp: x0, z: 0.0 }
    }
    fn step(&self, st: &mut BoucWenState, _dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        st.xp = x;
        if dx == 0.0 {
            return st.z;
        }
        let s = sign(dx);
        let n: u32 = if self.h.is_infinite() {
            1
        } else {
            (dx.abs() / self.h).ceil().clamp(1.0, 100_000.0) as u32
        };
        let hs = dx / f64::from(n);
        let mut z = st.z;
        for _ in 0..n {
            let k1 = self.rate(z, s);
            let k2 = self.rate(z + 0.5 * hs * k1, s);
            let k3 = self.rate(z + 0.5 * hs * k2, s);
            let k4 = self.rate(z + hs * k3, s);
            z += hs / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        st.z = z;
        z
    }
}
