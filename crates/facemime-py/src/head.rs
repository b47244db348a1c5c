//! Bindings of `facemime_core::head`: `HeadFollower`, the head's rigid points followed from
//! frame to frame.

use facemime_core::corners::CornerSettings;
use facemime_core::flow::LkParams;
use facemime_core::head::{self, FollowSettings, Quad};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3,
    PyReadonlyArrayDyn,
};
use pyo3::prelude::*;

use crate::error::{invalid, CoreErr};
use crate::points::{array, image_view, matrix, point_rows, rows};

/// The head's similarity step or None, and the extra points' positions.
type Step<'py> = (Option<Bound<'py, PyArray2<f64>>>, Bound<'py, PyArray2<f64>>);

/// (M, 2) float32 points.
fn f32_rows<'py>(py: Python<'py>, pts: &[[f32; 2]]) -> Bound<'py, PyArray2<f32>> {
    let flat: Vec<f32> = pts.iter().flatten().copied().collect();
    ndarray::Array2::from_shape_vec((pts.len(), 2), flat)
        .expect("M x 2")
        .into_pyarray(py)
}

/// (M, 2) float32 points and their (M,) int64 identities.
type Identified<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<i64>>);

/// [`Identified`] from the core's points and identities.
fn identified<'py>(py: Python<'py>, (pts, ids): (&[[f32; 2]], &[i64])) -> Identified<'py> {
    (f32_rows(py, pts), ids.to_vec().into_pyarray(py))
}

/// See `facemime.track.motion.HeadMotion` for the documented API.
#[pyclass(module = "facemime._core")]
pub struct HeadFollower {
    head: head::HeadFollower,
}

#[pymethods]
impl HeadFollower {
    /// frame: the first frame, (H, W) grey or (H, W, 3) RGB uint8; brows: (N, 2) its brow
    /// points; zones: (Z, 4, 2) its rigid zones; window, max_level, guided_levels, limit,
    /// min_points, rounds, iterations, epsilon, min_eigen: see
    /// `facemime_core::head::FollowSettings` and `facemime_core::flow::LkParams`.
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (frame, brows, zones, window, max_level, guided_levels, limit, min_points, rounds, iterations, epsilon, min_eigen))]
    fn new(
        frame: PyReadonlyArrayDyn<u8>,
        brows: PyReadonlyArray2<f64>,
        zones: PyReadonlyArray3<f64>,
        window: usize,
        max_level: usize,
        guided_levels: usize,
        limit: f64,
        min_points: usize,
        rounds: usize,
        iterations: usize,
        epsilon: f64,
        min_eigen: f64,
    ) -> PyResult<Self> {
        let frame = image_view("frame", &frame)?;
        let z = zones.as_array();
        if z.shape()[1..] != [4, 2] {
            return Err(invalid(format!(
                "zones must have shape (Z, 4, 2), got {:?}",
                z.shape()
            )));
        }
        let zones: Vec<Quad> = z
            .outer_iter()
            .map(|c| std::array::from_fn(|k| [c[[k, 0]], c[[k, 1]]]))
            .collect();
        let settings = FollowSettings {
            window,
            max_level,
            guided_levels,
            limit,
            min_points,
            rounds,
            lk: LkParams {
                iterations,
                epsilon,
                min_eigen,
            },
        };
        let brows = rows::<2, _>("brows", &brows)?;
        let head = head::HeadFollower::new(&frame, brows, zones, settings).map_err(CoreErr)?;
        Ok(Self { head })
    }

    /// frame: the next frame, (H, W) grey or (H, W, 3) RGB uint8; brows: (N, 2) the previous
    /// frame's brow points; extra: (E, 2) other points of the previous frame. Returns (the
    /// head's 2×3 similarity step or None, the extra points' (E, 2) positions, NaN where the
    /// flow failed).
    fn follow<'py>(
        &mut self,
        py: Python<'py>,
        frame: PyReadonlyArrayDyn<u8>,
        brows: PyReadonlyArray2<f64>,
        extra: PyReadonlyArray2<f64>,
    ) -> PyResult<Step<'py>> {
        let frame = image_view("frame", &frame)?;
        let (brows, extra) = (
            rows::<2, _>("brows", &brows)?,
            rows::<2, _>("extra", &extra)?,
        );
        let head = &mut self.head;
        let got = py
            .detach(|| head.follow(&frame, &brows, &extra))
            .map_err(CoreErr)?;
        Ok((
            got.similarity.map(|m| array(py, &m)),
            point_rows(py, &got.extra),
        ))
    }

    /// step: the head's 2×3 similarity from the previous frame. Returns whether new points
    /// are wanted.
    fn advance(&mut self, step: PyReadonlyArray2<f64>) -> PyResult<bool> {
        Ok(self.head.advance(&matrix::<3>("step", &step)?))
    }

    /// (M, 2) float32 corners (frame pixels) of the current frame in the box `area` = (x0, y0,
    /// x1, y1), exclusive ends, where the (y1 − y0, x1 − x0) uint8 `mask` is nonzero, as
    /// OpenCV's goodFeaturesToTrack finds them on its grey levels; see
    /// `facemime_core::head::HeadFollower::corners`.
    #[pyo3(signature = (area, mask, max_corners, quality, min_distance, block))]
    #[allow(clippy::too_many_arguments)]
    fn corners<'py>(
        &self,
        py: Python<'py>,
        area: [usize; 4],
        mask: PyReadonlyArray2<'py, u8>,
        max_corners: usize,
        quality: f64,
        min_distance: f64,
        block: usize,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let m = mask
            .as_slice()
            .map_err(|_| invalid("mask must be a C-contiguous uint8 array"))?;
        let settings = CornerSettings {
            max_corners,
            quality,
            min_distance,
            block,
        };
        let head = &self.head;
        let found = py
            .detach(|| head.corners(area, m, &settings))
            .map_err(CoreErr)?;
        Ok(f32_rows(py, &found))
    }

    /// points: (M, 2) float32, new corners replacing the rigid points (new identities; the
    /// first frame's set how few call for new ones).
    fn detected(&mut self, points: PyReadonlyArray2<f32>) -> PyResult<()> {
        self.head.detected(rows::<2, _>("points", &points)?);
        Ok(())
    }

    /// Drops every rigid point.
    fn drop_points(&mut self) {
        self.head.drop_points();
    }

    /// (Z, 4, 2) float64: the rigid zones now.
    #[getter]
    fn zones<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let z = self.head.zones();
        let flat: Vec<f64> = z.iter().flatten().flatten().copied().collect();
        ndarray::Array3::from_shape_vec((z.len(), 4, 2), flat)
            .expect("Z x 4 x 2")
            .into_pyarray(py)
    }

    /// ((M, 2) float32, (M,) int64): the rigid points now and their identities.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Identified<'py> {
        identified(py, self.head.points())
    }

    /// ((M, 2) float32, (M,) int64): the points followed from the previous frame.
    #[getter]
    fn followed<'py>(&self, py: Python<'py>) -> Identified<'py> {
        identified(py, self.head.followed())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<HeadFollower>()?;
    Ok(())
}
