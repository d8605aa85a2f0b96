//! Bindings of `contactlab_core::signal` (the streaming reversal detector), the branch memory
//! of the Masing rules, and the multi-channel force kernel (Rust threads).

use contactlab_core::cycles::{cycle_block, CycleState};
use contactlab_core::fold::{fold_phase, fold_spread, period_means, period_means_pair, FoldSums};
use contactlab_core::isotonic::monotone_path;
use contactlab_core::loop_area::{loop_area_sensitivity, loop_areas};
use contactlab_core::masing::split::{force_channels, Channel, PIECE};
use contactlab_core::masing::{branch_memory, MasingState};
use contactlab_core::parallel::run_jobs;
use contactlab_core::reversal::{Excursion, Schmitt};
use contactlab_core::select::order_stats;
use contactlab_core::window::{
    detrend_pair, detrend_pair_into, fold_window, WindowFold as CoreWindowFold,
};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{input, to_pyerr};
use crate::{detach_guarded, slice, MasingCore};

/// Streaming hysteresis-threshold reversal detector (state carried across `push` calls).
#[pyclass(module = "contactlab._core")]
struct ReversalDetector {
    inner: Schmitt,
}

fn table<'py>(py: Python<'py>, ex: &[Excursion]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let idx = |f: &dyn Fn(&Excursion) -> u64| -> Vec<i64> {
        ex.iter()
            .map(|e| i64::try_from(f(e)).unwrap_or(i64::MAX))
            .collect()
    };
    d.set_item(
        "sign",
        ex.iter()
            .map(|e| i64::from(e.sign))
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("start", idx(&|e| e.start).into_pyarray(py))?;
    d.set_item("extreme", idx(&|e| e.extreme).into_pyarray(py))?;
    d.set_item("last_beyond", idx(&|e| e.last_beyond).into_pyarray(py))?;
    d.set_item(
        "extreme_value",
        ex.iter()
            .map(|e| e.extreme_value)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "returned",
        ex.iter()
            .map(|e| e.returned)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    Ok(d)
}

#[pymethods]
impl ReversalDetector {
    #[new]
    fn new(py: Python<'_>, centre: f64, threshold: f64) -> PyResult<Self> {
        let inner = Schmitt::new(centre, threshold).map_err(|e| to_pyerr(py, &e))?;
        Ok(Self { inner })
    }

    /// Excursions completed in this chunk: dict of arrays `sign, start, extreme,
    /// last_beyond, extreme_value, returned`. `value` (default `x`) is where extremes are
    /// located.
    #[pyo3(signature = (x, value=None))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        value: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let xs = slice(&x, "x")?;
        let vs = value.as_ref().map(|v| slice(v, "value")).transpose()?;
        let mut st = self.inner.clone();
        let (done, st) = detach_guarded(py, || {
            let mut done = Vec::new();
            st.push(xs, vs, &mut done)?;
            Ok((done, st))
        })?;
        self.inner = st;
        table(py, &done)
    }

    /// The excursion in progress (0 or 1 rows, same columns as `push`).
    fn open<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let open: Vec<Excursion> = self.inner.open.iter().copied().collect();
        table(py, &open)
    }

    #[getter]
    fn count(&self) -> u64 {
        self.inner.count
    }
}

type FloatPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);
/// Outputs of `force_many` and one statistics dict per worker thread.
type ManyForces<'py> = (Vec<Bound<'py, PyArray1<f64>>>, Vec<Bound<'py, PyDict>>);
type IndexPair<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>);

/// Per-sample branch bookkeeping of the Masing memory rules from the origin:
/// `(anchor, target)` sample-index arrays (see `contactlab_core::masing::branch_memory`).
#[pyfunction]
#[pyo3(name = "branch_memory")]
fn branch_memory_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
) -> PyResult<IndexPair<'py>> {
    let xs = slice(&x, "x")?;
    let (a, t) = detach_guarded(py, || {
        let mut a = vec![0_i64; xs.len()];
        let mut t = vec![0_i64; xs.len()];
        branch_memory(xs, &mut a, &mut t, &mut MasingState::default())?;
        Ok((a, t))
    })?;
    Ok((a.into_pyarray(py), t.into_pyarray(py)))
}

/// Forces of several channels, each from the origin with its own model, on up to `threads`
/// Rust threads inside this one call (GIL released; `contactlab_core::masing::split::
/// force_channels`: channels of at least two pieces of `piece` samples are split by a
/// comparisons-only pre-pass, then pieces and short channels go longest first from one shared
/// queue; bit for bit the serial kernel). Into `outs` when given (one
/// contiguous float64 array per channel, reused between calls: no fresh pages to fault in),
/// else into new arrays. Returns the outputs and one dict per worker thread (`jobs`,
/// `samples`, `start`, `end`, `cpu`, `wait`, `prepass`, `prepass_cpu`; seconds; the CPU
/// times only with `cpu_times` and where the system tells, else None).
#[pyfunction]
#[pyo3(signature = (models, xs, threads, outs=None, cpu_times=false, piece=PIECE))]
fn force_many<'py>(
    py: Python<'py>,
    models: Vec<PyRef<'py, MasingCore>>,
    xs: Vec<PyReadonlyArray1<'py, f64>>,
    threads: usize,
    outs: Option<Vec<Bound<'py, PyArray1<f64>>>>,
    cpu_times: bool,
    piece: usize,
) -> PyResult<ManyForces<'py>> {
    if models.len() != xs.len() {
        return Err(input(
            py,
            &format!("{} models but {} signals", models.len(), xs.len()),
        ));
    }
    if threads == 0 {
        return Err(input(py, "threads must be >= 1"));
    }
    let inputs: Vec<&[f64]> = xs.iter().map(|x| slice(x, "x")).collect::<PyResult<_>>()?;
    let outs: Vec<Bound<'py, PyArray1<f64>>> = match outs {
        Some(o) if o.len() != inputs.len() => {
            return Err(input(
                py,
                &format!("{} output arrays but {} signals", o.len(), inputs.len()),
            ));
        }
        Some(o) => o,
        None => inputs
            .iter()
            .map(|x| PyArray1::<f64>::zeros(py, x.len(), false))
            .collect(),
    };
    let mut rws: Vec<PyReadwriteArray1<'py, f64>> = Vec::with_capacity(outs.len());
    for (i, o) in outs.iter().enumerate() {
        rws.push(o.try_readwrite().map_err(|_| {
            input(
                py,
                &format!(
                    "out[{i}] must be a writeable array shared with no signal or other output"
                ),
            )
        })?);
    }
    let mut jobs: Vec<(&[f64], &mut [f64])> = Vec::with_capacity(rws.len());
    for (i, (rw, x)) in rws.iter_mut().zip(&inputs).enumerate() {
        let o = rw
            .as_slice_mut()
            .map_err(|_| input(py, &format!("out[{i}] must be contiguous")))?;
        if o.len() != x.len() {
            return Err(input(
                py,
                &format!(
                    "out[{i}] has {} samples but signal {i} has {}",
                    o.len(),
                    x.len()
                ),
            ));
        }
        jobs.push((x, o));
    }
    let cores: Vec<&dyn Channel> = models.iter().map(|m| &**m as &dyn Channel).collect();
    let (xs, os): (Vec<&[f64]>, Vec<&mut [f64]>) = jobs.into_iter().unzip();
    let mut states = vec![MasingState::default(); xs.len()];
    let stats = detach_guarded(py, || {
        force_channels(&cores, &xs, os, &mut states, threads, piece, cpu_times)
    })?;
    drop(rws);
    let mut dicts = Vec::with_capacity(stats.len());
    for s in stats {
        let d = PyDict::new(py);
        d.set_item("jobs", s.jobs)?;
        d.set_item("samples", s.samples)?;
        d.set_item("start", s.start)?;
        d.set_item("end", s.end)?;
        d.set_item("cpu", s.cpu)?;
        d.set_item("wait", s.wait)?;
        d.set_item("prepass", s.prepass)?;
        d.set_item("prepass_cpu", s.prepass_cpu)?;
        dicts.push(d);
    }
    Ok((outs, dicts))
}

/// The machine's own scaling, for the benchmarks: `jobs` independent jobs, each the force of
/// the same short signal `x` from the origin `repeats` times into the job's own buffer
/// (`x` and the buffer stay in cache: no memory traffic, no shared data written, no split),
/// on up to `threads` threads (`contactlab_core::parallel::run_jobs`). What `force_many`'s
/// speed-up is compared with in the same run. Returns one statistics dict per thread.
#[pyfunction]
#[pyo3(signature = (model, x, jobs, repeats, threads))]
fn force_repeat<'py>(
    py: Python<'py>,
    model: PyRef<'py, MasingCore>,
    x: PyReadonlyArray1<'py, f64>,
    jobs: usize,
    repeats: usize,
    threads: usize,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    if threads == 0 {
        return Err(input(py, "threads must be >= 1"));
    }
    let xs = slice(&x, "x")?;
    let core: &dyn Channel = &*model;
    let stats = detach_guarded(py, || {
        run_jobs(
            vec![xs.len(); jobs],
            threads,
            true,
            |n| *n,
            |_, n| {
                let mut out = vec![0.0; n];
                for _ in 0..repeats {
                    core.whole(xs, &mut out, &mut MasingState::default())?;
                }
                std::hint::black_box(&out);
                Ok(())
            },
        )
    })?;
    let mut dicts = Vec::with_capacity(stats.len());
    for s in stats {
        let d = PyDict::new(py);
        d.set_item("jobs", s.jobs)?;
        d.set_item("start", s.start)?;
        d.set_item("end", s.end)?;
        d.set_item("cpu", s.cpu)?;
        d.set_item("wait", s.wait)?;
        dicts.push(d);
    }
    Ok(dicts)
}

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

/// `∮ F dx` of each cycle between consecutive `bounds` (NaN below 3 samples).
#[pyfunction]
#[pyo3(name = "loop_areas")]
fn loop_areas_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    bounds: Vec<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    let a = detach_guarded(py, || loop_areas(xs, fs, &bounds))?;
    Ok(a.into_pyarray(py))
}

/// Per cycle between consecutive `bounds`: `(Σ coef_F², Σ coef_x²)`, the loop area's noise
/// sensitivities (see `contactlab_core::loop_area::loop_area_sensitivity`).
#[pyfunction]
#[pyo3(name = "loop_area_sensitivity")]
fn loop_area_sensitivity_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    bounds: Vec<usize>,
) -> PyResult<FloatPair<'py>> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    let (a, b) = detach_guarded(py, || loop_area_sensitivity(xs, fs, &bounds))?;
    Ok((a.into_pyarray(py), b.into_pyarray(py)))
}

/// Streaming cycle finder: upward crossings of a drive channel and per-cycle loop energy,
/// amplitude and offset (see `contactlab_core::cycles::cycle_block`).
#[pyclass(module = "contactlab._core")]
struct CycleTracker {
    state: CycleState,
}

#[pymethods]
impl CycleTracker {
    #[new]
    fn new() -> Self {
        Self {
            state: CycleState::default(),
        }
    }

    /// One block: dict of arrays `crossings` (global indices), `start`, `end`, `energy`,
    /// `amplitude`, `offset` (one per complete cycle).
    #[allow(clippy::too_many_arguments)]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        t: PyReadonlyArray1<'py, f64>,
        x: PyReadonlyArray1<'py, f64>,
        f: PyReadonlyArray1<'py, f64>,
        drive: PyReadonlyArray1<'py, f64>,
        offset: u64,
        low: f64,
        high: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
        let ds = slice(&drive, "drive")?;
        let state = &mut self.state;
        let c = detach_guarded(py, || cycle_block(ts, xs, fs, ds, offset, low, high, state))?;
        let d = PyDict::new(py);
        let idx: Vec<i64> = c
            .crossings
            .iter()
            .map(|&i| i64::try_from(i).unwrap_or(i64::MAX))
            .collect();
        d.set_item("crossings", idx.into_pyarray(py))?;
        for (k, v) in [
            ("start", c.start),
            ("end", c.end),
            ("energy", c.energy),
            ("amplitude", c.amplitude),
            ("offset", c.offset),
        ] {
            d.set_item(k, v.into_pyarray(py))?;
        }
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

/// The values of rank `ranks` (0-based, ascending values) of `x`, those of a sort
/// (`contactlab_core::select::order_stats`: near the ends of a long sample from its tails
/// only); `x` finite (the caller's check).
#[pyfunction]
#[pyo3(name = "order_stats")]
fn order_stats_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    ranks: Vec<usize>,
) -> PyResult<Arr<'py>> {
    let xs = slice(&x, "x")?;
    let v = detach_guarded(py, || order_stats(xs, &ranks))?;
    Ok(v.into_pyarray(py))
}

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
#[pyo3(name = "fold_window")]
#[allow(clippy::too_many_arguments)]
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
) -> PyResult<WindowFold> {
    let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
    let (kt, kp) = (slice(&knot_t, "knot_t")?, slice(&knot_phase, "knot_phase")?);
    let es = slice(&edges, "edges")?;
    let inner = detach_guarded(py, || fold_window(ts, xs, fs, kt, kp, n_bins, n_cycles, es))?;
    Ok(WindowFold { inner })
}

type Arr<'py> = Bound<'py, PyArray1<f64>>;

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
#[allow(clippy::too_many_arguments)]
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

/// `x` projected on monotone stretches between `edges` (isotonic regressions; see
/// `contactlab_core::isotonic::monotone_path`).
#[pyfunction]
#[pyo3(name = "monotone_path")]
fn monotone_path_py<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    edges: PyReadonlyArray1<'py, i64>,
) -> PyResult<Arr<'py>> {
    let xs = slice(&x, "x")?;
    let mut ed = Vec::new();
    for &e in &edges.as_array() {
        ed.push(usize::try_from(e).map_err(|_| input(py, "edges must be >= 0"))?);
    }
    let out = detach_guarded(py, || monotone_path(xs, &ed))?;
    Ok(out.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(monotone_path_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_py, m)?)?;
    m.add_function(wrap_pyfunction!(detrend_pair_into_py, m)?)?;
    m.add_class::<PhaseFold>()?;
    m.add_class::<WindowFold>()?;
    m.add_function(wrap_pyfunction!(fold_window_py, m)?)?;
    m.add_function(wrap_pyfunction!(loop_areas_py, m)?)?;
    m.add_function(wrap_pyfunction!(loop_area_sensitivity_py, m)?)?;
    m.add_function(wrap_pyfunction!(period_means_py, m)?)?;
    m.add_function(wrap_pyfunction!(period_means_pair_py, m)?)?;
    m.add_function(wrap_pyfunction!(order_stats_py, m)?)?;
    m.add_class::<CycleTracker>()?;
    m.add_class::<ReversalDetector>()?;
    m.add_function(wrap_pyfunction!(branch_memory_py, m)?)?;
    m.add_function(wrap_pyfunction!(force_many, m)?)?;
    m.add_function(wrap_pyfunction!(force_repeat, m)?)?;
    Ok(())
}
