//! Bindings of `facemime_core::pose`: the orthographic head-pose fit.

use facemime_core::pose::{self, FitSettings};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::points::{rows, same_length};

/// model_points: (M, 3) model units; image_points: (M, 2) pixels; start: (yaw, pitch, roll
/// degrees, ln scale, tx, ty pixels); yaw and pitch are held at `anchor` with weight `prior`
/// (px² per degree²). Returns the fitted parameters in the same order.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fit_pose(
    py: Python<'_>,
    model_points: PyReadonlyArray2<f64>,
    image_points: PyReadonlyArray2<f64>,
    start: [f64; 6],
    anchor: [f64; 2],
    prior: f64,
    huber: f64,
    iterations: usize,
) -> PyResult<[f64; 6]> {
    let (x, t) = (
        rows::<3, _>("model_points", &model_points)?,
        rows::<2, _>("image_points", &image_points)?,
    );
    same_length(&[("model_points", x.len()), ("image_points", t.len())])?;
    let settings = FitSettings {
        huber,
        prior,
        anchor,
        iterations,
    };
    Ok(py.detach(|| pose::fit(&x, &t, start, &settings)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit_pose, m)?)?;
    Ok(())
}
