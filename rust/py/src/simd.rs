//! Binding of `contactlab_core::simd`: the instruction-set level the kernels run at.

use contactlab_core::simd::level;
use pyo3::prelude::*;

/// The SIMD level the vectorised kernels run at in this process (`"generic"`, `"avx2"` or
/// `"avx512"`; detected once, capped by `CONTACTLAB_SIMD`).
#[pyfunction]
fn simd_level() -> &'static str {
    level().name()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simd_level, m)?)?;
    Ok(())
}
