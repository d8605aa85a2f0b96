//! Linear structures with hysteretic joints (issue 10):
//! `M x'' + C x' + K x + Σ F_j = f + K r y + C r ẏ`, integrated by implicit Newmark (average
//! acceleration) with Newton iterations on the joint forces.
//!
//! - [`joint`]: the joint laws (Masing, Jenkins, Iwan, Bouc-Wen, Kelvin-Voigt, nonlinear normal
//!   contact stiffness), their tangents, events and stored energy.
//! - [`newmark`]: the integrator, sample-exact outputs, energy bookkeeping.
//! - [`dense`]: allocation-free LU for the Newton systems.
//! - `sdof`: the integrator specialised to one DOF (scalars throughout).

pub(crate) mod dense;
pub mod joint;
pub mod newmark;
mod sdof;

pub use joint::{Joint, JointLaw, JointState, MasingCurve, Trial};
pub use newmark::{
    simulate, simulate_into, Buffers, Inputs, Options, Response, Status, Structure, Summary,
};
