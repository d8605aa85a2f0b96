//! One error type for the whole core. Every variant carries the data a user needs to find the
//! problem (which argument, which index); the Python binding maps them to
//! `contactlab.InputError`. A solver that does not converge is not an error: it returns its
//! partial result with a failure status (see `normal::ode::Status`).

/// Errors returned by core kernels. The core never panics on user input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CoreError {
    /// A sample is NaN or infinite.
    #[error("{name}[{index}] is not finite ({value})")]
    NonFinite {
        name: &'static str,
        index: usize,
        value: f64,
    },
    /// An input array has no samples.
    #[error("{name} is empty")]
    Empty { name: &'static str },
    /// Two arrays that must be sample-aligned differ in length.
    #[error("{name_a} has {len_a} samples but {name_b} has {len_b}")]
    LengthMismatch {
        name_a: &'static str,
        len_a: usize,
        name_b: &'static str,
        len_b: usize,
    },
    /// A scalar parameter is outside its valid range.
    #[error("parameter {name} = {value} is invalid: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// An array that must be strictly increasing is not.
    #[error("{name} must be strictly increasing, but {name}[{index}] = {value} does not exceed {name}[{prev_index}] = {prev}", prev_index = index.saturating_sub(1))]
    NotIncreasing {
        name: &'static str,
        index: usize,
        value: f64,
        prev: f64,
    },
    /// A backbone (virgin curve) table violates a requirement.
    #[error("backbone is invalid at point {index}: {reason}")]
    InvalidBackbone { index: usize, reason: &'static str },
    /// An exported operator state cannot be restored.
    #[error("operator state is invalid: {reason}")]
    InvalidState { reason: &'static str },
    /// A result does not fit in double precision although every input did (overflow, or an
    /// underflow that became 0·∞): the input's magnitudes are too extreme in its units.
    #[error("{what}[{index}] is out of the double-precision range ({value}) although the inputs are finite: their magnitudes are too extreme in these units; rescale the data (other units)")]
    OutOfRange {
        what: &'static str,
        index: usize,
        value: f64,
    },
    /// A signal is too long for the sample counter (global indices must fit in 63 bits).
    #[error("a chunk of {len} samples would overflow the operator's sample counter")]
    TooLong { len: usize },
    /// A composite joint law (series, backlash) found no force balance in a step.
    #[error("{what}: no force balance at sample {index} (a law whose force decreases as its displacement grows)")]
    NoSolution { what: &'static str, index: usize },
    /// A joint-law description names no known law or has the wrong shape.
    #[error("joint law {kind:?}: {reason}")]
    InvalidLaw { kind: String, reason: String },
    /// A stiffness function is not positive where it is evaluated.
    #[error("stiffness is not positive ({value}) at {name} = {at}")]
    NonPositiveStiffness {
        name: &'static str,
        at: f64,
        value: f64,
    },
}

/// Return `Err(NonFinite)` naming the first non-finite sample of `data`.
pub fn check_finite(name: &'static str, data: &[f64]) -> Result<(), CoreError> {
    // blocks of 64 tested without an early exit (the compiler vectorises that, for the
    // CPU's SIMD level), the first offending index searched only in a block that has one
    if all_finite_at(crate::simd::level(), data) {
        return Ok(());
    }
    match data.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(CoreError::NonFinite {
            name,
            index,
            value: data[index],
        }),
        None => Ok(()),
    }
}

crate::simd::dispatch! {
    /// Whether every value of `data` is finite, the scan compiled for `level`.
    fn all_finite_at(data: &[f64]) -> bool = all_finite_generic;
}

#[inline(always)]
fn all_finite_generic(data: &[f64]) -> bool {
    data.chunks(64)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
}

/// Return `Err(OutOfRange)` naming the first non-finite value of a kernel's result (inputs
/// already checked finite: a NaN or ±inf here is an overflow, never a success).
pub fn check_output(what: &'static str, data: &[f64]) -> Result<(), CoreError> {
    match data.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(CoreError::OutOfRange {
            what,
            index,
            value: data[index],
        }),
        None => Ok(()),
    }
}

/// Return `Err(InvalidParameter)` unless `value` is finite and strictly positive.
pub fn check_positive(name: &'static str, value: f64) -> Result<(), CoreError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(CoreError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        })
    }
}

/// Return `Err(LengthMismatch)` unless the two lengths agree.
pub fn check_same_len(
    name_a: &'static str,
    len_a: usize,
    name_b: &'static str,
    len_b: usize,
) -> Result<(), CoreError> {
    if len_a == len_b {
        Ok(())
    } else {
        Err(CoreError::LengthMismatch {
            name_a,
            len_a,
            name_b,
            len_b,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_finiteness_scan_is_the_same_on_every_simd_level() {
        for n in [0_usize, 1, 63, 64, 65, 1000] {
            let v: Vec<f64> = (0..n).map(|i| i as f64 - 3.5).collect();
            for bad in [
                None,
                Some(f64::NAN),
                Some(f64::INFINITY),
                Some(f64::NEG_INFINITY),
            ] {
                for at in [0, n / 2, n.saturating_sub(1)] {
                    let mut w = v.clone();
                    if let (Some(b), true) = (bad, n > 0) {
                        w[at] = b;
                    }
                    let want = w.iter().all(|x| x.is_finite());
                    for level in crate::simd::Level::ALL
                        .into_iter()
                        .filter(|l| l.supported())
                    {
                        assert_eq!(all_finite_at(level, &w), want, "{level:?} n={n} at={at}");
                    }
                    assert_eq!(check_finite("v", &w).is_ok(), want);
                }
            }
        }
    }
}
