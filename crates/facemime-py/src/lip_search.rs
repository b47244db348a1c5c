//! Bindings of `facemime_core::lip_search`: the lip-edge search along the mouth knots' normals.

use facemime_core::lip_search::{self, LipColour, Probe, SearchSettings};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;

use crate::error::CoreErr;
use crate::points::{rows, same_length};
use crate::snake::rgb_view;

/// The core's lip colour from (w_r, w_g, bias).
fn lip_colour(c: [f64; 3]) -> LipColour {
    LipColour {
        weights: [c[0], c[1]],
        bias: c[2],
    }
}

/// frame: (H, W, 3) uint8 RGB; colour: (w_r, w_g, bias) of the lip score; points, normals:
/// (K, 2) pixels and unit vectors; signs: (K,) +1 for a score rising along the normal, −1 for
/// one falling; expect: (K,) offsets (px) to search nearest to; reach, sigma (px), min_step.
/// Returns the (K,) offsets (px along the normals), NaN where no transition was found.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn find_lip_edges<'py>(
    py: Python<'py>,
    frame: PyReadonlyArray3<u8>,
    colour: [f64; 3],
    points: PyReadonlyArray2<f64>,
    normals: PyReadonlyArray2<f64>,
    signs: PyReadonlyArray1<f64>,
    expect: PyReadonlyArray1<f64>,
    reach: f64,
    sigma: f64,
    min_step: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let img = rgb_view("frame", &frame)?;
    let (at, normal) = (
        rows::<2>("points", &points)?,
        rows::<2>("normals", &normals)?,
    );
    let (signs, expect) = (signs.as_array(), expect.as_array());
    let k = at.len();
    same_length(&[
        ("points", k),
        ("normals", normal.len()),
        ("signs", signs.len()),
        ("expect", expect.len()),
    ])?;
    let probes: Vec<Probe> = (0..k)
        .map(|i| Probe {
            at: at[i],
            normal: normal[i],
            sign: signs[i],
            expect: expect[i],
        })
        .collect();
    let colour = lip_colour(colour);
    let settings = SearchSettings {
        reach,
        sigma,
        min_step,
    };
    let found = py
        .detach(|| lip_search::find_edges(&img, &colour, &probes, &settings))
        .map_err(CoreErr)?;
    Ok(found.into_pyarray(py))
}

/// frame: (H, W, 3) uint8 RGB; colour: (w_r, w_g, bias) of the lip score; points: (K, 2)
/// pixels. Returns the (K,) scores averaged over the 3×3 pixels nearest each point.
#[pyfunction]
fn lip_scores_near<'py>(
    py: Python<'py>,
    frame: PyReadonlyArray3<u8>,
    colour: [f64; 3],
    points: PyReadonlyArray2<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let img = rgb_view("frame", &frame)?;
    let at = rows::<2>("points", &points)?;
    let colour = lip_colour(colour);
    let scores = lip_search::scores_near(&img, &colour, &at).map_err(CoreErr)?;
    Ok(scores.into_pyarray(py))
}

/// frame: (H, W, 3) uint8 RGB; colour: (w_r, w_g, bias) of the lip score; bounds: (x0, y0, x1,
/// y1), exclusive ends. Returns the (y1 − y0, x1 − x0) float32 scores of the box's pixels.
#[pyfunction]
fn lip_score_map<'py>(
    py: Python<'py>,
    frame: PyReadonlyArray3<u8>,
    colour: [f64; 3],
    bounds: (usize, usize, usize, usize),
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let img = rgb_view("frame", &frame)?;
    let colour = lip_colour(colour);
    let (x0, y0, x1, y1) = bounds;
    let map = lip_search::score_map(&img, &colour, [x0, y0, x1, y1]).map_err(CoreErr)?;
    let map = ndarray::Array2::from_shape_vec((y1 - y0, x1 - x0), map).expect("box-sized");
    Ok(map.into_pyarray(py))
}

/// points, normals: (K, 2) pixels and unit vectors; curve: (M, 2) pixels, a polyline.
/// Returns the (K,) signed distances (px) along the normals to the curve's nearest crossing,
/// NaN where a normal's line misses it.
#[pyfunction]
fn normal_gaps<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<f64>,
    normals: PyReadonlyArray2<f64>,
    curve: PyReadonlyArray2<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (at, normal) = (
        rows::<2>("points", &points)?,
        rows::<2>("normals", &normals)?,
    );
    same_length(&[("points", at.len()), ("normals", normal.len())])?;
    let curve = rows::<2>("curve", &curve)?;
    Ok(lip_search::normal_gaps(&at, &normal, &curve).into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(find_lip_edges, m)?)?;
    m.add_function(wrap_pyfunction!(lip_scores_near, m)?)?;
    m.add_function(wrap_pyfunction!(lip_score_map, m)?)?;
    m.add_function(wrap_pyfunction!(normal_gaps, m)?)?;
    Ok(())
}
