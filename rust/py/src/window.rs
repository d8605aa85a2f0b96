//! Binding of `contactlab_core::window`: the per-sample work of one analysis window (fold,
//! cycle areas, detrending).

use contactlab_core::window::{
    detrend_pair, detrend_pair_into, detrend_pair_scan_into, detrend_pair_scan_uniform_into,
    fold_window, fold_window_scanned, WindowFold as CoreWindowFold, WindowScan as CoreWindowScan,
};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;

use crate::error::{input, slice};
use crate::{detach_guarded, Arr};

/// One analysis window folded (`contactlab_core::window`): fold sums, cycle bounds, loop
/// areas and their sensitivities, period means (read-only array attributes, each a copy).
#[pyclass(module = "contactlab._core", frozen)]
struct WindowFold {
    inner: CoreWindowFold,
}

#[pymethods]
impl WindowFold {
    /// Per phase bin: the number of samples.
    #[getter]
    fn count<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.count.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of x.
    #[getter]
    fn sum_x<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_x.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of F.
    #[getter(sum_F)]
    fn get_sum_f<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_f.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of the phase.
    #[getter]
    fn sum_phase<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_phase.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of the squared phase.
    #[getter]
    fn sum_phase2<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_phase2.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of x squared.
    #[getter]
    fn sum_xx<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_xx.clone().into_pyarray(py)
    }

    /// Per phase bin: the sum of t.
    #[getter]
    fn sum_t<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sum_t.clone().into_pyarray(py)
    }

    /// As `PhaseFold.spread`: the cycle-to-cycle spread of x per bin.
    #[getter]
    fn x_std<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.x_std.clone().into_pyarray(py)
    }

    /// As `PhaseFold.spread`: the cycle-to-cycle spread of F per bin.
    #[getter(F_std)]
    fn get_f_std<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.f_std.clone().into_pyarray(py)
    }

    /// Per cycle: the displacement amplitude.
    #[getter]
    fn amplitude<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.amplitude.clone().into_pyarray(py)
    }

    /// Per cycle: the force range.
    #[getter]
    fn force_range<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.force_range.clone().into_pyarray(py)
    }

    /// Per cycle: the loop area.
    #[getter]
    fn energy<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.energy.clone().into_pyarray(py)
    }

    /// Per cycle: the loop area's noise sensitivity to F.
    #[getter(sens_F)]
    fn get_sens_f<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sens_f.clone().into_pyarray(py)
    }

    /// Per cycle: the loop area's noise sensitivity to x.
    #[getter]
    fn sens_x<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.sens_x.clone().into_pyarray(py)
    }

    /// Per cycle: the period mean of F between the edges.
    #[getter(mean_F)]
    fn get_mean_f<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.mean_f.clone().into_pyarray(py)
    }

    /// Per cycle: the period mean of x between the edges.
    #[getter]
    fn mean_x<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.mean_x.clone().into_pyarray(py)
    }

    /// Each cycle's first sample (-1 for none).
    #[getter]
    fn first<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.inner.first.clone().into_pyarray(py)
    }

    /// Per cycle: the bounds (n + 1 sample indices).
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let b: Vec<i64> = self
            .inner
            .bounds
            .iter()
            .map(|&v| i64::try_from(v).unwrap_or(i64::MAX))
            .collect();
        b.into_pyarray(py)
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

/// `detrend_pair_scan_into` of a window whose time axis is `t0 + dt * (offset + i)`
/// (`fill_time`'s, bit for bit), made as the pass goes instead of read
/// (`contactlab_core::window::detrend_pair_scan_uniform_into`).
#[pyfunction]
#[pyo3(name = "detrend_pair_scan_uniform_into")]
#[allow(clippy::too_many_arguments)]
fn detrend_pair_scan_uniform_into_py<'py>(
    py: Python<'py>,
    t0: f64,
    dt: f64,
    offset: u64,
    tm: f64,
    f: PyReadonlyArray1<'py, f64>,
    slope_f: f64,
    x: PyReadonlyArray1<'py, f64>,
    slope_x: f64,
    mut out_f: PyReadwriteArray1<'py, f64>,
    mut out_x: PyReadwriteArray1<'py, f64>,
    ranks: Vec<usize>,
) -> PyResult<WindowScan> {
    let (fs, xs) = (slice(&f, "F")?, slice(&x, "x")?);
    let of = out_f
        .as_slice_mut()
        .map_err(|_| input(py, "out_F must be a contiguous array"))?;
    let ox = out_x
        .as_slice_mut()
        .map_err(|_| input(py, "out_x must be a contiguous array"))?;
    let inner = detach_guarded(py, || {
        detrend_pair_scan_uniform_into(
            (t0, dt, offset),
            tm,
            (fs, slope_f),
            (xs, slope_x),
            (of, ox),
            &ranks,
        )
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
    m.add_function(wrap_pyfunction!(detrend_pair_scan_uniform_into_py, m)?)?;
    m.add_function(wrap_pyfunction!(fold_window_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_into_py, m)?)?;
    Ok(())
}
