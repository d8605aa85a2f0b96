//! Binding of `contactlab_core::fold`: the phase-bin fold, its spread, and period means.

use contactlab_core::fold::{fold_phase, fold_spread, period_means, period_means_pair, FoldSums};
use contactlab_core::raw_scan::{
    order_stats_trapezoids, period_means_pair_resumed, RawScan as CoreRawScan,
};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::error::{slice, to_pyerr};
use crate::{detach_guarded, Arr};

/// Phase-bin fold of a periodic recording, accumulated chunk by chunk (see
/// `contactlab_core::fold::fold_phase`).
#[pyclass(module = "contactlab._core")]
struct PhaseFold {
    sums: FoldSums,
}

#[pymethods]
impl PhaseFold {
    #[new]
    fn new(py: Python<'_>, n_bins: usize, n_cycles: usize) -> PyResult<Self> {
        let sums = FoldSums::new(n_bins, n_cycles).map_err(|e| to_pyerr(py, &e))?;
        Ok(Self { sums })
    }

    /// Fold the chunk `(t, x, F)` starting at global sample `offset`, phases from the knots.
    fn push(
        &mut self,
        py: Python<'_>,
        t: PyReadonlyArray1<'_, f64>,
        x: PyReadonlyArray1<'_, f64>,
        f: PyReadonlyArray1<'_, f64>,
        offset: u64,
        knot_t: PyReadonlyArray1<'_, f64>,
        knot_phase: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
        let (kt, kp) = (slice(&knot_t, "knot_t")?, slice(&knot_phase, "knot_phase")?);
        // fold_phase checks everything before it adds a sample: on error nothing changed
        let sums = &mut self.sums;
        detach_guarded(py, || fold_phase(ts, xs, fs, offset, kt, kp, sums))
    }

    /// Cycle-to-cycle spread per bin (`x_std`, `F_std`) and per-cycle half ranges of the
    /// bin means (`amplitude`, `force_range`); see `contactlab_core::fold::fold_spread`.
    fn spread(&self, py: Python<'_>) -> PyResult<FoldSpread> {
        let sums = &self.sums;
        let sp = detach_guarded(py, || fold_spread(sums))?;
        Ok(FoldSpread {
            x_std: sp.x_std.into_pyarray(py).unbind(),
            f_std: sp.f_std.into_pyarray(py).unbind(),
            amplitude: sp.amplitude.into_pyarray(py).unbind(),
            force_range: sp.force_range.into_pyarray(py).unbind(),
        })
    }

    /// The sums so far (a `FoldTable`: per bin, and with `cells` per cycle × bin as 2-D
    /// arrays, else those are `None`).
    #[pyo3(signature = (cells=true))]
    fn sums(&self, py: Python<'_>, cells: bool) -> PyResult<FoldTable> {
        let s = &self.sums;
        let arr = |v: &Vec<f64>| v.clone().into_pyarray(py).unbind();
        let cell = |v: &Vec<f64>| -> PyResult<Option<Py<PyArray2<f64>>>> {
            if !cells {
                return Ok(None);
            }
            let a = v.clone().into_pyarray(py);
            Ok(Some(a.reshape([s.n_cycles, s.n_bins])?.unbind()))
        };
        Ok(FoldTable {
            count: arr(&s.count),
            sum_x: arr(&s.sum_x),
            sum_f: arr(&s.sum_f),
            sum_phase: arr(&s.sum_phase),
            sum_phase2: arr(&s.sum_phase2),
            sum_xx: arr(&s.sum_xx),
            sum_t: arr(&s.sum_t),
            first: s.first.clone().into_pyarray(py).unbind(),
            cycle_count: cell(&s.cycle_count)?,
            cycle_x: cell(&s.cycle_x)?,
            cycle_f: cell(&s.cycle_f)?,
            cycle_phase: cell(&s.cycle_phase)?,
        })
    }
}

/// `PhaseFold.spread`: `x_std`, `F_std` per bin, `amplitude`, `force_range` per cycle.
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct FoldSpread {
    x_std: Py<PyArray1<f64>>,
    #[pyo3(name = "F_std")]
    f_std: Py<PyArray1<f64>>,
    amplitude: Py<PyArray1<f64>>,
    force_range: Py<PyArray1<f64>>,
}

/// `PhaseFold.sums`: per bin `count, sum_x, sum_F, sum_phase, sum_phase2, sum_xx, sum_t`,
/// `first` (each cycle's first sample, -1 for none), and per cycle × bin `cycle_count,
/// cycle_x, cycle_F, cycle_phase` (`None` unless asked for).
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct FoldTable {
    count: Py<PyArray1<f64>>,
    sum_x: Py<PyArray1<f64>>,
    #[pyo3(name = "sum_F")]
    sum_f: Py<PyArray1<f64>>,
    sum_phase: Py<PyArray1<f64>>,
    sum_phase2: Py<PyArray1<f64>>,
    sum_xx: Py<PyArray1<f64>>,
    sum_t: Py<PyArray1<f64>>,
    first: Py<PyArray1<i64>>,
    cycle_count: Option<Py<PyArray2<f64>>>,
    cycle_x: Option<Py<PyArray2<f64>>>,
    #[pyo3(name = "cycle_F")]
    cycle_f: Option<Py<PyArray2<f64>>>,
    cycle_phase: Option<Py<PyArray2<f64>>>,
}

/// Time averages of `v` between consecutive `edges` (see
/// `contactlab_core::fold::period_means`).
#[pyfunction]
#[pyo3(name = "period_means")]
fn period_means_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    v: PyReadonlyArray1<'py, f64>,
    edges: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (ts, vs, es) = (slice(&t, "t")?, slice(&v, "v")?, slice(&edges, "edges")?);
    let m = detach_guarded(py, || period_means(ts, vs, es))?;
    Ok(m.into_pyarray(py))
}

/// Period means of two channels on one time axis in one pass (see
/// `contactlab_core::fold::period_means_pair`); `scan`: `order_stats_trapezoids` of these
/// very samples, whose checkpoints the walk resumes from (the same numbers:
/// `contactlab_core::raw_scan::period_means_pair_resumed`).
#[pyfunction]
#[pyo3(name = "period_means_pair", signature = (t, f, x, edges, scan=None))]
fn period_means_pair_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray1<'py, f64>,
    edges: PyReadonlyArray1<'py, f64>,
    scan: Option<PyRef<'py, RawScan>>,
) -> PyResult<(Arr<'py>, Arr<'py>)> {
    let (ts, fs, xs) = (slice(&t, "t")?, slice(&f, "F")?, slice(&x, "x")?);
    let es = slice(&edges, "edges")?;
    let sc = scan.as_ref().map(|s| &s.inner);
    let (a, b) = detach_guarded(py, || match sc {
        Some(s) => period_means_pair_resumed(ts, fs, xs, es, s),
        None => period_means_pair(ts, fs, xs, es),
    })?;
    Ok((a.into_pyarray(py), b.into_pyarray(py)))
}

/// What `order_stats_trapezoids` found of a window's raw samples: the order statistics,
/// and the period means' checkpoints that `period_means_pair(..., scan=)` resumes from.
#[pyclass(module = "contactlab._core", frozen)]
struct RawScan {
    inner: CoreRawScan,
}

#[pymethods]
impl RawScan {
    /// The order statistics of x at the ranks asked for (in their order).
    #[getter]
    fn order_stats<'py>(&self, py: Python<'py>) -> Arr<'py> {
        self.inner.order_stats.clone().into_pyarray(py)
    }
}

/// `order_stats(x, ranks)` and, in the same pass, the checkpoints of the trapezoid
/// integrals of F and x over t that `period_means_pair(t, F, x, edges, scan=)` resumes
/// from (`contactlab_core::raw_scan::order_stats_trapezoids`); x finite (the caller's check).
#[pyfunction]
#[pyo3(name = "order_stats_trapezoids")]
fn order_stats_trapezoids_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    t: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    ranks: Vec<usize>,
) -> PyResult<RawScan> {
    let (xs, ts, fs) = (slice(&x, "x")?, slice(&t, "t")?, slice(&f, "F")?);
    let inner = detach_guarded(py, || order_stats_trapezoids(xs, ts, fs, &ranks))?;
    Ok(RawScan { inner })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PhaseFold>()?;
    m.add_class::<RawScan>()?;
    m.add_function(wrap_pyfunction!(order_stats_trapezoids_py, m)?)?;
    m.add_class::<FoldSpread>()?;
    m.add_class::<FoldTable>()?;
    m.add_function(wrap_pyfunction!(period_means_py, m)?)?;
    m.add_function(wrap_pyfunction!(period_means_pair_py, m)?)?;
    Ok(())
}
