//! `contactlab._core`: converts numpy arrays and errors, releases the GIL, and nothing else.
//! All physics lives in `contactlab-core`.

// PyO3 extracts arguments by value; borrowing them is not an option in signatures.
#![allow(clippy::needless_pass_by_value)]

use contactlab_core::{
    curve::{Backbone, Exponential, Tabulated},
    masing, BranchRule, CoreError, MasingState,
};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;

mod errors;
mod joints;
mod loop_fit;
mod normal;
mod scan;
mod signal;
mod stream;
mod structure;
use errors::{internal, slice, to_pyerr};

/// Run `f` without the GIL, turning a panic (a bug, never expected) into `ContactLabError`.
pub(crate) fn detach_guarded<T: Send, F: FnOnce() -> Result<T, CoreError> + Send>(
    py: Python<'_>,
    f: F,
) -> PyResult<T> {
    let r = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match r {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_pyerr(py, &e)),
        Err(_) => Err(internal(
            py,
            "internal error in contactlab core (panic caught)",
        )),
    }
}

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
    /// With `threads > 1` a long chunk runs in pieces of `piece` samples on that many threads
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
            let mut rw = arr.try_readwrite().map_err(|_| {
                errors::input(py, "out must be a writeable array not shared with x")
            })?;
            let out = rw
                .as_slice_mut()
                .map_err(|_| errors::input(py, "out must be contiguous"))?;
            let me = &*self;
            st = detach_guarded(py, || {
                if threads > 1 {
                    let mut sts = [st];
                    masing::split::force_channels(
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

    /// Closed cycles of `x` (continuing the carried history, which is advanced):
    /// dict of arrays `range, mean, start, end, count, energy`.
    fn cycles<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let xs = slice(&x, "x")?;
        if self.anchored {
            return Err(errors::input(
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
        let d = PyDict::new(py);
        let col =
            |f: &dyn Fn(&masing::Cycle) -> f64| -> Vec<f64> { cycles.iter().map(f).collect() };
        d.set_item("range", col(&|c| c.range).into_pyarray(py))?;
        d.set_item("mean", col(&|c| c.mean).into_pyarray(py))?;
        let idx = |f: &dyn Fn(&masing::Cycle) -> u64| -> Vec<i64> {
            cycles.iter().map(|c| f(c) as i64).collect()
        };
        d.set_item("start", idx(&|c| c.start).into_pyarray(py))?;
        d.set_item("end", idx(&|c| c.end).into_pyarray(py))?;
        d.set_item("count", col(&|c| c.count).into_pyarray(py))?;
        d.set_item("energy", col(&|c| c.energy).into_pyarray(py))?;
        Ok(d)
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

impl masing::split::Channel for MasingCore {
    fn split(
        &self,
        x: &[f64],
        state: &MasingState,
        piece: usize,
        emit: &mut dyn FnMut(usize, MasingState) -> bool,
    ) -> Result<masing::split::Walked, CoreError> {
        let rule = self.rule();
        with_curve!(&self.curve, curve => masing::split::Model { curve, rule }.split(x, state, piece, emit))
    }
    fn piece(
        &self,
        x: &[f64],
        out: &mut [f64],
        state: &mut MasingState,
    ) -> Result<bool, CoreError> {
        let rule = self.rule();
        with_curve!(&self.curve, curve => masing::split::Model { curve, rule }.piece(x, out, state))
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

/// `∮ F dx` of the closed polygon through the samples (positive for a dissipative loop).
#[pyfunction]
#[pyo3(name = "loop_area")]
fn loop_area_py(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    f: PyReadonlyArray1<'_, f64>,
) -> PyResult<f64> {
    let (xs, fs) = (slice(&x, "x")?, slice(&f, "F")?);
    detach_guarded(py, || masing::loop_area(xs, fs))
}

static VERSION: PyOnceLock<String> = PyOnceLock::new();

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add(
        "__version__",
        VERSION.get_or_init(py, || env!("CARGO_PKG_VERSION").to_string()),
    )?;
    m.add_class::<MasingCore>()?;
    m.add_function(wrap_pyfunction!(loop_area_py, m)?)?;
    normal::register(m)?;
    structure::register(m)?;
    signal::register(m)?;
    scan::register(m)?;
    stream::register(m)?;
    loop_fit::register(m)?;
    joints::register(m)?;
    Ok(())
}
