//! Bindings of `facemime_core::snake::FramePlan`: a tracker frame's steps around its solver
//! passes, a call each.

use facemime_core::snake;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadwriteArray2,
};
use pyo3::prelude::*;

use crate::error::CoreErr;
use crate::points::{array, matrix, rows, same_length, write_rows};

/// (start (K, 2), followed (K,) or None, whether the mouth was followed too little, scale,
/// down (2,)).
type Begun<'py> = (
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray1<bool>>>,
    bool,
    f64,
    Bound<'py, PyArray1<f64>>,
);

/// (carried (K, 2), rest (K, 2), pair targets (P,)).
type Settled<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Each curve's confidence (C,) and each feature's.
type Confidences<'py> = (Bound<'py, PyArray1<f64>>, Vec<f64>);

/// Each curve's confidence (C,), each feature's, and each feature's shape check.
type Assessed<'py> = (Bound<'py, PyArray1<f64>>, Vec<f64>, Vec<bool>);

/// See `facemime.track.tracker.Tracker` (its frame steps) and
/// `facemime_core::snake::FramePlan` for the fields.
#[pyclass(module = "facemime._core", frozen)]
pub struct FramePlan {
    plan: snake::FramePlan,
}

impl FramePlan {
    /// The rows of a (K, 2) array of the plan's K knots; a clear error for another shape.
    fn knots(&self, name: &str, a: &PyReadonlyArray2<f64>) -> PyResult<Vec<[f64; 2]>> {
        let pts = rows::<2, _>(name, a)?;
        same_length(&[(name, pts.len()), ("knots0", self.plan.knots0.len())])?;
        Ok(pts)
    }

    /// A (C,) array of one edge response per curve of the plan.
    fn responses(&self, a: &PyReadonlyArray1<f64>) -> PyResult<Vec<f64>> {
        let r = a.as_array().to_vec();
        same_length(&[
            ("response", r.len()),
            ("response0", self.plan.response0.len()),
        ])?;
        Ok(r)
    }
}

#[pymethods]
impl FramePlan {
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        knots0: PyReadonlyArray2<f64>,
        down0: (f64, f64),
        targets0: PyReadonlyArray1<f64>,
        response0: PyReadonlyArray1<f64>,
        bounds: (f64, f64),
        mouth: PyReadonlyArray1<usize>,
        mouth_patch: f64,
        affine_groups: Vec<Vec<usize>>,
        mouth_affine: f64,
        inner: PyReadonlyArray1<usize>,
        outer: PyReadonlyArray1<usize>,
        centring: f64,
        chord_ends: PyReadonlyArray2<usize>,
        least_chord: PyReadonlyArray1<f64>,
        feature_curves: PyReadonlyArray2<usize>,
    ) -> PyResult<Self> {
        let plan = snake::FramePlan {
            knots0: rows::<2, _>("knots0", &knots0)?,
            down0: [down0.0, down0.1],
            targets0: targets0.as_array().to_vec(),
            response0: response0.as_array().to_vec(),
            bounds: [bounds.0, bounds.1],
            mouth: mouth.as_array().to_vec(),
            mouth_patch,
            affine_groups,
            mouth_affine,
            inner: inner.as_array().to_vec(),
            outer: outer.as_array().to_vec(),
            centring,
            chord_ends: rows::<2, _>("chord_ends", &chord_ends)?,
            least_chord: least_chord.as_array().to_vec(),
            feature_curves: rows::<2, _>("feature_curves", &feature_curves)?,
        };
        plan.check().map_err(CoreErr)?;
        Ok(Self { plan })
    }

    /// step, total: the head's 2×3 step from the previous frame and motion since the first;
    /// knots: (K, 2) the previous frame's; flow: (K, 2) where the flow put them (NaN where it
    /// failed) or None. Returns (start (K, 2), followed (K,) or None, whether the flow
    /// followed too few mouth knots, the head's scale, down (2,)).
    fn begin<'py>(
        &self,
        py: Python<'py>,
        step: PyReadonlyArray2<f64>,
        total: PyReadonlyArray2<f64>,
        knots: PyReadonlyArray2<f64>,
        flow: Option<PyReadonlyArray2<f64>>,
    ) -> PyResult<Begun<'py>> {
        let (step, total) = (matrix::<3>("step", &step)?, matrix::<3>("total", &total)?);
        let knots = self.knots("knots", &knots)?;
        let flow = flow.map(|f| rows::<2, _>("flow", &f)).transpose()?;
        if let Some(f) = &flow {
            same_length(&[("knots", knots.len()), ("flow", f.len())])?;
        }
        let b = self.plan.begin(&step, &total, &knots, flow.as_deref());
        Ok((
            array(py, &b.start),
            b.followed.map(|f| f.into_pyarray(py)),
            b.mouth_unfollowed,
            b.scale,
            b.down.to_vec().into_pyarray(py),
        ))
    }

    /// start: (K, 2), clipped to the frame in place; total: the head's 2×3 motion since the
    /// first frame; scale: its scale. Returns (carried, rest, pair targets).
    fn settle<'py>(
        &self,
        py: Python<'py>,
        mut start: PyReadwriteArray2<f64>,
        total: PyReadonlyArray2<f64>,
        scale: f64,
    ) -> PyResult<Settled<'py>> {
        let total = matrix::<3>("total", &total)?;
        let mut pts = self.knots("start", &start)?;
        let s = self.plan.settle(&mut pts, &total, scale);
        write_rows(&mut start, &pts);
        Ok((
            array(py, &s.carried),
            array(py, &s.rest),
            s.targets.into_pyarray(py),
        ))
    }

    /// carried, start: (K, 2). Returns the (K, 2) rest shape (`FramePlan::rest`).
    fn rest<'py>(
        &self,
        py: Python<'py>,
        carried: PyReadonlyArray2<f64>,
        start: PyReadonlyArray2<f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (carried, start) = (
            self.knots("carried", &carried)?,
            self.knots("start", &start)?,
        );
        Ok(array(py, &self.plan.rest(&carried, &start)))
    }

    /// knots: (K, 2), the inner mouth slid in place; rest: (K, 2); down: unit vector
    /// (`FramePlan::centre`).
    fn centre(
        &self,
        mut knots: PyReadwriteArray2<f64>,
        rest: PyReadonlyArray2<f64>,
        down: (f64, f64),
    ) -> PyResult<()> {
        let mut pts = self.knots("knots", &knots)?;
        let rest = self.knots("rest", &rest)?;
        self.plan.centre(&mut pts, &rest, [down.0, down.1]);
        write_rows(&mut knots, &pts);
        Ok(())
    }

    /// knots, rest: (K, 2). Returns each feature's shape check (`FramePlan::shapes`).
    fn shapes(
        &self,
        knots: PyReadonlyArray2<f64>,
        rest: PyReadonlyArray2<f64>,
    ) -> PyResult<Vec<bool>> {
        let (knots, rest) = (self.knots("knots", &knots)?, self.knots("rest", &rest)?);
        Ok(self.plan.shapes(&knots, &rest))
    }

    /// response: (C,) each curve's edge response. Returns (each curve's confidence (C,), each
    /// feature's).
    fn confidences<'py>(
        &self,
        py: Python<'py>,
        response: PyReadonlyArray1<f64>,
    ) -> PyResult<Confidences<'py>> {
        let response = self.responses(&response)?;
        let (ratio, confidence) = self.plan.confidences(&response);
        Ok((ratio.into_pyarray(py), confidence))
    }

    /// knots: (K, 2), the inner mouth slid back in place; rest, carried: (K, 2); down: unit
    /// vector; response: (C,). Returns (each curve's confidence (C,), each feature's, each
    /// feature's shape check).
    fn assess<'py>(
        &self,
        py: Python<'py>,
        mut knots: PyReadwriteArray2<f64>,
        rest: PyReadonlyArray2<f64>,
        down: (f64, f64),
        response: PyReadonlyArray1<f64>,
        carried: PyReadonlyArray2<f64>,
    ) -> PyResult<Assessed<'py>> {
        let mut pts = self.knots("knots", &knots)?;
        let (rest, carried) = (self.knots("rest", &rest)?, self.knots("carried", &carried)?);
        let response = self.responses(&response)?;
        let a = self
            .plan
            .assess(&mut pts, &rest, [down.0, down.1], &response, &carried);
        write_rows(&mut knots, &pts);
        Ok((a.ratio.into_pyarray(py), a.confidence, a.shape_ok))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FramePlan>()?;
    Ok(())
}
