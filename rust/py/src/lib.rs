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

/// Load numpy's C-API table now, at import, with SIGINT deferred.
///
/// The `numpy` crate loads the table on the first array it touches, and that load runs Python
/// code (`numpy.lib.NumpyVersion`); a Ctrl-C landing there turns into a panic inside the crate
/// (`expect("Failed to access NumPy array API capsule")`), seen as `PanicException` and status 1
/// instead of an interrupt (a `demo` run given SIGINT while its first Masing loop was drawn).
/// Here the load runs under `contactlab._interrupt.deferred()`: an interrupt over it is held
/// back and raised as `KeyboardInterrupt` from the import, which fails cleanly and can be
/// retried (the table stays unloaded until a load succeeds).
fn load_numpy_api(py: Python<'_>) -> PyResult<()> {
    let guard = py
        .import("contactlab._interrupt")?
        .getattr("deferred")?
        .call0()?;
    guard.call_method0("__enter__")?;
    // Any array creation loads the table; a zero-length one costs nothing more.
    let _ = numpy::PyArray1::<f64>::zeros(py, 0, false);
    let none = py.None();
    guard.call_method1("__exit__", (none.clone_ref(py), none.clone_ref(py), none))?;
    Ok(())
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    load_numpy_api(py)?;
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
