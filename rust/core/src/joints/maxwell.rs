//! Maxwell-slip (parallel Jenkins elements) and the generalised Maxwell-slip model
//! (Al-Bender, Lampaert & Swevers, IEEE Trans. Autom. Control 50, 2005).

use super::jenkins::jenkins_step;
use super::lugre::stribeck;
use super::{check_nonneg, sign, Law};
use crate::error::{check_positive, check_same_len, CoreError};

/// `N` Jenkins elements in parallel.
#[derive(Debug, Clone, PartialEq)]
pub struct MaxwellSlip {
    pub k: Vec<f64>,
    pub fs: Vec<f64>,
}

/// Slider positions of the elements.
#[derive(Debug, Clone, PartialEq)]
pub struct MaxwellState {
    pub z: Vec<f64>,
}

impl MaxwellSlip {
    pub fn new(k: &[f64], fs: &[f64]) -> Result<Self, CoreError> {
        check_same_len("k", k.len(), "fs", fs.len())?;
        if k.is_empty() {
            return Err(CoreError::Empty { name: "k" });
        }
        for (&ki, &fi) in k.iter().zip(fs) {
            check_positive("k", ki)?;
            check_positive("fs", fi)?;
        }
        Ok(Self {
            k: k.to_vec(),
            fs: fs.to_vec(),
        })
    }
}

impl Law for MaxwellSlip {
    type State = MaxwellState;
    fn start(&self, x0: f64) -> MaxwellState {
        MaxwellState {
            z: vec![x0; self.k.len()],
        }
    }
    #[inline]
    fn step(&self, st: &mut MaxwellState, _dt: Option<f64>, x: f64) -> f64 {
        let mut total = 0.0;
        for ((&k, &fs), z) in self.k.iter().zip(&self.fs).zip(st.z.iter_mut()) {
            total += jenkins_step(k, fs, z, x);
        }
        total
    }
}

/// Generalised Maxwell-slip: element `i` sticks (`dF_i = k_i dx`) until `|F_i|` reaches
/// `α_i s(v)` (`s` the Stribeck curve), then slips with `dF_i/dt = sgn(v) C (1 - F_i / (α_i
/// s(v) sgn v))` until the motion reverses; `F = Σ F_i + σ2 v`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gms {
    pub k: Vec<f64>,
    pub alpha: Vec<f64>,
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub c: f64,
    pub delta: f64,
    pub sigma2: f64,
}

/// Element forces, slip direction of each element (0: sticking), last displacement.
#[derive(Debug, Clone, PartialEq)]
pub struct GmsState {
    pub xp: f64,
    pub f: Vec<f64>,
    pub slip: Vec<f64>,
}

impl Gms {
    pub fn new(
        k: &[f64],
        alpha: &[f64],
        fc: f64,
        fs: f64,
        vs: f64,
        c: f64,
        delta: f64,
        sigma2: f64,
    ) -> Result<Self, CoreError> {
        check_same_len("k", k.len(), "alpha", alpha.len())?;
        if k.is_empty() {
            return Err(CoreError::Empty { name: "k" });
        }
        for (&ki, &ai) in k.iter().zip(alpha) {
            check_positive("k", ki)?;
            check_positive("alpha", ai)?;
        }
        check_positive("Fc", fc)?;
        check_positive("Fs", fs)?;
        check_positive("vs", vs)?;
        check_positive("C", c)?;
        check_positive("delta", delta)?;
        check_nonneg("sigma2", sigma2)?;
        Ok(Self {
            k: k.to_vec(),
            alpha: alpha.to_vec(),
            fc,
            fs,
            vs,
            c,
            delta,
            sigma2,
        })
    }
}

impl Law for Gms {
    type State = GmsState;
    fn start(&self, x0: f64) -> GmsState {
        let n = self.k.len();
        GmsState {
            xp: x0,
            f: vec![0.0; n],
            slip: vec![0.0; n],
        }
    }
    fn step(&self, st: &mut GmsState, dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        st.xp = x;
        let (v, g) = match dt {
            None => (0.0, self.fs),
            Some(dt) => {
                let v = dx / dt;
                (v, stribeck(self.fc, self.fs, self.vs, self.delta, v))
            }
        };
        let mut total = 0.0;
        if dx == 0.0 {
            for &f in &st.f {
                total += f;
            }
        } else {
            let s = sign(dx);
            for (((&k, &a), f), slip) in self
                .k
                .iter()
                .zip(&self.alpha)
                .zip(st.f.iter_mut())
                .zip(st.slip.iter_mut())
            {
                let lim = a * g;
                let target = s * lim;
                if *slip != 0.0 && *slip != s {
                    *slip = 0.0;
                }
                if *slip == 0.0 {
                    let fnew = *f + k * dx;
                    if s * fnew <= lim {
                        *f = fnew;
                    } else {
                        *f = target;
                        *slip = s;
                    }
                } else {
                    match dt {
                        None => *f = target,
                        Some(dt) => *f = target + (*f - target) * (-self.c * dt / lim).exp(),
                    }
                }
                total += *f;
            }
        }
        total + self.sigma2 * v
    }
}
