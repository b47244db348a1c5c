//! Bindings of `facemime_core::lip_search` and `facemime_core::lip_placement`: the lip-edge
//! search along the mouth knots' normals, and the tracker's placement of mouth knots there.

use facemime_core::lip_placement;
use facemime_core::lip_search::{self, LipColour};
use numpy::{
    IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyReadwriteArray2,
};
use pyo3::prelude::*;

use crate::error::CoreErr;
use crate::points::image_view;
use crate::points::{rows, write_rows};

/// The core's lip colour from (w_r, w_g, bias).
fn lip_colour(c: [f64; 3]) -> LipColour {
    LipColour {
        weights: [c[0], c[1]],
        bias: c[2],
    }
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
    let img = image_view("frame", &frame)?;
    let colour = lip_colour(colour);
    let (x0, y0, x1, y1) = bounds;
    let map = lip_search::score_map(&img, &colour, [x0, y0, x1, y1]).map_err(CoreErr)?;
    let map = ndarray::Array2::from_shape_vec((y1 - y0, x1 - x0), map).expect("box-sized");
    Ok(map.into_pyarray(py))
}

/// See `facemime.track.lips.LipSearch` for the documented API.
#[pyclass(module = "facemime._core")]
pub struct LipPlacer {
    placer: lip_placement::LipPlacer,
}

#[pymethods]
impl LipPlacer {
    /// frame: the first frame, (H, W, 3) uint8 RGB; colour: (w_r, w_g, bias) of its lip score;
    /// reach: search range, ± px; min_step: smallest edge (score units per px); index: the knot
    /// indices of the outer upper, outer lower, inner upper and inner lower lip; signs: per
    /// curve, +1 where the score rises along the downward normal at its edge, −1 where it
    /// falls; edges: (K, 2) pixels, the first frame's knots as settled on the image edges.
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        frame: PyReadonlyArray3<u8>,
        colour: [f64; 3],
        reach: f64,
        min_step: f64,
        index: [Vec<usize>; 4],
        signs: [f64; 4],
        edges: PyReadonlyArray2<f64>,
    ) -> PyResult<Self> {
        let img = image_view("frame", &frame)?;
        let edges = rows::<2, _>("edges", &edges)?;
        let colour = lip_colour(colour);
        let placer = py
            .detach(|| {
                lip_placement::LipPlacer::new(&img, colour, reach, min_step, index, signs, &edges)
            })
            .map_err(CoreErr)?;
        Ok(Self { placer })
    }

    /// frame: (H, W, 3) uint8 RGB; knots: (K, 2) pixels, moved in place; unfollowed: (K,)
    /// bool, the knots the optical flow could not follow; scale: the head's scale relative to
    /// the first frame.
    fn place(
        &self,
        py: Python<'_>,
        frame: PyReadonlyArray3<u8>,
        mut knots: PyReadwriteArray2<f64>,
        unfollowed: PyReadonlyArray1<bool>,
        scale: f64,
    ) -> PyResult<()> {
        let img = image_view("frame", &frame)?;
        let mut pts = rows::<2, _>("knots", &knots)?;
        let unfollowed = unfollowed.as_array().to_vec();
        py.detach(|| self.placer.place(&img, &mut pts, &unfollowed, scale))
            .map_err(CoreErr)?;
        write_rows(&mut knots, &pts);
        Ok(())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LipPlacer>()?;
    m.add_function(wrap_pyfunction!(lip_score_map, m)?)?;
    Ok(())
}
