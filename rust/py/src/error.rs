//! Binding of `contactlab_core::error`: every `CoreError` variant and the binding's own
//! argument errors mapped to the Python exception hierarchy of `contactlab/errors.py`
//! (`ContactLabError` > `InputError(ValueError)`), in one place ([`class_of`]).

use contactlab_core::CoreError;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

/// The Python exception classes of `contactlab.errors` the binding raises.
#[derive(Clone, Copy)]
pub enum Class {
    /// `ContactLabError`: a bug in contactlab, not in the input.
    Internal,
    /// `InputError`: the input (arrays, parameters, states) is what is wrong.
    Input,
}

/// The class of each core error: every `CoreError` is about the input (a solve that does not
/// converge returns a failure status instead). A new variant must be placed here.
pub fn class_of(e: &CoreError) -> Class {
    match e {
        CoreError::NonFinite { .. }
        | CoreError::Empty { .. }
        | CoreError::LengthMismatch { .. }
        | CoreError::InvalidParameter { .. }
        | CoreError::NotIncreasing { .. }
        | CoreError::InvalidBackbone { .. }
        | CoreError::InvalidState { .. }
        | CoreError::OutOfRange { .. }
        | CoreError::TooLong { .. }
        | CoreError::NonPositiveStiffness { .. }
        | CoreError::NoSolution { .. }
        | CoreError::InvalidLaw { .. } => Class::Input,
    }
}

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

/// An exception of class `which` with message `msg` (`ValueError` if `contactlab.errors`
/// cannot be imported).
pub fn raise(py: Python<'_>, which: Class, msg: String) -> PyErr {
    match classes(py) {
        Some(c) => {
            let cls = match which {
                Class::Internal => &c.0,
                Class::Input => &c.1,
            };
            match cls.bind(py).call1((msg.clone(),)) {
                Ok(inst) => PyErr::from_value(inst),
                Err(e) => e,
            }
        }
        None => PyErr::new::<pyo3::exceptions::PyValueError, _>(msg),
    }
}

/// A core error as its Python exception ([`class_of`]).
pub fn to_pyerr(py: Python<'_>, e: &CoreError) -> PyErr {
    raise(py, class_of(e), e.to_string())
}

/// `InputError` with a message of the binding's own (an argument the core never sees).
pub fn input(py: Python<'_>, msg: impl Into<String>) -> PyErr {
    raise(py, Class::Input, msg.into())
}

/// `ContactLabError` for a condition that is a bug in contactlab, not in the input.
pub fn internal(py: Python<'_>, msg: &str) -> PyErr {
    raise(py, Class::Internal, msg.to_string())
}

/// The data of a 1-d float array; a non-contiguous one is an `InputError` naming it.
pub fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &'static str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| input(a.py(), format!("{name} must be a contiguous array")))
}
