//! Linear Kelvin-Voigt contact (Konowalski 2009, eqs. 8-15; PHYSICS.md §2).
//!
//! `p = k δ + h δ'`, `h = ψ k / (2π ω)` (eq. 13). Under `p = pa sin ω t` the steady state is
//! `δ = K sin(ω t − φ)` with `K = (pa / k) / sqrt(1 + (ψ / 2π)²)` (eq. 14) and
//! `φ = arctan(ψ / 2π)` (eq. 15); the loop is an ellipse of area `π pa K sin φ`, which makes
//! `E_d / E_pu = ψ` with `E_pu = k K² / 2` (eq. 3).

use std::f64::consts::PI;

use super::model::{ContactModel, Stiffness};
use crate::error::{check_finite, check_positive, CoreError};

/// Kelvin-Voigt parameters: stiffness `k` (Pa/m), dissipation coefficient `ψ`, angular
/// frequency `ω` (rad/s) at which `ψ` holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KelvinVoigt {
    pub k: f64,
    pub psi: f64,
    pub omega: f64,
}

impl KelvinVoigt {
    pub fn new(k: f64, psi: f64, omega: f64) -> Result<Self, CoreError> {
        check_positive("k", k)?;
        check_positive("psi", psi)?;
        check_positive("omega", omega)?;
        let kv = Self { k, psi, omega };
        let g = psi / (2.0 * PI);
        crate::error::check_output("damping, (psi/2pi)^2", &[kv.damping(), g * g])?;
        Ok(kv)
    }

    /// Damping coefficient `h = ψ k / (2π ω)` (eq. 13).
    pub fn damping(&self) -> f64 {
        self.psi * self.k / (2.0 * PI * self.omega)
    }

    /// Steady amplitude `K` under `pa sin ω t` (eq. 14).
    pub fn amplitude(&self, pa: f64) -> f64 {
        let g = self.psi / (2.0 * PI);
        pa / self.k / (1.0 + g * g).sqrt()
    }

    /// Phase lag `φ` (eq. 15).
    pub fn phase(&self) -> f64 {
        (self.psi / (2.0 * PI)).atan()
    }

    /// Dissipated energy per cycle, the ellipse area `π pa K sin φ`.
    pub fn loop_energy(&self, pa: f64) -> f64 {
        // sin φ (< 1) first: π pa overflowing while sin φ underflows to 0 gave inf · 0 = NaN
        // (found by AFL++); in this order the product is finite or, truly beyond range, inf
        PI * (self.phase().sin() * self.amplitude(pa) * pa)
    }

    /// Steady-state displacement and velocity at times `t` under `pa sin ω t`.
    pub fn steady_state(
        &self,
        pa: f64,
        t: &[f64],
        delta: &mut [f64],
        velocity: &mut [f64],
    ) -> Result<(), CoreError> {
        if !pa.is_finite() {
            return Err(CoreError::InvalidParameter {
                name: "pa",
                value: pa,
                reason: "must be finite",
            });
        }
        check_finite("t", t)?;
        crate::error::check_same_len("t", t.len(), "delta (output)", delta.len())?;
        crate::error::check_same_len("t", t.len(), "velocity (output)", velocity.len())?;
        let (a, phi, w) = (self.amplitude(pa), self.phase(), self.omega);
        for ((d, v), &tt) in delta.iter_mut().zip(velocity.iter_mut()).zip(t) {
            let x = w * tt - phi;
            *d = a * x.sin();
            *v = a * w * x.cos();
        }
        crate::error::check_output("delta", delta)?;
        crate::error::check_output("velocity", velocity)?;
        Ok(())
    }

    /// The same model as an ODE for [`super::ode::simulate`].
    pub fn to_model(&self) -> Result<ContactModel, CoreError> {
        ContactModel::new(Stiffness::Constant(self.k), self.psi, self.omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_ratio_is_psi() {
        let kv = KelvinVoigt::new(1.206e12, 0.0887, 1.0).unwrap();
        let pa = 0.4e6;
        let k_amp = kv.amplitude(pa);
        let e_pu = 0.5 * kv.k * k_amp * k_amp;
        assert!((kv.loop_energy(pa) / e_pu - 0.0887).abs() < 1e-14);
        // eq. 11 and eq. 14 agree.
        let h = kv.damping();
        let k11 = pa / (kv.k * kv.k + (h * kv.omega).powi(2)).sqrt();
        assert!((k11 - k_amp).abs() < 1e-15 * k_amp.abs().max(1e-300) * 1e3);
        assert!((kv.phase() - (h * kv.omega / kv.k).atan()).abs() < 1e-15);
    }

    #[test]
    fn loop_energy_of_extreme_parameters_is_not_nan() {
        // found by AFL++ (fuzz/afl): k = 1e300, ψ = 5e-324 (sin φ = 0), pa = f64::MAX
        let kv = KelvinVoigt::new(1e300, 5e-324, 2.96e-308).unwrap();
        let e = kv.loop_energy(f64::MAX);
        assert!(e.is_finite() && e >= 0.0, "{e}");
        let kv = KelvinVoigt::new(2.0, 0.3, 1.0).unwrap();
        let g = 0.3 / (2.0 * PI);
        let expect = PI * 5.0 * (5.0 / 2.0) * g / (1.0 + g * g); // π pa² sinφ cosφ / k
        assert!((kv.loop_energy(5.0) / expect - 1.0).abs() < 1e-14);
    }

    #[test]
    fn steady_state_rejects_non_finite_amplitude() {
        let kv = KelvinVoigt::new(1.0, 0.1, 1.0).unwrap();
        let t = [0.0, 0.5, 1.0];
        let (mut d, mut v) = ([0.0; 3], [0.0; 3]);
        for pa in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let r = kv.steady_state(pa, &t, &mut d, &mut v);
            assert!(matches!(
                r,
                Err(CoreError::InvalidParameter { name: "pa", .. })
            ));
        }
        assert!(kv.steady_state(0.4, &t, &mut d, &mut v).is_ok());
    }

    #[test]
    fn rejects_non_positive() {
        assert!(KelvinVoigt::new(1.0, 0.0, 1.0).is_err());
        assert!(KelvinVoigt::new(0.0, 0.1, 1.0).is_err());
        assert!(KelvinVoigt::new(1.0, 0.1, -1.0).is_err());
    }
}
