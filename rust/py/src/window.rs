//! Binding of `contactlab_core::window`: the per-sample work of one analysis window (fold,
//! cycle areas, detrending).

use contactlab_core::window::{
    detrend_pair, detrend_pair_into, detrend_pair_scan_into, fold_window, fold_window_scanned,
    WindowFold as CoreWindowFold, WindowScan as CoreWindowScan,
};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::{input, slice};
use crate::{detach_guarded, Arr};

/// One analysis window folded (`contactlab_core::window`): fold sums, cycle bounds, loop
/// areas and their sensitivities, period means.
#[pyclass(module = "contactlab._core")]
struct WindowFold {
    inner: CoreWindowFold,
}

fn f64_dict<'py>(py: Python<'py>, items: &[(&str, &Vec<f64>)]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for &(k, v) in items {
        d.set_item(k, v.clone().into_pyarray(py))?;
    }
    Ok(d)
}

#[pymethods]
impl WindowFold {
    /// Per bin sums (`count, sum_x, sum_F, sum_phase, sum_phase2, sum_xx, sum_t`) and
    /// `first` (each cycle's first sample, -1 for none).
    fn sums<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = &self.inner;
        let d = f64_dict(
            py,
            &[
                ("count", &w.count),
                ("sum_x", &w.sum_x),
                ("sum_F", &w.sum_f),
                ("sum_phase", &w.sum_phase),
                ("sum_phase2", &w.sum_phase2),
                ("sum_xx", &w.sum_xx),
                ("sum_t", &w.sum_t),
            ],
        )?;
        d.set_item("first", w.first.clone().into_pyarray(py))?;
        Ok(d)
    }

    /// As `PhaseFold.spread`: `x_std`, `F_std` per bin, `amplitude`, `force_range` per cycle.
    fn spread<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = &self.inner;
        f64_dict(
            py,
            &[
                ("x_std", &w.x_std),
                ("F_std", &w.f_std),
                ("amplitude", &w.amplitude),
                ("force_range", &w.force_range),
            ],
        )
    }

    /// Per cycle: `bounds` (n + 1 sample indices), `energy` (loop area), `sens_F`, `sens_x`
    /// (the area's noise sensitivities), `mean_F`, `mean_x` (period means between the edges).
    fn cycles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = &self.inner;
        let d = f64_dict(
            py,
            &[
                ("energy", &w.energy),
                ("sens_F", &w.sens_f),
                ("sens_x", &w.sens_x),
                ("mean_F", &w.mean_f),
                ("mean_x", &w.mean_x),
            ],
        )?;
        let b: Vec<i64> = w
            .bounds
            .iter()
            .map(|&v| i64::try_from(v).unwrap_or(i64::MAX))
            .collect();
        d.set_item("bounds", b.into_pyarray(py))?;
        Ok(d)
    }
}

/// Fold one window (see `contactlab_core::window::fold_window`).
#[pyfunction]
#[pyo3(name = "fold_window", signature = (t, x, f, knot_t, knot_phase, n_bins, n_cycles, edges, scan=None))]
fn fold_window_py(
    py: Python<'_>,
    t: PyReadonlyArray1<'_, f64>,
    x: PyReadonlyArray1<'_, f64>,
    f: PyReadonlyArray1<'_, f64>,
    knot_t: PyReadonlyArray1<'_, f64>,
    knot_phase: PyReadonlyArray1<'_, f64>,
    n_bins: usize,
    n_cycles: usize,
    edges: PyReadonlyArray1<'_, f64>,
    scan: Option<PyRef<'_, WindowScan>>,
) -> PyResult<WindowFold> {
    let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
    let (kt, kp) = (slice(&knot_t, "knot_t")?, slice(&knot_phase, "knot_phase")?);
    let es = slice(&edges, "edges")?;
    let sc = scan.map(|s| s.inner.clone());
    let inner = detach_guarded(py, || match &sc {
        Some(s) => fold_window_scanned(ts, xs, fs, (kt, kp), (n_bins, n_cycles), es, s),
        None => fold_window(ts, xs, fs, kt, kp, n_bins, n_cycles, es),
    })?;
    Ok(WindowFold { inner })
}

/// What `detrend_pair_scan_into` found of the detrended samples (see
/// `contactlab_core::window::WindowScan`): `clean`, the order statistics asked for; handed
/// to `fold_window(..., scan=)` it stands for the fold's own check pass.
#[pyclass(module = "contactlab._core", frozen)]
struct WindowScan {
    inner: CoreWindowScan,
}

#[pymethods]
impl WindowScan {
    /// Whether t is finite and increasing and the detrended x and F finite.
    #[getter]
    fn clean(&self) -> bool {
        self.inner.clean
    }

    /// The order statistics of the detrended x at the ranks asked for (in their order).
    #[getter]
    fn order_stats<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.order_stats.clone().into_pyarray(py)
    }
}

/// `detrend_pair_into` and, in the same pass, the order statistics of the detrended x at
/// `ranks` and the fold's checks (`contactlab_core::window::detrend_pair_scan_into`).
#[pyfunction]
#[pyo3(name = "detrend_pair_scan_into")]
fn detrend_pair_scan_into_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    tm: f64,
    f: PyReadonlyArray1<'py, f64>,
    slope_f: f64,
    x: PyReadonlyArray1<'py, f64>,
    slope_x: f64,
    mut out_f: PyReadwriteArray1<'py, f64>,
    mut out_x: PyReadwriteArray1<'py, f64>,
    ranks: Vec<usize>,
) -> PyResult<WindowScan> {
    let (ts, fs, xs) = (slice(&t, "t")?, slice(&f, "F")?, slice(&x, "x")?);
    let of = out_f
        .as_slice_mut()
        .map_err(|_| input(py, "out_F must be a contiguous array"))?;
    let ox = out_x
        .as_slice_mut()
        .map_err(|_| input(py, "out_x must be a contiguous array"))?;
    let inner = detach_guarded(py, || {
        detrend_pair_scan_into(ts, tm, (fs, slope_f), (xs, slope_x), (of, ox), &ranks)
    })?;
    Ok(WindowScan { inner })
}

/// Remove the linear drifts of F and x in one pass (see
/// `contactlab_core::window::detrend_pair`).
#[pyfunction]
#[pyo3(name = "detrend_pair")]
fn detrend_pair_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    tm: f64,
    f: PyReadonlyArray1<'py, f64>,
    slope_f: f64,
    x: PyReadonlyArray1<'py, f64>,
    slope_x: f64,
) -> PyResult<(Arr<'py>, Arr<'py>)> {
    let (ts, fs, xs) = (slice(&t, "t")?, slice(&f, "F")?, slice(&x, "x")?);
    let (a, b) = detach_guarded(py, || detrend_pair(ts, tm, (fs, slope_f), (xs, slope_x)))?;
    Ok((a.into_pyarray(py), b.into_pyarray(py)))
}

/// `detrend_pair` into the caller's arrays (``numpy.empty``: numpy's allocator asks for huge
/// pages, where a fresh `Vec` of a window's length faulted in every 4 KiB page, 5 ms of
/// system time a window of 2^19 samples).
#[pyfunction]
#[pyo3(name = "detrend_pair_into")]
fn detrend_pair_into_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    tm: f64,
    f: PyReadonlyArray1<'py, f64>,
    slope_f: f64,
    x: PyReadonlyArray1<'py, f64>,
    slope_x: f64,
    mut out_f: PyReadwriteArray1<'py, f64>,
    mut out_x: PyReadwriteArray1<'py, f64>,
) -> PyResult<()> {
    let (ts, fs, xs) = (slice(&t, "t")?, slice(&f, "F")?, slice(&x, "x")?);
    let of = out_f
        .as_slice_mut()
        .map_err(|_| input(py, "out_F must be a contiguous array"))?;
    let ox = out_x
        .as_slice_mut()
        .map_err(|_| input(py, "out_x must be a contiguous array"))?;
    detach_guarded(py, || {
        detrend_pair_into(ts, tm, (fs, slope_f), (xs, slope_x), (of, ox))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<WindowFold>()?;
    m.add_class::<WindowScan>()?;
    m.add_function(wrap_pyfunction!(detrend_pair_scan_into_py, m)?)?;
    m.add_function(wrap_pyfunction!(fold_window_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_into_py, m)?)?;
    Ok(())
}
