//! Binding of `contactlab_core::stream` and of the streaming cycle finder
//! (`contactlab_core::cycles::cycle_block`): the reading side of a streamed analysis.

use contactlab_core::cycles::{cycle_block, cycle_block_sampled, BlockCycles, CycleState};
use contactlab_core::stream::fill_time;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::detach_guarded;
use crate::errors::{input, slice};

/// ``out[i] = t0 + dt * (offset + i)`` (see `contactlab_core::stream::fill_time`).
#[pyfunction]
#[pyo3(name = "fill_time")]
fn fill_time_py<'py>(
    py: Python<'py>,
    mut out: PyReadwriteArray1<'py, f64>,
    t0: f64,
    dt: f64,
    offset: u64,
) -> PyResult<()> {
    let os = out
        .as_slice_mut()
        .map_err(|_| input(py, "out must be a contiguous array"))?;
    detach_guarded(py, || fill_time(os, t0, dt, offset))
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
        cycles_dict(py, c)
    }

    /// One block of a recording sampled every `dt` from `t0` (no time array; see
    /// `contactlab_core::cycles::cycle_block_sampled`): as `push`.
    #[allow(clippy::too_many_arguments)]
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
    m.add_class::<CycleStream>()?;
    m.add_function(wrap_pyfunction!(fill_time_py, m)?)?;
    Ok(())
}
