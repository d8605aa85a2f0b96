//! Normal contact of machined joints (Konowalski 2009; PHYSICS.md §2).
//!
//! - [`poly`]: the loop polynomials (eq. 1), k_s(δ) (eq. 6) and k_s(p) (eq. 16); least squares.
//! - [`kelvin_voigt`]: linear Kelvin-Voigt model and its analytic steady state (eqs. 8-15).
//! - [`model`]: the contact ODE `δ' = (2π ω / ψ)(p / k_s − δ)` for constant, δ- or
//!   p-dependent stiffness (eq. 17).
//! - [`forcing`]: the sampled pressure continued between samples (linear or cubic Hermite).
//! - [`grid`]: the fixed-grid exponential integrator on the record's own samples (the
//!   diagnosis' fits; [`ode`] is its accurate reference).
//! - [`ode`]: the error-controlled solve, stepping sample to sample, for recordings of any
//!   length: Taylor series per interval ([`taylor`]), RODAS4 where the interval is stiff.
//! - [`cycles`]: folding a recording into whole cycles on a common phase grid.

pub mod cycles;
pub mod forcing;
pub mod grid;
pub mod kelvin_voigt;
pub mod model;
pub mod ode;
pub mod poly;
pub mod taylor;

pub use forcing::{Forcing, Interp};
pub use kelvin_voigt::KelvinVoigt;
pub use model::{ContactModel, Stiffness};
pub use ode::{simulate, simulate_with, Method, Options, Outcome, Stats, Status};
