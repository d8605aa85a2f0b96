//! LuGre friction model (Canudas de Wit, Olsson, Åström & Lischinsky 1995):
//! `dz/dt = v - σ0 |v| z / g(v)`, `g(v) = Fc + (Fs - Fc) exp(-|v/vs|^δ)`,
//! `F = σ0 z + σ1 dz/dt + σ2 v`.
//!
//! With the velocity constant over a step, `z` relaxes exponentially in the travelled
//! distance towards `sgn(v) g(v) / σ0`: the exact solution, stable for any bristle stiffness
//! and sampling rate (no explicit ODE step).

use super::{check_nonneg, sign, Law};
use crate::error::{check_positive, CoreError};

/// The Stribeck curve `Fc + (Fs - Fc) exp(-|v/vs|^δ)`.
#[inline(always)]
pub(crate) fn stribeck(fc: f64, fs: f64, vs: f64, delta: f64, v: f64) -> f64 {
    let r = v.abs() / vs;
    let p = if delta == 2.0 { r * r } else { r.powf(delta) };
    // far past the Stribeck velocity the exponential is below 1e-21 of (Fs - Fc): skipped,
    // which also keeps libm's slow subnormal path (exp below -708) out of the loop
    if p > 48.0 {
        return fc;
    }
    fc + (fs - fc) * (-p).exp()
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuGre {
    pub sigma0: f64,
    pub sigma1: f64,
    pub sigma2: f64,
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub delta: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuGreState {
    pub xp: f64,
    pub z: f64,
}

impl LuGre {
    pub fn new(
        sigma0: f64,
        sigma1: f64,
        sigma2: f64,
        fc: f64,
        fs: f64,
        vs: f64,
        delta: f64,
    ) -> Result<Self, CoreError> {
        check_positive("sigma0", sigma0)?;
        check_nonneg("sigma1", sigma1)?;
        check_nonneg("sigma2", sigma2)?;
        check_positive("Fc", fc)?;
        check_positive("Fs", fs)?;
        check_positive("vs", vs)?;
        check_positive("delta", delta)?;
        Ok(Self {
            sigma0,
            sigma1,
            sigma2,
            fc,
            fs,
            vs,
            delta,
        })
    }
}

impl Law for LuGre {
    type State = LuGreState;
    fn start(&self, x0: f64) -> LuGreState {
        LuGreState { xp: x0, z: 0.0 }
    }
    #[inline(always)]
    fn step(&self, st: &mut LuGreState, dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        st.xp = x;
        let (v, g) = match dt {
            None => (0.0, self.fs),
            Some(dt) => {
                let v = dx / dt;
                (v, stribeck(self.fc, self.fs, self.vs, self.delta, v))
            }
        };
        let ig = 1.0 / g;
        if dx != 0.0 {
            let zss = sign(dx) * g / self.sigma0;
            st.z = zss + (st.z - zss) * (-self.sigma0 * dx.abs() * ig).exp();
        }
        let z = st.z;
        let zdot = v - self.sigma0 * v.abs() * z * ig;
        self.sigma0 * z + self.sigma1 * zdot + self.sigma2 * v
    }
}
