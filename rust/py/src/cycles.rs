//! Binding of `contactlab_core::cycles`: the streaming cycle finder (`cycle_block`), with
//! and without a time axis.

use contactlab_core::cycles::{cycle_block, cycle_block_sampled, BlockCycles, CycleState};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detach_guarded;
use crate::error::slice;

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

/// Streaming cycle finder of a long recording (`contactlab.studies._cycles`): upward
/// crossings of a drive channel and per-cycle loop energy, amplitude and offset (see
/// `contactlab_core::cycles::cycle_block`), the state carried from block to block.
#[pyclass(module = "contactlab._core")]
struct CycleStream {
    state: CycleState,
}

fn cycles_dict(py: Python<'_>, c: BlockCycles) -> PyResult<Bound<'_, PyDict>> {
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

#[pymethods]
impl CycleStream {
    #[new]
    fn new() -> Self {
        Self {
            state: CycleState::default(),
        }
    }

    /// One block with its time stamps: dict of arrays `crossings` (global indices), `start`,
    /// `end`, `energy`, `amplitude`, `offset` (one per complete cycle).
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
        cycles_dict(py, c)
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
    ) -> PyResult<Bound<'py, PyDict>> {
        let (xs, fs, ds) = (slice(&x, "x")?, slice(&f, "F")?, slice(&drive, "drive")?);
        let state = &mut self.state;
        let c = detach_guarded(py, || {
            cycle_block_sampled(t0, dt, xs, fs, ds, offset, low, high, state)
        })?;
        cycles_dict(py, c)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CycleTracker>()?;
    m.add_class::<CycleStream>()?;
    Ok(())
}
