//! Jenkins element: stiffness `k` in series with a Coulomb slider of slip force `fs`.

use super::Law;
use crate::error::{check_positive, CoreError};

/// Elastic-Coulomb element. Energy per symmetric cycle of amplitude `A`: `4 fs (A - fs/k)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jenkins {
    pub k: f64,
    pub fs: f64,
}

/// Slider position `z` (the force is `k (x - z)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JenkinsState {
    pub z: f64,
}

impl Jenkins {
    pub fn new(k: f64, fs: f64) -> Result<Self, CoreError> {
        check_positive("k", k)?;
        check_positive("fs", fs)?;
        Ok(Self { k, fs })
    }
}

/// One elastic-Coulomb update: the force at `x`, moving the slider `z` when it slips.
#[inline(always)]
pub(crate) fn jenkins_step(k: f64, fs: f64, z: &mut f64, x: f64) -> f64 {
    let f = k * (x - *z);
    if f > fs {
        *z = x - fs / k;
        fs
    } else if f < -fs {
        *z = x + fs / k;
        -fs
    } else {
        f
    }
}

impl Law for Jenkins {
    type State = JenkinsState;
    fn start(&self, x0: f64) -> JenkinsState {
        JenkinsState { z: x0 }
    }
    #[inline(always)]
    fn step(&self, st: &mut JenkinsState, _dt: Option<f64>, x: f64) -> f64 {
        jenkins_step(self.k, self.fs, &mut st.z, x)
    }
}
