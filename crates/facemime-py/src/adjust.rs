//! Bindings of `facemime_core::adjust`: the elastic adjustment of projected model vertices.

use facemime_core::adjust::{self, Contour, Settings};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::error::{invalid, CoreErr};
use crate::points::{array, rows};

/// Splits a concatenated array into consecutive runs of the given lengths.
fn runs<T: Clone>(name: &str, all: &[T], lengths: &[u32]) -> PyResult<Vec<Vec<T>>> {
    let total: usize = lengths.iter().map(|&n| n as usize).sum();
    if total != all.len() {
        return Err(invalid(format!(
            "{name}: lengths add up to {total}, but {} entries were given",
            all.len()
        )));
    }
    let mut out = Vec::with_capacity(lengths.len());
    let mut at = 0;
    for &n in lengths {
        out.push(all[at..at + n as usize].to_vec());
        at += n as usize;
    }
    Ok(out)
}

/// Adjusted points (N, 2) and the residual after each iteration.
type Adjusted<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// points: (N, 2) projected model vertices (pixels); chains + chain_lengths: the model vertex
/// indices of each contour, concatenated; targets + target_lengths: each contour's target
/// polyline, concatenated. Returns (adjusted points (N, 2), residuals (iterations + 1,)).
#[pyfunction]
#[pyo3(signature = (points, chains, chain_lengths, targets, target_lengths, psi, shrink, epsilon, iterations, tolerance))]
#[allow(clippy::too_many_arguments)]
fn elastic_adjust<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<f64>,
    chains: PyReadonlyArray1<u32>,
    chain_lengths: PyReadonlyArray1<u32>,
    targets: PyReadonlyArray2<f64>,
    target_lengths: PyReadonlyArray1<u32>,
    psi: f64,
    shrink: f64,
    epsilon: f64,
    iterations: usize,
    tolerance: f64,
) -> PyResult<Adjusted<'py>> {
    let mut pts = rows::<2, _>("points", &points)?;
    let chain_list: Vec<usize> = chains.as_array().iter().map(|&i| i as usize).collect();
    let chain_runs = runs("chains", &chain_list, chain_lengths.as_slice()?)?;
    let target_runs = runs(
        "targets",
        &rows::<2, _>("targets", &targets)?,
        target_lengths.as_slice()?,
    )?;
    if chain_runs.len() != target_runs.len() {
        return Err(invalid(format!(
            "{} chains but {} targets",
            chain_runs.len(),
            target_runs.len()
        )));
    }
    let contours: Vec<Contour> = chain_runs
        .into_iter()
        .zip(target_runs)
        .map(|(chain, target)| Contour { chain, target })
        .collect();
    let settings = Settings {
        psi,
        shrink,
        epsilon,
        iterations,
        tolerance,
    };
    let report = py
        .detach(|| adjust::elastic(&mut pts, &contours, &settings))
        .map_err(CoreErr::from)?;
    Ok((array(py, &pts), report.residuals.into_pyarray(py)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(elastic_adjust, m)?)?;
    Ok(())
}
