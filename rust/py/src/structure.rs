//! Bindings of `contactlab_core::structure`: array/error conversion and GIL release only.

use contactlab_core::curve::{Exponential, Tabulated};
use contactlab_core::structure::{
    simulate_into, Buffers, Inputs, Joint, JointLaw, MasingCurve, Options, Structure,
};
use contactlab_core::CoreError;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;

use crate::detach_guarded;
use crate::error::slice as sl;

fn bad(name: &'static str, reason: &'static str) -> CoreError {
    CoreError::InvalidParameter {
        name,
        value: f64::NAN,
        reason,
    }
}

/// `(kind, dof, dof2 or -1, params, array_a, array_b)` as `contactlab.structure.joints` sends it.
type JointSpec = (String, usize, i64, Vec<f64>, Vec<f64>, Vec<f64>);

fn build_joint(spec: &JointSpec) -> Result<Joint, CoreError> {
    let (kind, dof, dof2, p, a, b) = spec;
    let want = |k: usize| {
        if p.len() == k {
            Ok(())
        } else {
            Err(bad("joint params", "wrong number of joint parameters"))
        }
    };
    let law = match kind.as_str() {
        "masing" => {
            want(3)?;
            JointLaw::masing(MasingCurve::Exp(Exponential::new(p[0], p[1])?), p[2])?
        }
        "masing_tabulated" => {
            want(1)?;
            JointLaw::masing(MasingCurve::Tab(Tabulated::new(a, b)?), p[0])?
        }
        "jenkins" => {
            want(2)?;
            JointLaw::jenkins(p[0], p[1])?
        }
        "iwan" => JointLaw::iwan(a, b)?,
        "bouc_wen" => {
            want(5)?;
            JointLaw::bouc_wen(p[0], p[1], p[2], p[3], p[4])?
        }
        "kelvin_voigt" => {
            want(2)?;
            JointLaw::kelvin_voigt(p[0], p[1])?
        }
        "normal" => JointLaw::normal(a)?,
        "law" => JointLaw::law(contactlab_core::joints::AnyLaw::from_flat(a)?)?,
        _ => return Err(bad("joint kind", "unknown joint kind")),
    };
    Ok(Joint {
        law,
        dof: *dof,
        dof2: usize::try_from(*dof2).ok(),
    })
}

/// The result of `structure_simulate`: the flat output arrays (`x`, `v`, `a` of `n_t × n`
/// values, the joints' `joint_force`, `joint_work`, `joint_dissipated` of `n_t × n_joints`,
/// `input_work`, `damping_work` of `n_t`; empty when not asked for), valid for the first
/// `n_out` steps, the status (0 = success) with its message, and the step and iteration counts.
#[pyclass(module = "contactlab._core", frozen, get_all)]
struct StructureRun {
    x: Py<PyArray1<f64>>,
    v: Py<PyArray1<f64>>,
    a: Py<PyArray1<f64>>,
    joint_force: Py<PyArray1<f64>>,
    joint_work: Py<PyArray1<f64>>,
    joint_dissipated: Py<PyArray1<f64>>,
    input_work: Py<PyArray1<f64>>,
    damping_work: Py<PyArray1<f64>>,
    n_out: usize,
    status: i32,
    message: String,
    n_steps: u64,
    n_iter: u64,
}

/// Newmark simulation of a structure with joints; returns a `StructureRun`.
#[pyfunction]
#[pyo3(signature = (n, m, c, k, joints, t, x0, v0, force=None, base=None, base_velocity=None, kr=None, cr=None, rtol=1e-10, max_iter=30, outputs=None, tol=None, substeps=1))]
fn structure_simulate<'py>(
    py: Python<'py>,
    n: usize,
    m: PyReadonlyArray1<'py, f64>,
    c: PyReadonlyArray1<'py, f64>,
    k: PyReadonlyArray1<'py, f64>,
    joints: Vec<JointSpec>,
    t: PyReadonlyArray1<'py, f64>,
    x0: PyReadonlyArray1<'py, f64>,
    v0: PyReadonlyArray1<'py, f64>,
    force: Option<PyReadonlyArray1<'py, f64>>,
    base: Option<PyReadonlyArray1<'py, f64>>,
    base_velocity: Option<PyReadonlyArray1<'py, f64>>,
    kr: Option<PyReadonlyArray1<'py, f64>>,
    cr: Option<PyReadonlyArray1<'py, f64>>,
    rtol: f64,
    max_iter: usize,
    outputs: Option<Vec<String>>,
    tol: Option<f64>,
    substeps: usize,
) -> PyResult<StructureRun> {
    let (ms, cs, ks) = (sl(&m, "M")?, sl(&c, "C")?, sl(&k, "K")?);
    let (ts, x0s, v0s) = (sl(&t, "t")?, sl(&x0, "x0")?, sl(&v0, "v0")?);
    let fs = match &force {
        Some(f) => Some(sl(f, "force")?),
        None => None,
    };
    let base = match (&base, &base_velocity, &kr, &cr) {
        (Some(y), Some(yd), Some(kr), Some(cr)) => Some((
            sl(y, "base")?,
            sl(yd, "base_velocity")?,
            sl(kr, "K r")?,
            sl(cr, "C r")?,
        )),
        (None, None, None, None) => None,
        _ => {
            return Err(crate::error::to_pyerr(
                py,
                &bad("base", "base, base_velocity, kr and cr go together"),
            ))
        }
    };
    let opts = Options {
        rtol,
        max_iter,
        tol,
        substeps,
        ..Options::default()
    };
    // The outputs are numpy arrays the kernel writes into (no Vec and copy; numpy's large
    // allocations are also backed by huge pages where the system offers them, so the 64 MB of
    // a 1e6-sample run are not first-touched 4 kB at a time).
    let nt = ts.len();
    let too_many =
        || crate::error::to_pyerr(py, &bad("t", "too many samples for the output arrays"));
    let total = nt.checked_mul(n).ok_or_else(too_many)?;
    let total_j = nt.checked_mul(joints.len()).ok_or_else(too_many)?;
    let names = [
        "x",
        "v",
        "a",
        "joint_force",
        "joint_work",
        "joint_dissipated",
        "input_work",
        "damping_work",
    ];
    let mut lens = [total, total, total, total_j, total_j, total_j, nt, nt];
    // Outputs not asked for are empty arrays, and the kernel does not compute them.
    if let Some(wanted) = &outputs {
        if let Some(bad_name) = wanted.iter().find(|w| !names.contains(&w.as_str())) {
            return Err(crate::error::input(
                py,
                format!("unknown output {bad_name:?} (known: {})", names.join(", ")),
            ));
        }
        for (len, name) in lens.iter_mut().zip(names) {
            if !wanted.iter().any(|w| w == name) {
                *len = 0;
            }
        }
    }
    let arrays: Vec<Bound<'py, PyArray1<f64>>> = lens
        .iter()
        .map(|&len| PyArray1::<f64>::zeros(py, len, false))
        .collect();
    let mut rws: Vec<PyReadwriteArray1<'py, f64>> =
        arrays.iter().map(PyArrayMethods::readwrite).collect();
    let mut slices: Vec<&mut [f64]> = Vec::with_capacity(rws.len());
    for rw in &mut rws {
        slices.push(
            rw.as_slice_mut()
                .map_err(|_| crate::error::internal(py, "output array not contiguous"))?,
        );
    }
    let [x, v, a, joint_force, joint_work, joint_dissipated, input_work, damping_work] =
        <[&mut [f64]; 8]>::try_from(slices)
            .map_err(|_| crate::error::internal(py, "output arrays"))?;
    let mut bufs = Buffers {
        x,
        v,
        a,
        joint_force,
        joint_work,
        joint_dissipated,
        input_work,
        damping_work,
    };
    let r = detach_guarded(py, move || {
        let js = joints
            .iter()
            .map(build_joint)
            .collect::<Result<Vec<_>, _>>()?;
        let s = Structure::new(n, ms, cs, ks, js)?;
        let inp = Inputs {
            t: ts,
            force: fs,
            base,
        };
        simulate_into(&s, &inp, x0s, v0s, &opts, &mut bufs)
    })?;
    drop(rws);
    let [x, v, a, joint_force, joint_work, joint_dissipated, input_work, damping_work] =
        <[Bound<'py, PyArray1<f64>>; 8]>::try_from(arrays)
            .map_err(|_| crate::error::internal(py, "output arrays"))?;
    Ok(StructureRun {
        x: x.unbind(),
        v: v.unbind(),
        a: a.unbind(),
        joint_force: joint_force.unbind(),
        joint_work: joint_work.unbind(),
        joint_dissipated: joint_dissipated.unbind(),
        input_work: input_work.unbind(),
        damping_work: damping_work.unbind(),
        n_out: r.n_out,
        status: r.status.code(),
        message: r.status.message(),
        n_steps: r.n_steps,
        n_iter: r.n_iter,
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<StructureRun>()?;
    m.add_function(wrap_pyfunction!(structure_simulate, m)?)?;
    Ok(())
}
