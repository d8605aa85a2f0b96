//! Bindings of `contactlab_core::normal`: array/error conversion and GIL release only.

use contactlab_core::normal::{
    cycles, grid, ode, poly, ContactModel, Forcing, Interp, KelvinVoigt, Stiffness,
};
use contactlab_core::CoreError;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::{slice, to_pyerr};

fn bad(name: &'static str, reason: &'static str) -> CoreError {
    CoreError::InvalidParameter {
        name,
        value: f64::NAN,
        reason,
    }
}

fn build_model(law: &str, coeffs: &[f64], psi: f64, omega: f64) -> Result<ContactModel, CoreError> {
    let st = match law {
        "constant" => match coeffs {
            [k] => Stiffness::Constant(*k),
            _ => {
                return Err(bad(
                    "coeffs",
                    "law 'constant' takes exactly one coefficient (k)",
                ))
            }
        },
        "delta" => Stiffness::Delta(coeffs.to_vec()),
        "pressure" => Stiffness::Pressure(coeffs.to_vec()),
        _ => return Err(bad("law", "must be 'constant', 'delta' or 'pressure'")),
    };
    ContactModel::new(st, psi, omega)
}

/// The result of `normal_simulate` / `normal_simulate_grid`: the displacement and velocity
/// at the first `n_out` samples, the solver status (0 = success) with its message, and the
/// solver's counters.
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct NormalRun {
    delta: Py<PyArray1<f64>>,
    velocity: Py<PyArray1<f64>>,
    n_out: usize,
    status: i32,
    message: String,
    nfev: u64,
    njev: u64,
    nlu: u64,
    n_accepted: u64,
    n_rejected: u64,
}

impl NormalRun {
    fn new(py: Python<'_>, mut delta: Vec<f64>, mut vel: Vec<f64>, out: &ode::Outcome) -> Self {
        delta.truncate(out.n_out);
        vel.truncate(out.n_out);
        Self {
            delta: delta.into_pyarray(py).unbind(),
            velocity: vel.into_pyarray(py).unbind(),
            n_out: out.n_out,
            status: out.status.code(),
            message: out.status.message(),
            nfev: out.stats.nfev,
            njev: out.stats.njev,
            nlu: out.stats.nlu,
            n_accepted: out.stats.n_accepted,
            n_rejected: out.stats.n_rejected,
        }
    }
}

/// Integrate the contact ODE over sampled `(t, p)`; returns a `NormalRun`.
#[pyfunction]
#[pyo3(signature = (t, p, law, coeffs, psi, omega, delta0, rtol, atol, interp="cubic", dpdt=None, first_step=None, max_steps=0, method="auto"))]
fn normal_simulate<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    law: &str,
    coeffs: PyReadonlyArray1<'py, f64>,
    psi: f64,
    omega: f64,
    delta0: f64,
    rtol: f64,
    atol: f64,
    interp: &str,
    dpdt: Option<PyReadonlyArray1<'py, f64>>,
    first_step: Option<f64>,
    max_steps: u64,
    method: &str,
) -> PyResult<NormalRun> {
    let ts = slice(&t, "t")?;
    let ps = slice(&p, "p")?;
    let cs = slice(&coeffs, "coeffs")?;
    let ds = match &dpdt {
        Some(d) => Some(slice(d, "dpdt")?),
        None => None,
    };
    let law = law.to_owned();
    let interp = match interp {
        "cubic" => Interp::Cubic,
        "linear" => Interp::Linear,
        _ => return Err(to_pyerr(py, &bad("interp", "must be 'cubic' or 'linear'"))),
    };
    let method = match method {
        "auto" => ode::Method::Auto,
        "rodas4" => ode::Method::Rodas4,
        _ => return Err(to_pyerr(py, &bad("method", "must be 'auto' or 'rodas4'"))),
    };
    let opts = ode::Options {
        rtol,
        atol,
        first_step,
        max_steps,
    };
    let (delta, vel, out) = detach_guarded(py, move || {
        let model = build_model(&law, cs, psi, omega)?;
        let forcing = Forcing::new(ts, ps, ds, interp)?;
        let n = forcing.len();
        let mut delta = vec![0.0; n];
        let mut vel = vec![0.0; n];
        let out = ode::simulate_with(
            &model, &forcing, delta0, &opts, method, &mut delta, &mut vel,
        )?;
        Ok((delta, vel, out))
    })?;
    Ok(NormalRun::new(py, delta, vel, &out))
}

/// Eq. 17 on the samples' own grid (`grid::simulate_grid`); returns a `NormalRun`
/// (`njev`, `nlu` as the grid counts them). `dpdt`: the pressure's exact slopes at the samples (else finite
/// differences).
#[pyfunction]
#[pyo3(signature = (t, p, law, coeffs, psi, omega, delta0, substeps, tol, dpdt=None))]
fn normal_simulate_grid<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray1<'py, f64>,
    law: &str,
    coeffs: PyReadonlyArray1<'py, f64>,
    psi: f64,
    omega: f64,
    delta0: f64,
    substeps: usize,
    tol: f64,
    dpdt: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<NormalRun> {
    let ts = slice(&t, "t")?;
    let ps = slice(&p, "p")?;
    let cs = slice(&coeffs, "coeffs")?;
    let ds = match &dpdt {
        Some(d) => Some(slice(d, "dpdt")?),
        None => None,
    };
    let law = law.to_owned();
    let (delta, vel, out) = detach_guarded(py, move || {
        let model = build_model(&law, cs, psi, omega)?;
        let forcing = Forcing::new(ts, ps, ds, Interp::Cubic)?;
        let n = forcing.len();
        let mut delta = vec![0.0; n];
        let mut vel = vec![0.0; n];
        let out = grid::simulate_grid(
            &model, &forcing, delta0, substeps, tol, &mut delta, &mut vel,
        )?;
        Ok((delta, vel, out))
    })?;
    Ok(NormalRun::new(py, delta, vel, &out))
}

/// Equilibrium displacement `k_s δ = p` of a model under constant pressure `p`.
#[pyfunction]
fn normal_equilibrium(
    py: Python<'_>,
    law: &str,
    coeffs: PyReadonlyArray1<'_, f64>,
    psi: f64,
    omega: f64,
    p: f64,
) -> PyResult<f64> {
    let cs = slice(&coeffs, "coeffs")?;
    let model = build_model(law, cs, psi, omega).map_err(|e| to_pyerr(py, &e))?;
    if !p.is_finite() {
        return Err(to_pyerr(py, &bad("p", "must be finite")));
    }
    model.equilibrium(p).map_err(|e| to_pyerr(py, &e))
}

/// Kelvin-Voigt analytic quantities `(h, K, phi, E_d)` for amplitude `pa` (eqs. 13-15).
#[pyfunction]
fn kv_analytic(
    py: Python<'_>,
    k: f64,
    psi: f64,
    omega: f64,
    pa: f64,
) -> PyResult<(f64, f64, f64, f64)> {
    let kv = KelvinVoigt::new(k, psi, omega).map_err(|e| to_pyerr(py, &e))?;
    if !pa.is_finite() {
        return Err(to_pyerr(py, &bad("pa", "must be finite")));
    }
    Ok((
        kv.damping(),
        kv.amplitude(pa),
        kv.phase(),
        kv.loop_energy(pa),
    ))
}

/// Two arrays handed to Python.
type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// Kelvin-Voigt steady state `(δ, δ')` at times `t` under `pa sin ω t`.
#[pyfunction]
fn kv_steady_state<'py>(
    py: Python<'py>,
    k: f64,
    psi: f64,
    omega: f64,
    pa: f64,
    t: PyReadonlyArray1<'py, f64>,
) -> PyResult<ArrayPair<'py>> {
    let kv = KelvinVoigt::new(k, psi, omega).map_err(|e| to_pyerr(py, &e))?;
    let ts = slice(&t, "t")?;
    let (d, v) = detach_guarded(py, || {
        let mut d = vec![0.0; ts.len()];
        let mut v = vec![0.0; ts.len()];
        kv.steady_state(pa, ts, &mut d, &mut v)?;
        Ok((d, v))
    })?;
    Ok((d.into_pyarray(py), v.into_pyarray(py)))
}

/// Least-squares polynomial (ascending coefficients) through `(x, y)`.
#[pyfunction]
#[pyo3(signature = (x, y, degree, weights=None))]
fn poly_fit<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    degree: usize,
    weights: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let xs = slice(&x, "x")?;
    let ys = slice(&y, "y")?;
    let ws = match &weights {
        Some(w) => Some(slice(w, "weights")?),
        None => None,
    };
    let c = detach_guarded(py, || poly::fit(xs, ys, degree, ws))?;
    Ok(c.into_pyarray(py))
}

/// Real roots of a polynomial (ascending coefficients) in `[lo, hi]`.
#[pyfunction]
fn poly_roots_in<'py>(
    py: Python<'py>,
    c: PyReadonlyArray1<'py, f64>,
    lo: f64,
    hi: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let cs = slice(&c, "c")?;
    contactlab_core::error::check_finite("c", cs).map_err(|e| to_pyerr(py, &e))?;
    Ok(poly::roots_in(cs, lo, hi, 0).into_pyarray(py))
}

/// `(minimum value, where)` of a polynomial over `[lo, hi]`.
#[pyfunction]
fn poly_min_on(
    py: Python<'_>,
    c: PyReadonlyArray1<'_, f64>,
    lo: f64,
    hi: f64,
) -> PyResult<(f64, f64)> {
    let cs = slice(&c, "c")?;
    contactlab_core::error::check_finite("c", cs).map_err(|e| to_pyerr(py, &e))?;
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(to_pyerr(py, &bad("lo, hi", "must be finite with lo <= hi")));
    }
    Ok(poly::min_on(cs, lo, hi))
}

/// Fold `x` into `n_cycles * n_bins` values (row-major) on a common phase grid.
#[pyfunction]
fn fold_cycles<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    start: f64,
    period: f64,
    n_cycles: usize,
    n_bins: usize,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let xs = slice(&x, "x")?;
    let out = detach_guarded(py, || {
        let len = n_cycles
            .checked_mul(n_bins)
            .ok_or_else(|| bad("n_cycles", "n_cycles * n_bins overflows"))?;
        let mut out = vec![0.0; len];
        cycles::fold_cycles(xs, start, period, n_cycles, n_bins, &mut out)?;
        Ok(out)
    })?;
    Ok(out.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<NormalRun>()?;
    m.add_function(wrap_pyfunction!(normal_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(normal_simulate_grid, m)?)?;
    m.add_function(wrap_pyfunction!(normal_equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(kv_analytic, m)?)?;
    m.add_function(wrap_pyfunction!(kv_steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(poly_fit, m)?)?;
    m.add_function(wrap_pyfunction!(poly_roots_in, m)?)?;
    m.add_function(wrap_pyfunction!(poly_min_on, m)?)?;
    m.add_function(wrap_pyfunction!(fold_cycles, m)?)?;
    Ok(())
}
