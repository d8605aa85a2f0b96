//! contactlab-core: contact-joint hysteresis kernels with no Python dependency.
//!
//! - [`curve`]: virgin curves (the exponential curve of the tangential-contact paper, tabulated
//!   measured backbones).
//! - [`isotonic`]: isotonic regression (PAVA) and the monotone projection of a path.
//! - [`joints`]: displacement-driven joint laws (Jenkins, Iwan, Segalman, Maxwell-slip, Dahl,
//!   LuGre, Bouc-Wen, composed in series / parallel / behind a backlash).
//! - [`loop_fit`]: Levenberg–Marquardt fit of the steady Masing loop to an averaged cycle.
//! - [`masing`]: the Masing operator with non-local memory, cycle counting and loop areas.
//! - [`parallel`]: independent jobs (channels, recordings) on scoped threads.
//! - [`scan`]: byte-signature search (the HDF5 structure checks).
//! - [`reversal`]: streaming reversal detection by a hysteresis threshold.
//! - [`fold`]: phase-bin folding of a periodic recording and its cycle-to-cycle spread.
//! - [`cycles`]: blocks of whole cycles cut at the drive's crossings; period means.
//! - [`loop_area`]: loop areas of cycles and their noise sensitivity.
//! - [`simd`]: runtime dispatch of the vectorised kernels (baseline, AVX2, AVX-512).
//! - [`stream`]: the reading side of a streamed analysis (chunk checks, time axis).
//! - [`window`]: the per-sample work of one analysis window (fold, cycle areas, detrending).
//!
//! Every kernel validates its input and returns [`CoreError`]; none panics on user data.

// Library code never unwraps and never lets an integer operation overflow or divide by zero:
// counts and sizes come from the caller. Unit tests (cfg(test)) may.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::arithmetic_side_effects
    )
)]

pub mod curve;
pub mod cycles;
pub mod error;
pub mod extrema;
pub mod fold;
pub mod isotonic;
pub mod joints;
pub mod loop_area;
pub mod loop_fit;
pub mod masing;
pub mod normal;
pub mod parallel;
pub mod raw_scan;
pub mod reversal;
pub mod scan;
pub mod select;
pub mod simd;
pub mod stream;
pub mod structure;
pub mod window;

pub use curve::{Backbone, Exponential, Tabulated};
pub use error::CoreError;
pub use masing::{
    branch_memory, cycle_energies, loop_area, masing_force, masing_force_rule, BranchRule, Cycle,
    MasingState,
};
