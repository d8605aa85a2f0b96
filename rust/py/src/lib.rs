//! `contactlab._core`: converts numpy arrays and errors, releases the GIL, and nothing else.
//! All physics lives in `contactlab-core`; each module here binds the core module of the same
//! name (`error` maps `CoreError` to the Python exception classes).

// PyO3 extracts arguments by value; borrowing them is not an option in signatures.
#![allow(clippy::needless_pass_by_value)]

use contactlab_core::CoreError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

mod cycles;
mod error;
mod extrema;
mod fold;
mod isotonic;
mod joints;
mod loop_area;
mod loop_fit;
mod masing;
mod normal;
mod reversal;
mod scan;
mod select;
mod simd;
mod stream;
mod structure;
mod window;
use error::{internal, to_pyerr};
// The old name of `error`, still used by `joints.rs` (owned by another change; drop the alias
// once it imports `crate::error`).
use error as errors;

/// A float array returned to Python.
pub(crate) type Arr<'py> = Bound<'py, numpy::PyArray1<f64>>;
/// Two float arrays.
pub(crate) type FloatPair<'py> = (Arr<'py>, Arr<'py>);
/// Two index arrays.
pub(crate) type IndexPair<'py> = (
    Bound<'py, numpy::PyArray1<i64>>,
    Bound<'py, numpy::PyArray1<i64>>,
);

/// Run `f` without the GIL, turning a panic (a bug, never expected) into `ContactLabError`.
pub(crate) fn detach_guarded<T: Send, F: FnOnce() -> Result<T, CoreError> + Send>(
    py: Python<'_>,
    f: F,
) -> PyResult<T> {
    let r = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match r {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_pyerr(py, &e)),
        Err(_) => Err(internal(
            py,
            "internal error in contactlab core (panic caught)",
        )),
    }
}

static VERSION: PyOnceLock<String> = PyOnceLock::new();

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add(
        "__version__",
        VERSION.get_or_init(py, || env!("CARGO_PKG_VERSION").to_string()),
    )?;
    masing::register(m)?;
    loop_area::register(m)?;
    normal::register(m)?;
    structure::register(m)?;
    reversal::register(m)?;
    fold::register(m)?;
    cycles::register(m)?;
    select::register(m)?;
    window::register(m)?;
    isotonic::register(m)?;
    extrema::register(m)?;
    scan::register(m)?;
    simd::register(m)?;
    stream::register(m)?;
    loop_fit::register(m)?;
    joints::register(m)?;
    Ok(())
}
