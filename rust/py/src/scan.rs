//! Binding of `contactlab_core::scan` (the HDF5 structure checks' signature search).

use contactlab_core::scan::signature_positions;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::detach_guarded;
use crate::error::input;

/// Every position (``offset`` + index in ``block``) of each of ``needles`` that starts
/// before ``starts_below`` in ``block`` (a ``uint8`` array): one ``int64`` array a needle.
#[pyfunction]
#[pyo3(name = "signature_positions")]
fn signature_positions_py<'py>(
    py: Python<'py>,
    block: PyReadonlyArray1<'py, u8>,
    needles: Vec<Bound<'py, PyBytes>>,
    starts_below: usize,
    offset: u64,
) -> PyResult<Vec<Bound<'py, PyArray1<i64>>>> {
    let hay = block
        .as_slice()
        .map_err(|_| input(py, "block must be a contiguous array"))?;
    let nds: Vec<Vec<u8>> = needles.iter().map(|b| b.as_bytes().to_vec()).collect();
    let found = detach_guarded(py, || {
        let refs: Vec<&[u8]> = nds.iter().map(Vec::as_slice).collect();
        signature_positions(hay, &refs, starts_below)
    })?;
    let too_far = || input(py, "a signature's position does not fit in 64 bits");
    found
        .into_iter()
        .map(|hits| {
            hits.into_iter()
                .map(|i| {
                    u64::try_from(i)
                        .ok()
                        .and_then(|i| i.checked_add(offset))
                        .and_then(|p| i64::try_from(p).ok())
                        .ok_or_else(too_far)
                })
                .collect::<PyResult<Vec<i64>>>()
                .map(|v| v.into_pyarray(py))
        })
        .collect()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(signature_positions_py, m)?)?;
    Ok(())
}
