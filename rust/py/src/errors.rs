//! Map `CoreError` to the Python exception hierarchy defined in `contactlab/errors.py`
//! (`ContactLabError` > `InputError(ValueError)`, `ConvergenceError(RuntimeError)`).

use contactlab_core::CoreError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

static ERRORS: PyOnceLock<(Py<PyType>, Py<PyType>, Py<PyType>)> = PyOnceLock::new();

fn classes(py: Python<'_>) -> Option<&(Py<PyType>, Py<PyType>, Py<PyType>)> {
    ERRORS
        .get_or_try_init(py, || -> PyResult<_> {
            let m = py.import("contactlab.errors")?;
            let get = |n: &str| -> PyResult<Py<PyType>> {
                Ok(m.getattr(n)?.cast_into::<PyType>()?.unbind())
            };
            Ok((
                get("ContactLabError")?,
                get("InputError")?,
                get("ConvergenceError")?,
            ))
        })
        .ok()
}

fn make(py: Python<'_>, which: usize, msg: String) -> PyErr {
    match classes(py) {
        Some(c) => {
            let cls = match which {
                0 => &c.0,
                1 => &c.1,
                _ => &c.2,
            };
            match cls.bind(py).call1((msg.clone(),)) {
                Ok(inst) => PyErr::from_value(inst),
                Err(e) => e,
            }
        }
        None => PyErr::new::<pyo3::exceptions::PyValueError, _>(msg),
    }
}

/// Convert a core error to `InputError` or `ConvergenceError`.
pub fn to_pyerr(py: Python<'_>, e: &CoreError) -> PyErr {
    let which = match e {
        CoreError::StepSizeTooSmall { .. } => 2,
        _ => 1,
    };
    make(py, which, e.to_string())
}

/// `ContactLabError` for a condition that is a bug in contactlab, not in the input.
pub fn internal(py: Python<'_>, msg: &str) -> PyErr {
    make(py, 0, msg.to_string())
}

/// `InputError` with a message (bad arguments the binding itself detects).
pub fn input(py: Python<'_>, msg: &str) -> PyErr {
    make(py, 1, msg.to_string())
}
