//! Bindings of `facemime_core::motion`: the robust similarity fit of the head motion.

use facemime_core::motion;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::points::{array, rows};

/// The 2×3 similarity and the inlier mask.
type Fit<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<bool>>);

/// src, dst: (N, 2) points (pixels); limit: inlier residual (pixels); rounds: IRLS rounds at most.
/// Returns (the 2×3 similarity mapping src onto dst, the (N,) inlier mask).
#[pyfunction]
fn robust_similarity<'py>(
    py: Python<'py>,
    src: PyReadonlyArray2<f64>,
    dst: PyReadonlyArray2<f64>,
    limit: f64,
    rounds: usize,
) -> PyResult<Fit<'py>> {
    let (s, d) = (rows::<2>("src", &src)?, rows::<2>("dst", &dst)?);
    if s.len() != d.len() {
        return Err(PyValueError::new_err(format!(
            "src has {} points but dst has {}",
            s.len(),
            d.len()
        )));
    }
    let (m, inliers) = py.detach(|| motion::robust_similarity(&s, &d, limit, rounds));
    Ok((array(py, &m), inliers.into_pyarray(py)))
}

/// points: (N, 2) pixels; quads: (Z, 4, 2) convex quadrilaterals, corners in order. Returns
/// the (N,) mask of the points inside (or on the border of) any of them.
#[pyfunction]
fn inside_quads<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<f64>,
    quads: PyReadonlyArray3<f64>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let pts = rows::<2>("points", &points)?;
    let q = quads.as_array();
    if q.shape()[1..] != [4, 2] {
        return Err(PyValueError::new_err(format!(
            "quads must have shape (Z, 4, 2), got {:?}",
            q.shape()
        )));
    }
    let quads: Vec<[[f64; 2]; 4]> = q
        .outer_iter()
        .map(|c| std::array::from_fn(|k| [c[[k, 0]], c[[k, 1]]]))
        .collect();
    Ok(motion::inside_quads(&pts, &quads).into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(inside_quads, m)?)?;
    m.add_function(wrap_pyfunction!(robust_similarity, m)?)?;
    Ok(())
}
