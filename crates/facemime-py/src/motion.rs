//! Bindings of `facemime_core::motion`: the robust similarity fit of the head motion.

use crate::error::invalid;
use facemime_core::{extent, motion};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::points::{array, matrix, rows, same_length, MaskedPoints};

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
    let (s, d) = (rows::<2, _>("src", &src)?, rows::<2, _>("dst", &dst)?);
    same_length(&[("src", s.len()), ("dst", d.len())])?;
    let (m, inliers) = py.detach(|| motion::robust_similarity(&s, &d, limit, rounds));
    Ok((array(py, &m), inliers.into_pyarray(py)))
}

/// a, b: 2×3 transforms. Returns the 2×3 transform a ∘ b (b first).
#[pyfunction]
fn compose<'py>(
    py: Python<'py>,
    a: PyReadonlyArray2<f64>,
    b: PyReadonlyArray2<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b) = (matrix::<3>("a", &a)?, matrix::<3>("b", &b)?);
    Ok(array(py, &motion::compose(&a, &b)))
}

/// points: (N, 2) pixels; margin: pixels; width, height: the frame's. Returns the integer box
/// (x0, y0, x1, y1), exclusive ends, from the floor of the points' smallest to the ceiling of
/// their largest coordinates, grown by `margin` and clipped to the frame (empty, x1 <= x0 or
/// y1 <= y0, when the points lie outside it).
#[pyfunction]
fn grown_box(
    points: PyReadonlyArray2<f64>,
    margin: i64,
    width: usize,
    height: usize,
) -> PyResult<(i64, i64, i64, i64)> {
    let pts = rows::<2, _>("points", &points)?;
    if pts.is_empty() {
        return Err(invalid("a box needs at least one point"));
    }
    let [x0, y0, x1, y1] = extent::grown_box(pts, margin, width, height);
    Ok((x0, y0, x1, y1))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(grown_box, m)?)?;
    m.add_function(wrap_pyfunction!(compose, m)?)?;
    m.add_function(wrap_pyfunction!(robust_similarity, m)?)?;
    Ok(())
}
