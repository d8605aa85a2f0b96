//! Map `CoreError` (and the binding's own argument errors) to the Python exception hierarchy
//! defined in `contactlab/errors.py` (`ContactLabError` > `InputError(ValueError)`).

use contactlab_core::CoreError;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

static ERRORS: PyOnceLock<(Py<PyType>, Py<PyType>)> = PyOnceLock::new();

fn classes(py: Python<'_>) -> Option<&(Py<PyType>, Py<PyType>)> {
    ERRORS
        .get_or_try_init(py, || -> PyResult<_> {
            let m = py.import("contactlab.errors")?;
            let get = |n: &str| -> PyResult<Py<PyType>> {
                Ok(m.getattr(n)?.cast_into::<PyType>()?.unbind())
            };
            Ok((get("ContactLabError")?, get("InputError")?))
        })
        .ok()
}

fn make(py: Python<'_>, which: usize, msg: String) -> PyErr {
    match classes(py) {
        Some(c) => {
            let cls = if which == 0 { &c.0 } else { &c.1 };
            match cls.bind(py).call1((msg.clone(),)) {
                Ok(inst) => PyErr::from_value(inst),
                Err(e) => e,
            }
        }
        None => PyErr::new::<pyo3::exceptions::PyValueError, _>(msg),
    }
}

/// Convert a core error to `InputError`: every `CoreError` is about the input (a solve that
/// does not converge returns a failure status instead).
pub fn to_pyerr(py: Python<'_>, e: &CoreError) -> PyErr {
    make(py, 1, e.to_string())
}

/// `InputError` with a message of the binding's own (an argument the core never sees).
pub fn input_error(py: Python<'_>, msg: String) -> PyErr {
    make(py, 1, msg)
}

/// The data of a 1-d float array; a non-contiguous one is an `InputError` naming it.
pub fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &'static str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| input_error(a.py(), format!("{name} must be a contiguous array")))
}

/// `ContactLabError` for a condition that is a bug in contactlab, not in the input.
pub fn internal(py: Python<'_>, msg: &str) -> PyErr {
    make(py, 0, msg.to_string())
}

/// `InputError` with a message (bad arguments the binding itself detects).
pub fn input(py: Python<'_>, msg: &str) -> PyErr {
    make(py, 1, msg.to_string())
}
