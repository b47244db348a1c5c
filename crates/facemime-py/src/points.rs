//! Point arrays from numpy: (K, 2) pixel or (K, 3) model coordinates as fixed-size rows; and
//! grey or colour images as core views.

use facemime_core::raster::ImageRef;
use numpy::ndarray::Dimension;
use numpy::{
    Element, IntoPyArray, PyArray1, PyArray2, PyReadonlyArray, PyReadonlyArray2, PyReadwriteArray2,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::error::{invalid, CoreErr};

/// The rows of a (K, D) array (float64 points, float32 corners, index pairs); a clear error
/// naming `name` for another shape.
pub fn rows<const D: usize, T: Element + Copy>(
    name: &str,
    a: &PyReadonlyArray2<T>,
) -> PyResult<Vec<[T; D]>> {
    let v = a.as_array();
    if v.shape()[1] != D {
        return Err(invalid(format!(
            "{name} must have shape (K, {D}), got {:?}",
            v.shape()
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|i| r[i]))
        .collect())
}

/// Writes `pts` into the (K, 2) array `out`, row by row.
pub fn write_rows(out: &mut PyReadwriteArray2<f64>, pts: &[[f64; 2]]) {
    for (mut row, p) in out.as_array_mut().rows_mut().into_iter().zip(pts) {
        row[0] = p[0];
        row[1] = p[1];
    }
}

/// A (2, C) float64 array (a 2×3 transform, a 2×2 linear map) as its two rows; a clear error
/// naming `name` for another shape.
pub fn matrix<const C: usize>(name: &str, m: &PyReadonlyArray2<f64>) -> PyResult<[[f64; C]; 2]> {
    match rows::<C, _>(name, m)?.as_slice() {
        &[a, b] => Ok([a, b]),
        r => Err(invalid(format!(
            "{name} must have shape (2, {C}), got ({}, {C})",
            r.len()
        ))),
    }
}

/// An error unless the arrays, given as (name, length) pairs, all have the same length.
pub fn same_length(arrays: &[(&str, usize)]) -> PyResult<()> {
    if arrays.iter().all(|&(_, n)| n == arrays[0].1) {
        return Ok(());
    }
    let names: Vec<&str> = arrays.iter().map(|&(name, _)| name).collect();
    let lengths: Vec<String> = arrays.iter().map(|&(_, n)| n.to_string()).collect();
    Err(invalid(format!(
        "{} must have the same length, got {}",
        names.join(", "),
        lengths.join(", ")
    )))
}

/// A (K, D) float64 array of fixed-size rows (a point array, or a matrix such as the 2×3
/// similarity as its two rows).
pub fn array<'py, const D: usize>(py: Python<'py>, rows: &[[f64; D]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    numpy::ndarray::Array2::from_shape_vec((rows.len(), D), flat)
        .expect("K x D")
        .into_pyarray(py)
}

/// (K, 2) float64 points and a (K,) mask over them (the inliers of a fit, the points a flow
/// followed).
pub type MaskedPoints<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<bool>>);

/// (N, 2) float64 array of points, NaN rows where a point is None (lost).
pub fn point_rows<'py>(py: Python<'py>, pts: &[Option<[f64; 2]>]) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<[f64; 2]> = pts.iter().map(|m| m.unwrap_or([f64::NAN; 2])).collect();
    array(py, &rows)
}

/// A (H, W) grey or (H, W, C) C-contiguous uint8 image as a core image view (the core checks
/// the channels each use takes); a clear error naming `name` otherwise.
pub fn image_view<'a, D: Dimension>(
    name: &str,
    img: &'a PyReadonlyArray<'_, u8, D>,
) -> PyResult<ImageRef<'a>> {
    let shape = img.shape().to_vec();
    let data = img
        .as_slice()
        .map_err(|_| invalid(format!("{name} must be a C-contiguous uint8 array")))?;
    let channels = match shape.len() {
        2 => 1,
        3 => shape[2],
        n => {
            return Err(invalid(format!(
                "{name} must be a (H, W) or (H, W, C) image, got {n} dimensions"
            )))
        }
    };
    Ok(ImageRef::named(name, data, shape[1], shape[0], channels).map_err(CoreErr)?)
}
