//! Bindings of `facemime_core::motion`: the robust similarity fit of the head motion.

use facemime_core::motion;
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::points::{array, rows, same_length, MaskedPoints};

/// src, dst: (N, 2) points (pixels); limit: inlier residual (pixels); rounds: IRLS rounds at most.
/// Returns (the 2×3 similarity mapping src onto dst, the (N,) inlier mask).
#[pyfunction]
fn robust_similarity<'py>(
    py: Python<'py>,
    src: PyReadonlyArray2<f64>,
    dst: PyReadonlyArray2<f64>,
    limit: f64,
    rounds: usize,
) -> PyResult<MaskedPoints<'py>> {
    let (s, d) = (rows::<2>("src", &src)?, rows::<2>("dst", &dst)?);
    same_length(&[("src", s.len()), ("dst", d.len())])?;
    let (m, inliers) = py.detach(|| motion::robust_similarity(&s, &d, limit, rounds));
    Ok((array(py, &m), inliers.into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(robust_similarity, m)?)?;
    Ok(())
}
