//! contactlab-core: contact-joint hysteresis kernels with no Python dependency.
//!
//! - [`curve`]: virgin curves (the exponential curve of the tangential-contact paper, tabulated
//!   measured backbones).
//! - [`masing`]: the Masing operator with non-local memory, cycle counting and loop areas.
//! - [`signal`]: streaming reversal detection by a hysteresis threshold.
//!
//! Every kernel validates its input and returns [`CoreError`]; none panics on user data.

pub mod curve;
pub mod error;
pub mod masing;
pub mod normal;
pub mod signal;
pub mod structure;

pub use curve::{Backbone, Exponential, Tabulated};
pub use error::CoreError;
pub use masing::{
    branch_memory, cycle_energies, loop_area, masing_force, masing_force_rule, BranchRule, Cycle,
    MasingState,
};
