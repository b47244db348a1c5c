//! Bindings of `facemime_core::flow`: `FlowFrames`, the pyramids of the last two frames
//! (each built once, their memory reused) and the Lucas-Kanade flow between them.

use facemime_core::flow::{self, LkParams, Pyramid};
use facemime_core::motion;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::error::CoreErr;
use crate::points::{array, rows};

/// The moved points and the mask of those followed.
type Flow<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<bool>>);

/// The head's step: its similarity or None, the kept rigid points' indices and positions, and
/// the extra points' positions.
type Step<'py> = (
    Option<Bound<'py, PyArray2<f64>>>,
    Bound<'py, PyArray1<usize>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// (N, 2) float64 array of points, NaN rows for None.
fn point_rows<'py>(py: Python<'py>, pts: &[Option<[f64; 2]>]) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<[f64; 2]> = pts.iter().map(|m| m.unwrap_or([f64::NAN; 2])).collect();
    array(py, &rows)
}

/// See `facemime.track.flow` for the documented API.
#[pyclass(module = "facemime._core")]
pub struct FlowFrames {
    max_level: usize,
    prev: Pyramid,
    cur: Pyramid,
    pushed: usize,
}

impl FlowFrames {
    fn ready(&self) -> PyResult<()> {
        if self.pushed < 2 {
            return Err(PyValueError::new_err(
                "the flow needs two frames; push another",
            ));
        }
        Ok(())
    }
}

#[pymethods]
impl FlowFrames {
    /// max_level: pyramid levels above the frame at most; window: odd Lucas-Kanade window side.
    #[new]
    fn new(max_level: usize, window: usize) -> PyResult<Self> {
        Ok(Self {
            max_level,
            prev: Pyramid::new(window).map_err(CoreErr)?,
            cur: Pyramid::new(window).map_err(CoreErr)?,
            pushed: 0,
        })
    }

    /// gray: (H, W) C-contiguous uint8, the next frame; crop: (x0, y0, x1, y1) pixels,
    /// exclusive ends, the part of it the flow may use.
    fn push(
        &mut self,
        py: Python<'_>,
        gray: PyReadonlyArray2<u8>,
        crop: [usize; 4],
    ) -> PyResult<()> {
        let shape = gray.as_array().shape().to_vec();
        let data = gray
            .as_slice()
            .map_err(|_| PyValueError::new_err("gray must be a C-contiguous uint8 array"))?;
        std::mem::swap(&mut self.prev, &mut self.cur);
        let (cur, max_level) = (&mut self.cur, self.max_level);
        py.detach(|| cur.rebuild(data, shape[1], shape[0], crop, max_level))
            .map_err(CoreErr)?;
        self.pushed += 1;
        Ok(())
    }

    /// points: (N, 2) pixels in the previous frame (the current one if `backward`). Returns
    /// ((N, 2) positions in the current frame (the previous one), NaN where the flow failed;
    /// (N,) mask of the points followed).
    #[pyo3(signature = (points, backward, iterations, epsilon, min_eigen))]
    fn track<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<f64>,
        backward: bool,
        iterations: usize,
        epsilon: f64,
        min_eigen: f64,
    ) -> PyResult<Flow<'py>> {
        self.ready()?;
        let pts = rows::<2>("points", &points)?;
        let params = LkParams {
            iterations,
            epsilon,
            min_eigen,
        };
        let (from, to) = if backward {
            (&self.cur, &self.prev)
        } else {
            (&self.prev, &self.cur)
        };
        let moved = py
            .detach(|| flow::lucas_kanade(from, to, &pts, &params))
            .map_err(CoreErr)?;
        let ok: Vec<bool> = moved.iter().map(Option::is_some).collect();
        Ok((point_rows(py, &moved), ok.into_pyarray(py)))
    }

    /// points: (N, 2) rigid points and extra: (M, 2) other points, pixels in the previous
    /// frame; extra_levels: pyramid levels above the frame at most for the extra points, whose
    /// flow starts where the head's similarity carries them when there is one; limit:
    /// forward-backward and fit tolerance (px); min_points: fewest points for a similarity;
    /// rounds: its fit's rounds at most. Returns (the 2×3 similarity or None, the
    /// (K,) indices of the rigid points kept, their (K, 2) positions in the current frame, the
    /// extra points' (M, 2) positions, NaN where the flow failed or its check).
    #[pyo3(signature = (points, extra, extra_levels, limit, min_points, rounds, iterations, epsilon, min_eigen))]
    #[allow(clippy::too_many_arguments)]
    fn follow<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<f64>,
        extra: PyReadonlyArray2<f64>,
        extra_levels: usize,
        limit: f64,
        min_points: usize,
        rounds: usize,
        iterations: usize,
        epsilon: f64,
        min_eigen: f64,
    ) -> PyResult<Step<'py>> {
        self.ready()?;
        let (pts, more) = (rows::<2>("points", &points)?, rows::<2>("extra", &extra)?);
        let lk = LkParams {
            iterations,
            epsilon,
            min_eigen,
        };
        let (prev, cur) = (&self.prev, &self.cur);
        let step = py
            .detach(|| {
                motion::follow_rigid(
                    prev,
                    cur,
                    &pts,
                    &more,
                    extra_levels,
                    &lk,
                    limit,
                    min_points,
                    rounds,
                )
            })
            .map_err(CoreErr)?;
        Ok((
            step.similarity.map(|m| array(py, &m)),
            step.kept.into_pyarray(py),
            array(py, &step.moved),
            point_rows(py, &step.extra),
        ))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FlowFrames>()?;
    Ok(())
}
