//! Binding of `contactlab_core::masing`: the Masing operator with its carried state
//! (`MasingCore`), the branch memory, and the multi-channel force kernel (Rust threads).

use contactlab_core::curve::{Backbone, Exponential, Tabulated};
use contactlab_core::masing::channels::{force_channels, Channel};
use contactlab_core::masing::split::PIECE;
use contactlab_core::masing::{branch_memory, MasingState};
use contactlab_core::parallel::{run_jobs, ThreadStats};
use contactlab_core::{masing, BranchRule, CoreError};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;

use crate::error::{input, slice, to_pyerr};
use crate::{detach_guarded, Arr, IndexPair};

/// One worker thread's statistics (`force_many`, `force_repeat`; see
/// `contactlab_core::parallel::ThreadStats`): `jobs`, `samples`, `start` and `end` (seconds
/// since the call began), `cpu` and `wait` (CPU seconds, seconds runnable but waiting; `None`
/// where the system does not tell), `prepass` and `prepass_cpu` (the pre-pass's share).
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct WorkerStats {
    jobs: usize,
    samples: usize,
    start: f64,
    end: f64,
    cpu: Option<f64>,
    wait: Option<f64>,
    prepass: f64,
    prepass_cpu: Option<f64>,
}

impl From<ThreadStats> for WorkerStats {
    fn from(s: ThreadStats) -> Self {
        Self {
            jobs: s.jobs,
            samples: s.samples,
            start: s.start,
            end: s.end,
            cpu: s.cpu,
            wait: s.wait,
            prepass: s.prepass,
            prepass_cpu: s.prepass_cpu,
        }
    }
}

/// Outputs of `force_many` and one `WorkerStats` per worker thread.
type ManyForces<'py> = (Vec<Arr<'py>>, Vec<WorkerStats>);

/// A virgin curve: the exponential curve or a tabulated backbone.
#[derive(Clone)]
pub(crate) enum Curve {
    Exp(Exponential),
    Tab(Tabulated),
}

macro_rules! with_curve {
    ($curve:expr, $c:ident => $body:expr) => {
        match $curve {
            Curve::Exp($c) => $body,
            Curve::Tab($c) => $body,
        }
    };
}

/// Masing operator with non-local memory and a carried state (one instance per recording).
#[pyclass(module = "contactlab._core")]
pub(crate) struct MasingCore {
    curve: Curve,
    scale: f64,
    /// Branches anchored at both ends (`BranchRule::Anchored`) instead of Masing's scaled rule.
    anchored: bool,
    state: MasingState,
}

impl MasingCore {
    pub(crate) fn rule(&self) -> BranchRule {
        if self.anchored {
            BranchRule::Anchored(self.scale)
        } else {
            BranchRule::Scaled(self.scale)
        }
    }
}

#[pymethods]
impl MasingCore {
    /// Exponential virgin curve `h0 (1 - exp(-ac u))`.
    #[staticmethod]
    fn exponential(py: Python<'_>, h0: f64, ac: f64, scale: f64) -> PyResult<Self> {
        let curve = Exponential::new(h0, ac).map_err(|e| to_pyerr(py, &e))?;
        check_scale(py, scale)?;
        Ok(Self {
            curve: Curve::Exp(curve),
            scale,
            anchored: false,
            state: MasingState::default(),
        })
    }

    /// Tabulated monotone backbone through `(x_points, f_points)`.
    #[staticmethod]
    fn tabulated(
        py: Python<'_>,
        x_points: PyReadonlyArray1<'_, f64>,
        f_points: PyReadonlyArray1<'_, f64>,
        scale: f64,
    ) -> PyResult<Self> {
        let u = slice(&x_points, "x_points")?;
        let f = slice(&f_points, "f_points")?;
        let curve = Tabulated::new(u, f).map_err(|e| to_pyerr(py, &e))?;
        check_scale(py, scale)?;
        Ok(Self {
            curve: Curve::Tab(curve),
            scale,
            anchored: false,
            state: MasingState::default(),
        })
    }

    /// A copy with the same curve and scale, state reset to the origin; `anchored` selects
    /// the branch rule (default: keep this one's).
    #[pyo3(signature = (anchored=None))]
    fn fresh(&self, anchored: Option<bool>) -> Self {
        Self {
            curve: self.curve.clone(),
            scale: self.scale,
            anchored: anchored.unwrap_or(self.anchored),
            state: MasingState::default(),
        }
    }

    /// Forces for the chunk `x`, continuing the carried history; into `out` when given
    /// (same length, contiguous float64), else into a new array.
    /// With `threads > 1` a long chunk runs in pieces of `piece` samples on up to that many
    /// threads, no more than CPUs are idle now (`contactlab_core::parallel::threads_that_pay`)
    /// (`contactlab_core::masing::split`), bit for bit the same.
    #[pyo3(signature = (x, out=None, threads=1, piece=masing::split::PIECE))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        out: Option<Bound<'py, PyArray1<f64>>>,
        threads: usize,
        piece: usize,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let xs = slice(&x, "x")?;
        // A new output is allocated by numpy, which asks the OS for transparent huge pages on
        // large arrays: on this kind of machine, first-touch page faults and TLB misses on a
        // fresh 80 MB Vec cost as much as the kernel itself.
        let arr = match out {
            Some(a) => a,
            None => PyArray1::<f64>::zeros(py, xs.len(), false),
        };
        let mut st = self.state.clone();
        let (curve, rule) = (&self.curve, self.rule());
        {
            let mut rw = arr
                .try_readwrite()
                .map_err(|_| input(py, "out must be a writeable array not shared with x"))?;
            let out = rw
                .as_slice_mut()
                .map_err(|_| input(py, "out must be contiguous"))?;
            let me = &*self;
            st = detach_guarded(py, || {
                // split only onto CPUs that are idle now (a split onto a busy CPU loses)
                let threads = contactlab_core::parallel::threads_that_pay(threads);
                if threads > 1 {
                    let mut sts = [st];
                    masing::channels::force_channels(
                        &[me],
                        &[xs],
                        vec![out],
                        &mut sts,
                        threads,
                        piece,
                        false,
                    )?;
                    let [s] = sts;
                    return Ok(s);
                }
                with_curve!(curve, c => masing::masing_force_rule(c, rule, xs, out, &mut st))?;
                Ok(st)
            })?;
        }
        self.state = st;
        Ok(arr)
    }

    /// Closed cycles of `x` (continuing the carried history, which is advanced): a
    /// `MasingCycles`.
    fn cycles<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<MasingCycles> {
        let xs = slice(&x, "x")?;
        if self.anchored {
            return Err(input(
                py,
                "cycle energies are defined for Masing's scaled branches, not anchored ones",
            ));
        }
        let mut st = self.state.clone();
        let (curve, scale) = (&self.curve, self.scale);
        let (cycles, st) = detach_guarded(py, || {
            let c = with_curve!(curve, c => masing::cycle_energies(c, scale, xs, &mut st))?;
            Ok((c, st))
        })?;
        self.state = st;
        let col = |f: &dyn Fn(&masing::Cycle) -> f64| {
            cycles
                .iter()
                .map(f)
                .collect::<Vec<f64>>()
                .into_pyarray(py)
                .unbind()
        };
        let idx = |f: &dyn Fn(&masing::Cycle) -> u64| {
            cycles
                .iter()
                .map(|c| i64::try_from(f(c)).unwrap_or(i64::MAX))
                .collect::<Vec<i64>>()
                .into_pyarray(py)
                .unbind()
        };
        Ok(MasingCycles {
            range: col(&|c| c.range),
            mean: col(&|c| c.mean),
            start: idx(&|c| c.start),
            end: idx(&|c| c.end),
            count: col(&|c| c.count),
            energy: col(&|c| c.energy),
        })
    }

    fn reset(&mut self) {
        self.state = MasingState::default();
    }

    /// The carried state as a flat float array (see `MasingState::to_vec`).
    fn get_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.state.to_vec().into_pyarray(py)
    }

    fn set_state(&mut self, py: Python<'_>, state: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let v = slice(&state, "state")?;
        self.state = MasingState::from_slice(v).map_err(|e| to_pyerr(py, &e))?;
        Ok(())
    }

    /// Virgin curve `f(u)` (no history).
    fn backbone<'py>(
        &self,
        py: Python<'py>,
        u: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.map(py, &u, |c, v| c.eval(v))
    }

    /// Tangent stiffness of the virgin curve `f'(u)`.
    fn slope<'py>(
        &self,
        py: Python<'py>,
        u: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.map(py, &u, |c, v| c.slope(v))
    }

    /// Area between the virgin curve and its chord on `[0, |u|]`.
    fn chord_area<'py>(
        &self,
        py: Python<'py>,
        u: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.map(py, &u, |c, v| c.chord_area(v))
    }

    #[getter]
    fn scale(&self) -> f64 {
        self.scale
    }
}

impl masing::channels::Channel for MasingCore {
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
        emit: &mut dyn FnMut(usize, MasingState) -> bool,
    ) -> Result<masing::split::Walked, CoreError> {
        let rule = self.rule();
        with_curve!(&self.curve, curve => masing::channels::Model { curve, rule }.split(x, state, piece, emit))
    }
    fn piece(
        &self,
        x: &[f64],
        out: &mut [f64],
        state: &mut MasingState,
    ) -> Result<bool, CoreError> {
        let rule = self.rule();
        with_curve!(&self.curve, curve => masing::channels::Model { curve, rule }.piece(x, out, state))
    }
    fn whole(&self, x: &[f64], out: &mut [f64], state: &mut MasingState) -> Result<(), CoreError> {
        let rule = self.rule();
        with_curve!(&self.curve, c => masing::masing_force_rule(c, rule, x, out, state))
    }
}

impl MasingCore {
    fn map<'py>(
        &self,
        py: Python<'py>,
        u: &PyReadonlyArray1<'py, f64>,
        f: impl Fn(&dyn Backbone, f64) -> f64 + Send + Sync,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let us = slice(u, "x")?;
        let curve = &self.curve;
        let out = detach_guarded(py, || {
            contactlab_core::error::check_finite("x", us)?;
            let c: &dyn Backbone = match curve {
                Curve::Exp(c) => c,
                Curve::Tab(c) => c,
            };
            let v = us.iter().map(|&v| f(c, v)).collect::<Vec<f64>>();
            contactlab_core::error::check_output("curve value", &v)?;
            Ok(v)
        })?;
        Ok(out.into_pyarray(py))
    }
}

fn check_scale(py: Python<'_>, scale: f64) -> PyResult<()> {
    contactlab_core::error::check_positive("scale", scale).map_err(|e| to_pyerr(py, &e))
}

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
/// Rust threads inside this one call (GIL released; `contactlab_core::masing::channels::
/// force_channels`: channels of at least two pieces of `piece` samples are split by a
/// comparisons-only pre-pass, then pieces and short channels go longest first from one shared
/// queue; bit for bit the serial kernel). Into `outs` when given (one
/// contiguous float64 array per channel, reused between calls: no fresh pages to fault in),
/// else into new arrays. Returns the outputs and one `WorkerStats` per worker thread (the
/// CPU times only with `cpu_times` and where the system tells, else None).
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
            format!("{} models but {} signals", models.len(), xs.len()),
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
                format!("{} output arrays but {} signals", o.len(), inputs.len()),
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
                format!("out[{i}] must be a writeable array shared with no signal or other output"),
            )
        })?);
    }
    let mut jobs: Vec<(&[f64], &mut [f64])> = Vec::with_capacity(rws.len());
    for (i, (rw, x)) in rws.iter_mut().zip(&inputs).enumerate() {
        let o = rw
            .as_slice_mut()
            .map_err(|_| input(py, format!("out[{i}] must be contiguous")))?;
        if o.len() != x.len() {
            return Err(input(
                py,
                format!(
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
    Ok((outs, stats.into_iter().map(WorkerStats::from).collect()))
}

/// The machine's own scaling, for the benchmarks: `jobs` independent jobs, each the force of
/// the same short signal `x` from the origin `repeats` times into the job's own buffer
/// (`x` and the buffer stay in cache: no memory traffic, no shared data written, no split),
/// on up to `threads` threads (`contactlab_core::parallel::run_jobs`). What `force_many`'s
/// speed-up is compared with in the same run. Returns one `WorkerStats` per thread.
#[pyfunction]
#[pyo3(signature = (model, x, jobs, repeats, threads))]
fn force_repeat<'py>(
    py: Python<'py>,
    model: PyRef<'py, MasingCore>,
    x: PyReadonlyArray1<'py, f64>,
    jobs: usize,
    repeats: usize,
    threads: usize,
) -> PyResult<Vec<WorkerStats>> {
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
    Ok(stats.into_iter().map(WorkerStats::from).collect())
}

/// `MasingCore.cycles`: one row per closed cycle, `range`, `mean`, `start`, `end` (sample
/// indices), `count` (1 or 0.5), `energy` (count included).
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct MasingCycles {
    range: Py<PyArray1<f64>>,
    mean: Py<PyArray1<f64>>,
    start: Py<PyArray1<i64>>,
    end: Py<PyArray1<i64>>,
    count: Py<PyArray1<f64>>,
    energy: Py<PyArray1<f64>>,
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<MasingCore>()?;
    m.add_class::<MasingCycles>()?;
    m.add_class::<WorkerStats>()?;
    m.add_function(wrap_pyfunction!(branch_memory_py, m)?)?;
    m.add_function(wrap_pyfunction!(force_many, m)?)?;
    m.add_function(wrap_pyfunction!(force_repeat, m)?)?;
    Ok(())
}
