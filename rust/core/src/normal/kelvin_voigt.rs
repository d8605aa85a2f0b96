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
        // π pa K sin φ = pa² (ψ/k) / (2 (1 + g²)), g = ψ/2π: written so, no factor is
        // inf while another is 0 (π·pa overflowing or K = pa/k overflowing against sin φ
        // underflowing gave inf · 0 = NaN, found by AFL++); inf only when E truly is
        if pa == 0.0 {
            return 0.0;
        }
        let g = self.psi / (2.0 * PI);
        let direct = 0.5 * pa * (pa * (self.psi / self.k)) / (1.0 + g * g);
        if direct.is_finite() && direct > 0.0 {
            return direct;
        }
        // a factor overflowed or underflowed (k = pa = 5e-324 with ψ = 179 made ψ/k = inf
        // against 0.5 pa = 0: NaN, found by the kernels fuzz target): the same product in
        // logarithms, which is inf or 0 only when E itself is out of range
        let ln_1p_g2 = if g > 1e150 {
            2.0 * g.ln()
        } else {
            (g * g).ln_1p()
        };
        (2.0 * pa.abs().ln() + self.psi.ln() - self.k.ln() - ln_1p_g2 - std::f64::consts::LN_2)
            .exp()
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
        // the kernels fuzz target: k = pa = 5e-324, ψ = 178.6 made ψ/k = inf against
        // 0.5·pa = 0; E = pa² (ψ/k) / (2 (1 + g²)) underflows to 0
        let kv =
            KelvinVoigt::new(5e-324, 178.612_225_093_573_4, 0.002_097_592_964_408_458_6).unwrap();
        let e = kv.loop_energy(5e-324);
        assert!(e.is_finite() && e >= 0.0, "{e}");
        // ψ/k underflowing to 0 while E is ordinary: pa = 1e200, k = 1e100, ψ = 1e-300 give
        // E = pa² ψ / (2 k (1 + g²)) = 0.5 (the logarithmic route)
        let kv = KelvinVoigt::new(1e100, 1e-300, 1.0).unwrap();
        let e = kv.loop_energy(1e200);
        assert!((e / 0.5 - 1.0).abs() < 1e-12, "{e}");
        // the re-run: k = ψ = 5e-324 made K = pa/k inf against sin φ = 0; E = pa² ψ/(2k)
        let kv = KelvinVoigt::new(5e-324, 5e-324, 4.45e-308).unwrap();
        assert!(
            (kv.loop_energy(3.0) / 4.5 - 1.0).abs() < 1e-12,
            "{}",
            kv.loop_energy(3.0)
        );
        assert_eq!(kv.loop_energy(0.0), 0.0);
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
