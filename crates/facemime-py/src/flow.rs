//! Bindings of `facemime_core::flow`: `FlowFrames`, the pyramids of the last two frames
//! (each built once, their memory reused) and the Lucas-Kanade flow between them.

use facemime_core::flow::{self, LkParams, Pyramid};
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArrayDyn};
use pyo3::prelude::*;

use crate::error::{invalid, CoreErr};
use crate::points::{image_view, point_rows, rows, MaskedPoints};

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
            return Err(invalid("the flow needs two frames; push another"));
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

    /// frame: (H, W) grey or (H, W, 3) RGB C-contiguous uint8, the next frame; crop: (x0, y0,
    /// x1, y1) pixels, exclusive ends, the part of it the flow may use.
    fn push(
        &mut self,
        py: Python<'_>,
        frame: PyReadonlyArrayDyn<u8>,
        crop: [usize; 4],
    ) -> PyResult<()> {
        let frame = image_view("frame", &frame)?;
        std::mem::swap(&mut self.prev, &mut self.cur);
        let (cur, max_level) = (&mut self.cur, self.max_level);
        py.detach(|| cur.rebuild(&frame, crop, max_level))
            .map_err(CoreErr)?;
        self.pushed += 1;
        Ok(())
    }

    /// points: (N, 2) pixels in the previous frame (the current one if `backward`). Returns
    /// ((N, 2) positions in the current frame (the previous one), NaN where the flow failed;
    /// (N,) mask of the points followed).
    #[pyo3(signature = (points, backward, iterations, epsilon, min_eigen))]
    fn track<'py>(
        &mut self,
        py: Python<'py>,
        points: PyReadonlyArray2<f64>,
        backward: bool,
        iterations: usize,
        epsilon: f64,
        min_eigen: f64,
    ) -> PyResult<MaskedPoints<'py>> {
        self.ready()?;
        let pts = rows::<2, _>("points", &points)?;
        let params = LkParams {
            iterations,
            epsilon,
            min_eigen,
        };
        let (from, to) = if backward {
            (&mut self.cur, &mut self.prev)
        } else {
            (&mut self.prev, &mut self.cur)
        };
        let moved = py
            .detach(|| flow::lucas_kanade(from, to, &pts, &params))
            .map_err(CoreErr)?;
        let ok: Vec<bool> = moved.iter().map(Option::is_some).collect();
        Ok((point_rows(py, &moved), ok.into_pyarray(py)))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FlowFrames>()?;
    Ok(())
}
