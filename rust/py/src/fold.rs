//! Binding of `contactlab_core::fold`: the phase-bin fold, its spread, and period means.

use contactlab_core::fold::{fold_phase, fold_spread, period_means, period_means_pair, FoldSums};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    fn spread<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let sums = &self.sums;
        let sp = detach_guarded(py, || fold_spread(sums))?;
        let d = PyDict::new(py);
        d.set_item("x_std", sp.x_std.into_pyarray(py))?;
        d.set_item("F_std", sp.f_std.into_pyarray(py))?;
        d.set_item("amplitude", sp.amplitude.into_pyarray(py))?;
        d.set_item("force_range", sp.force_range.into_pyarray(py))?;
        Ok(d)
    }

    /// The sums so far: dict of arrays (per bin, and with `cells` per cycle × bin as 2-D
    /// arrays).
    #[pyo3(signature = (cells=true))]
    fn sums<'py>(&self, py: Python<'py>, cells: bool) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.sums;
        let d = PyDict::new(py);
        for (k, v) in [
            ("count", &s.count),
            ("sum_x", &s.sum_x),
            ("sum_F", &s.sum_f),
            ("sum_phase", &s.sum_phase),
            ("sum_phase2", &s.sum_phase2),
            ("sum_xx", &s.sum_xx),
            ("sum_t", &s.sum_t),
        ] {
            d.set_item(k, v.clone().into_pyarray(py))?;
        }
        let per_cell: &[(&str, &Vec<f64>)] = if cells {
            &[
                ("cycle_count", &s.cycle_count),
                ("cycle_x", &s.cycle_x),
                ("cycle_F", &s.cycle_f),
                ("cycle_phase", &s.cycle_phase),
            ]
        } else {
            &[]
        };
        for &(k, v) in per_cell {
            let a = v.clone().into_pyarray(py);
            d.set_item(k, a.reshape([s.n_cycles, s.n_bins])?)?;
        }
        d.set_item("first", s.first.clone().into_pyarray(py))?;
        Ok(d)
    }
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
/// `contactlab_core::fold::period_means_pair`).
#[pyfunction]
#[pyo3(name = "period_means_pair")]
fn period_means_pair_py<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray1<'py, f64>,
    edges: PyReadonlyArray1<'py, f64>,
) -> PyResult<(Arr<'py>, Arr<'py>)> {
    let (ts, fs, xs) = (slice(&t, "t")?, slice(&f, "F")?, slice(&x, "x")?);
    let es = slice(&edges, "edges")?;
    let (a, b) = detach_guarded(py, || period_means_pair(ts, fs, xs, es))?;
    Ok((a.into_pyarray(py), b.into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PhaseFold>()?;
    m.add_function(wrap_pyfunction!(period_means_py, m)?)?;
    m.add_function(wrap_pyfunction!(period_means_pair_py, m)?)?;
    Ok(())
}
