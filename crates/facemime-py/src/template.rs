//! Bindings of `facemime_core::template`: grey areas of frames and template matching.

use facemime_core::template::{self, Grey};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyReadonlyArrayDyn};
use pyo3::prelude::*;

use crate::error::CoreErr;
use crate::points::image_view;

/// image: (H, W) grey or (H, W, 3) RGB C-contiguous uint8; area: (x0, y0, x1, y1) pixels,
/// exclusive ends. Returns the (h, w) uint8 grey levels (`facemime_core::template::grey_area`).
#[pyfunction]
fn grey_area<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<u8>,
    area: [usize; 4],
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let image = image_view("image", &image)?;
    let g = py
        .detach(|| template::grey_area(&image, area))
        .map_err(CoreErr)?;
    Ok(Array2::from_shape_vec((g.height, g.width), g.data)
        .expect("h x w")
        .into_pyarray(py))
}

fn grey(name: &str, a: &PyReadonlyArray2<u8>) -> PyResult<Grey> {
    let v = a.as_array();
    let (h, w) = v.dim();
    let data = v
        .as_slice()
        .map_or_else(|| v.iter().copied().collect(), <[u8]>::to_vec);
    Grey::new(data, w, h).map_err(|e| {
        CoreErr(facemime_core::CoreError::InvalidInput(format!(
            "{name}: {e}"
        )))
        .into()
    })
}

/// window, template: (h, w) uint8 grey levels. Returns ((x, y), score): the template's best
/// placement in the window (its top-left pixel, pixels of the window) and the normalised
/// cross-correlation there (`facemime_core::template::best_match`).
#[pyfunction]
fn best_match(
    py: Python<'_>,
    window: PyReadonlyArray2<u8>,
    template: PyReadonlyArray2<u8>,
) -> PyResult<((usize, usize), f64)> {
    let (w, t) = (grey("window", &window)?, grey("template", &template)?);
    let m = py
        .detach(|| template::best_match(&w, &t))
        .map_err(CoreErr)?;
    Ok(((m.x, m.y), m.score))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(grey_area, m)?)?;
    m.add_function(wrap_pyfunction!(best_match, m)?)?;
    Ok(())
}
