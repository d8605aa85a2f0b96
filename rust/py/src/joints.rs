//! Binding of `contactlab_core::joints`: a joint law's operator built from a nested
//! description, pushing chunks with the GIL released. Conversion only.

use contactlab_core::joints::sens::force_sens;
use contactlab_core::joints::{AnyLaw, Operator};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use crate::detach_guarded;
use crate::errors::{input, slice, to_pyerr};

/// A law from `(kind, params, children)` (params: the law's own floats; children: a list of
/// such tuples), nested to at most 64 levels.
fn build(py: Python<'_>, spec: &Bound<'_, PyAny>, depth: usize) -> PyResult<AnyLaw> {
    if depth > 64 {
        return Err(input(py, "joint law description is nested too deeply"));
    }
    let tup = spec.cast::<PyTuple>().map_err(|_| {
        input(
            py,
            "a joint law description is a tuple (kind, params, children)",
        )
    })?;
    if tup.len() != 3 {
        return Err(input(
            py,
            "a joint law description is a tuple (kind, params, children)",
        ));
    }
    let kind: String = tup
        .get_item(0)?
        .extract()
        .map_err(|_| input(py, "a joint law's kind must be a string"))?;
    let params: Vec<f64> = tup
        .get_item(1)?
        .extract()
        .map_err(|_| input(py, "a joint law's params must be a list of floats"))?;
    let kids = tup.get_item(2)?;
    let kids = kids
        .cast::<PyList>()
        .map_err(|_| input(py, "a joint law's children must be a list"))?;
    let mut children = Vec::with_capacity(kids.len());
    for k in kids.iter() {
        children.push(build(py, &k, depth.saturating_add(1))?);
    }
    AnyLaw::build(&kind, &params, children).map_err(|e| to_pyerr(py, &e))
}

/// A joint law with its carried state (`contactlab_core::joints::Operator`).
#[pyclass(module = "contactlab._core")]
struct JointOperatorCore {
    op: Operator,
}

#[pymethods]
impl JointOperatorCore {
    #[new]
    fn new(py: Python<'_>, spec: &Bound<'_, PyAny>, x0: f64) -> PyResult<Self> {
        let law = build(py, spec, 0)?;
        let op = Operator::new(law, x0).map_err(|e| to_pyerr(py, &e))?;
        Ok(Self { op })
    }

    /// Forces of the next chunk `(t, x)` (`t` None for a rate-independent law).
    #[pyo3(signature = (t, x))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        t: Option<PyReadonlyArray1<'py, f64>>,
        x: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let xs = slice(&x, "x")?;
        let ts = match &t {
            Some(t) => Some(slice(t, "t")?),
            None => None,
        };
        let arr = PyArray1::<f64>::zeros(py, xs.len(), false);
        {
            let mut rw = arr
                .try_readwrite()
                .map_err(|_| input(py, "internal: output not writeable"))?;
            let out = rw
                .as_slice_mut()
                .map_err(|_| input(py, "internal: output not contiguous"))?;
            let op = &mut self.op;
            detach_guarded(py, || op.push(ts, xs, out))?;
        }
        Ok(arr)
    }

    /// Back to the relaxed state at `x0`.
    fn reset(&mut self) {
        self.op.reset();
    }

    /// True when the law needs sample times.
    #[getter]
    fn rate_dependent(&self) -> bool {
        self.op.law().rate_dependent()
    }

    /// A copy with the same law and carried state.
    fn copy(&self) -> Self {
        Self {
            op: self.op.clone(),
        }
    }
}

/// Forces of a whole history from the relaxed state at `x0` and their forward sensitivities
/// to the law's parameters: `(F, J)`, `J` of shape `(len(x), n_params)`.
#[pyfunction]
#[pyo3(signature = (spec, t, x, x0))]
#[allow(clippy::type_complexity)]
fn joint_force_sens<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyAny>,
    t: Option<PyReadonlyArray1<'py, f64>>,
    x: PyReadonlyArray1<'py, f64>,
    x0: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
    let law = build(py, spec, 0)?;
    let xs = slice(&x, "x")?;
    let ts = match &t {
        Some(t) => Some(slice(t, "t")?),
        None => None,
    };
    let np = law.n_params();
    let (f, jac) = detach_guarded(py, || force_sens(&law, ts, xs, x0))?;
    let n = f.len();
    let jac = jac.into_pyarray(py).reshape([n, np])?;
    Ok((f.into_pyarray(py), jac))
}

/// True when [`joint_force_sens`] differentiates the law (else: finite differences).
#[pyfunction]
fn joint_has_sens(py: Python<'_>, spec: &Bound<'_, PyAny>) -> PyResult<bool> {
    Ok(build(py, spec, 0)?.sens_len().is_some())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<JointOperatorCore>()?;
    m.add_function(wrap_pyfunction!(joint_force_sens, m)?)?;
    m.add_function(wrap_pyfunction!(joint_has_sens, m)?)?;
    Ok(())
}
