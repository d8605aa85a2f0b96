//! Binding of the steady-loop Levenberg–Marquardt fit (`contactlab_core::loop_fit`).

use contactlab_core::loop_fit::{fit_steady_loop, FitSetup, SteadyLoop, TurnPrior, N_PARAMS};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::slice;

type Five = [f64; N_PARAMS];
/// `(x0 or None, amplitude or None, sigma, scale)` of the turning-point prior.
type PriorArgs = (Option<f64>, Option<f64>, f64, f64);
/// `(values, vary, scale, lower, upper)` of the parameters.
type SetupArgs = (Five, [bool; N_PARAMS], Five, Five, Five);

/// Fit the steady Masing loop to averaged bins (GIL released). `prior`: `(x0 or None,
/// amplitude or None, sigma, scale)`; `setup`: `(values, vary, scale, lower, upper)`
/// (bounds of `value / scale`); `tol`: `(rscale, ftol, xtol, gtol)`. Returns `(values,
/// nfev, status)` (status as SciPy's `least_squares`: 0 = evaluation budget exhausted).
#[pyfunction]
#[pyo3(name = "fit_steady_loop")]
fn fit_steady_loop_py(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    f: PyReadonlyArray1<'_, f64>,
    w: PyReadonlyArray1<'_, f64>,
    bin_var: Option<PyReadonlyArray1<'_, f64>>,
    prior: Option<PriorArgs>,
    setup: SetupArgs,
    tol: (f64, f64, f64, f64),
    max_nfev: usize,
) -> PyResult<(Five, usize, i32)> {
    let (xs, fs, ws) = (slice(&x, "x")?, slice(&f, "F")?, slice(&w, "w")?);
    let bv = match &bin_var {
        Some(a) => Some(slice(a, "bin_var")?),
        None => None,
    };
    let prior = prior.map(|(x0, amplitude, sigma, scale)| TurnPrior {
        x0,
        amplitude,
        sigma,
        scale,
    });
    let (values, vary, scale, lower, upper) = setup;
    let (rscale, ftol, xtol, gtol) = tol;
    let s = FitSetup {
        values,
        vary,
        scale,
        lower,
        upper,
        rscale,
        ftol,
        xtol,
        gtol,
        max_nfev,
    };
    let fit = detach_guarded(py, || {
        let data = SteadyLoop::new(xs, fs, ws, bv, prior)?;
        fit_steady_loop(&data, &s)
    })?;
    Ok((fit.values, fit.nfev, fit.status))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit_steady_loop_py, m)?)?;
    Ok(())
}
