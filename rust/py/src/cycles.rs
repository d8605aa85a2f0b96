//! Binding of `contactlab_core::cycles`: the streaming cycle finder (`cycle_block`), with
//! and without a time axis.

use contactlab_core::cycles::{
    crossings_block, crossings_block_checked, cycle_block, cycle_block_sampled, BlockCycles,
    CycleState,
};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::{input, slice};

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

    /// One block: a `CycleBlock` (`crossings`, and per complete cycle `start`, `end`,
    /// `energy`, `amplitude`, `offset`).
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
    ) -> PyResult<CycleBlock> {
        let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
        let ds = slice(&drive, "drive")?;
        let state = &mut self.state;
        let c = detach_guarded(py, || cycle_block(ts, xs, fs, ds, offset, low, high, state))?;
        Ok(cycles_table(py, c))
    }
}

/// Streaming cycle finder of a long recording (`contactlab.studies._cycles`): upward
/// crossings of a drive channel and per-cycle loop energy, amplitude and offset (see
/// `contactlab_core::cycles::cycle_block`), the state carried from block to block.
#[pyclass(module = "contactlab._core")]
struct CycleStream {
    state: CycleState,
    /// `push_crossings` has cut this stream: its per-cycle state is stale, so `push` and
    /// `push_sampled` refuse it
    crossings_only: bool,
}

impl CycleStream {
    fn check_cycles(&self, py: Python<'_>) -> PyResult<()> {
        if self.crossings_only {
            return Err(input(
                py,
                "this CycleStream was cut by push_crossings (no per-cycle state): start a new one",
            ));
        }
        Ok(())
    }
}

/// The cycles a block completed (`CycleTracker.push`, `CycleStream.push`/`push_sampled`):
/// `crossings` (global sample indices of the block's upward crossings) and, one per complete
/// cycle, `start`, `end`, `energy`, `amplitude`, `offset`.
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct CycleBlock {
    crossings: Py<PyArray1<i64>>,
    start: Py<PyArray1<f64>>,
    end: Py<PyArray1<f64>>,
    energy: Py<PyArray1<f64>>,
    amplitude: Py<PyArray1<f64>>,
    offset: Py<PyArray1<f64>>,
}

fn cycles_table(py: Python<'_>, c: BlockCycles) -> CycleBlock {
    let idx: Vec<i64> = c
        .crossings
        .iter()
        .map(|&i| i64::try_from(i).unwrap_or(i64::MAX))
        .collect();
    CycleBlock {
        crossings: idx.into_pyarray(py).unbind(),
        start: c.start.into_pyarray(py).unbind(),
        end: c.end.into_pyarray(py).unbind(),
        energy: c.energy.into_pyarray(py).unbind(),
        amplitude: c.amplitude.into_pyarray(py).unbind(),
        offset: c.offset.into_pyarray(py).unbind(),
    }
}

#[pymethods]
impl CycleStream {
    #[new]
    fn new() -> Self {
        Self {
            state: CycleState::default(),
            crossings_only: false,
        }
    }

    /// The upward crossings alone of one block (global sample indices; see
    /// `contactlab_core::cycles::crossings_block`): those `push` finds, without the
    /// per-cycle quantities. A stream cut by this is cut by it to the end. ``finite``: the
    /// caller checked the samples finite (`crossings_block_checked`: not scanned again).
    #[pyo3(signature = (x, f, drive, offset, low, high, finite = false))]
    fn push_crossings<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        f: PyReadonlyArray1<'py, f64>,
        drive: PyReadonlyArray1<'py, f64>,
        offset: u64,
        low: f64,
        high: f64,
        finite: bool,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let (xs, fs, ds) = (slice(&x, "x")?, slice(&f, "F")?, slice(&drive, "drive")?);
        self.crossings_only = true;
        let state = &mut self.state;
        let c = detach_guarded(py, || {
            if finite {
                crossings_block_checked(xs, fs, ds, offset, (low, high), state)
            } else {
                crossings_block(xs, fs, ds, offset, (low, high), state)
            }
        })?;
        let idx: Vec<i64> = c
            .iter()
            .map(|&i| i64::try_from(i).unwrap_or(i64::MAX))
            .collect();
        Ok(idx.into_pyarray(py))
    }

    /// One block with its time stamps: a `CycleBlock`.
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
    ) -> PyResult<CycleBlock> {
        let (ts, xs, fs) = (slice(&t, "t")?, slice(&x, "x")?, slice(&f, "F")?);
        let ds = slice(&drive, "drive")?;
        self.check_cycles(py)?;
        let state = &mut self.state;
        let c = detach_guarded(py, || cycle_block(ts, xs, fs, ds, offset, low, high, state))?;
        Ok(cycles_table(py, c))
    }

    /// One block of a recording sampled every `dt` from `t0` (no time array; see
    /// `contactlab_core::cycles::cycle_block_sampled`): as `push`.
    fn push_sampled<'py>(
        &mut self,
        py: Python<'py>,
        t0: f64,
        dt: f64,
        x: PyReadonlyArray1<'py, f64>,
        f: PyReadonlyArray1<'py, f64>,
        drive: PyReadonlyArray1<'py, f64>,
        offset: u64,
        low: f64,
        high: f64,
    ) -> PyResult<CycleBlock> {
        let (xs, fs, ds) = (slice(&x, "x")?, slice(&f, "F")?, slice(&drive, "drive")?);
        self.check_cycles(py)?;
        let state = &mut self.state;
        let c = detach_guarded(py, || {
            cycle_block_sampled(t0, dt, xs, fs, ds, offset, low, high, state)
        })?;
        Ok(cycles_table(py, c))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CycleTracker>()?;
    m.add_class::<CycleStream>()?;
    m.add_class::<CycleBlock>()?;
    Ok(())
}
