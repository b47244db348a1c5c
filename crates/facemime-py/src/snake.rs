//! Bindings of `facemime_core::snake`: a `SnakeSolver` built once per tracker, solved per frame.

use facemime_core::snake::{
    self, Band, CurveParams, Field, FrameInput, FrameTimes, Knots, MorePasses, Operator, PairKind,
    PairSpec, Problem, Settings, FIELD_CHANNELS,
};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use std::sync::Mutex;

use crate::error::{invalid, CoreErr};
use crate::points::{array, image_view, matrix, rows, same_length};

/// Curves over one shared knot array solved jointly by sign descent (docs/method.md §1), as
/// `facemime.track.tracker.Tracker` builds and runs it; arrays follow its conventions.
#[pyclass(module = "facemime._core", frozen)]
pub struct SnakeSolver {
    problem: Problem,
    /// The image field's buffer for `track`, and the time its stages took in all.
    frames: Mutex<(Vec<f32>, FrameTimes)>,
}

/// Knot bands as (indices, margin) pairs from numpy, each with at least one knot and every
/// index below `n` knots.
fn bands_of<'a>(
    given: &'a [(PyReadonlyArray1<'_, usize>, f64)],
    n: usize,
) -> PyResult<Vec<Band<'a>>> {
    given
        .iter()
        .map(|(k, margin)| {
            let knots = k
                .as_slice()
                .map_err(|_| invalid("band knots must be a contiguous array"))?;
            if knots.is_empty() {
                return Err(invalid("a band needs at least one knot"));
            }
            within("bands", knots, n)?;
            Ok(Band {
                knots,
                margin: *margin,
            })
        })
        .collect()
}

/// An error unless every index is below `n` knots.
fn within(name: &str, idx: &[usize], n: usize) -> PyResult<()> {
    match idx.iter().find(|&&k| k >= n) {
        Some(k) => Err(invalid(format!(
            "{name}: knot index {k} is past the {n} knots"
        ))),
        None => Ok(()),
    }
}

/// An error unless the frame is at least 4×4 pixels.
fn frame_size(width: usize, height: usize) -> PyResult<()> {
    if width < 4 || height < 4 {
        return Err(invalid(format!(
            "the frame must be at least 4x4, got {width}x{height}"
        )));
    }
    Ok(())
}

/// A frame's knots (K, 2), the solver's iterations and each curve's response (C,).
type Tracked<'py> = (Bound<'py, PyArray2<f64>>, usize, Bound<'py, PyArray1<f64>>);

#[pymethods]
impl SnakeSolver {
    /// curve_knots: concatenated knot indices of all curves; curve_lengths: knots per curve;
    /// curve_params: (C, 8) alpha, beta, tau, rho, gamma, luma, chroma, operator (0 directional,
    /// 1 magnitude); pairs: (P, 2) knot indices (a, b); pair_params: (P, 2) kind (0 min gap,
    /// 1 keep), weight.
    #[new]
    #[pyo3(signature = (curve_knots, curve_lengths, curve_params, pairs, pair_params, points_per_segment, delta0, sigma, iterations, tol))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        curve_knots: PyReadonlyArray1<u32>,
        curve_lengths: PyReadonlyArray1<u32>,
        curve_params: PyReadonlyArray2<f64>,
        pairs: PyReadonlyArray2<u32>,
        pair_params: PyReadonlyArray2<f64>,
        points_per_segment: usize,
        delta0: f64,
        sigma: f64,
        iterations: usize,
        tol: f64,
    ) -> PyResult<Self> {
        let (ck, cl, cp) = (
            curve_knots.as_array(),
            curve_lengths.as_array(),
            curve_params.as_array(),
        );
        if cp.shape() != [cl.len(), 8] {
            return Err(invalid(format!(
                "curve_params must have shape ({}, 8), got {:?}",
                cl.len(),
                cp.shape()
            )));
        }
        if cl.iter().map(|&l| l as usize).sum::<usize>() != ck.len() {
            return Err(invalid(
                "curve_lengths must sum to the length of curve_knots",
            ));
        }
        let n_knots = ck.iter().map(|&i| i as usize + 1).max().unwrap_or(0);
        let mut curves = Vec::with_capacity(cl.len());
        let mut at = 0;
        for (c, &len) in cl.iter().enumerate() {
            let idx: Vec<usize> = ck
                .slice(ndarray::s![at..at + len as usize])
                .iter()
                .map(|&i| i as usize)
                .collect();
            at += len as usize;
            let r = cp.row(c);
            let operator = match r[7] {
                0.0 => Operator::Directional,
                1.0 => Operator::Magnitude,
                v => {
                    return Err(invalid(format!(
                        "curve {c} operator must be 0 or 1, got {v}"
                    )))
                }
            };
            let p = CurveParams {
                alpha: r[0],
                beta: r[1],
                tau: r[2],
                rho: r[3],
                gamma: r[4],
                luma: r[5],
                chroma: r[6],
                operator,
            };
            curves.push((idx, p));
        }
        let (pr, pp) = (pairs.as_array(), pair_params.as_array());
        if pr.ncols() != 2 || pp.shape() != [pr.nrows(), 2] {
            return Err(invalid(format!(
                "pairs must be (P, 2) and pair_params (P, 2), got {:?} and {:?}",
                pr.shape(),
                pp.shape()
            )));
        }
        let mut specs = Vec::with_capacity(pr.nrows());
        for k in 0..pr.nrows() {
            let kind = match pp[[k, 0]] {
                0.0 => PairKind::MinGap,
                1.0 => PairKind::Keep,
                v => return Err(invalid(format!("pair {k} kind must be 0 or 1, got {v}"))),
            };
            specs.push(PairSpec {
                a: pr[[k, 0]] as usize,
                b: pr[[k, 1]] as usize,
                kind,
                weight: pp[[k, 1]],
            });
        }
        let settings = Settings {
            points_per_segment,
            delta0,
            sigma,
            iterations,
            tol,
        };
        Ok(SnakeSolver {
            problem: Problem::new(curves, specs, n_knots, settings).map_err(CoreErr)?,
            frames: Mutex::new((Vec::new(), FrameTimes::default())),
        })
    }

    /// Number of knots in the shared knot array.
    #[getter]
    fn n_knots(&self) -> usize {
        self.problem.n_knots()
    }

    /// Solves one frame; returns (knots (K, 2), iterations, energy, response (C,)). With
    /// `curves`, a (C,) bool mask, only the features of the flagged curves are solved; with
    /// `held`, a (K,) bool mask, the flagged knots stay at the start (see
    /// `Problem::solve_some`).
    #[pyo3(signature = (field, origin, bounds, start, rest, down, pair_targets, curves=None, held=None))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        field: PyReadonlyArray3<f32>,
        origin: (f64, f64),
        bounds: (f64, f64),
        start: PyReadonlyArray2<f64>,
        rest: PyReadonlyArray2<f64>,
        down: (f64, f64),
        pair_targets: PyReadonlyArray1<f64>,
        curves: Option<PyReadonlyArray1<bool>>,
        held: Option<PyReadonlyArray1<bool>>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        usize,
        f64,
        Bound<'py, PyArray1<f64>>,
    )> {
        let frame = FrameArgs::new(&field, origin, bounds, &start, &rest, down, &pair_targets)?;
        let mask = match curves {
            Some(m) => m.as_array().to_vec(),
            None => vec![true; self.problem.n_curves()],
        };
        let held = held.map(|h| h.as_array().to_vec());
        let sol = py
            .detach(|| frame.run(|input| self.problem.solve_some(input, &mask, held.as_deref())))?;
        Ok((
            array(py, &sol.knots),
            sol.iterations,
            sol.energy,
            sol.response.into_pyarray(py),
        ))
    }

    /// One frame from `start`: the image field of `frame` (and `prev`, or None) smoothed by
    /// `smoothing` px in the `bands`, (knot indices (uintp), margin px) pairs, around `start`,
    /// built into a buffer the solver keeps; a solver pass; then passes of the features of the
    /// curves flagged in `mouth_curves` moving only `mouth_knots`, while one of them moved at
    /// least `fast` px in the last, `passes` in all at most. bounds: (width, height) of the
    /// frame. Returns (knots (K, 2), iterations, response (C,)), as `solve`.
    #[pyo3(signature = (frame, prev, start, rest, down, pair_targets, bounds, smoothing, bands, mouth_knots, mouth_curves, passes, fast))]
    #[allow(clippy::too_many_arguments)]
    fn track<'py>(
        &self,
        py: Python<'py>,
        frame: PyReadonlyArray3<u8>,
        prev: Option<PyReadonlyArray3<u8>>,
        start: PyReadonlyArray2<f64>,
        rest: PyReadonlyArray2<f64>,
        down: (f64, f64),
        pair_targets: PyReadonlyArray1<f64>,
        bounds: (usize, usize),
        smoothing: f64,
        bands: Vec<(PyReadonlyArray1<usize>, f64)>,
        mouth_knots: PyReadonlyArray1<usize>,
        mouth_curves: PyReadonlyArray1<bool>,
        passes: usize,
        fast: f64,
    ) -> PyResult<Tracked<'py>> {
        let img = image_view("frame", &frame)?;
        frame_size(bounds.0, bounds.1)?;
        let before = prev.as_ref().map(|p| image_view("prev", p)).transpose()?;
        let (start, rest) = (rows::<2, _>("start", &start)?, rows::<2, _>("rest", &rest)?);
        let n = self.problem.n_knots();
        if start.len() != n || rest.len() != n {
            return Err(invalid(format!(
                "start and rest must have {n} knots, got {} and {}",
                start.len(),
                rest.len()
            )));
        }
        let bands = bands_of(&bands, n)?;
        let mouth = mouth_knots
            .as_slice()
            .map_err(|_| invalid("mouth_knots must be a contiguous array"))?;
        within("mouth_knots", mouth, n)?;
        let curves = mouth_curves.as_array().to_vec();
        let more = MorePasses {
            knots: mouth,
            curves: &curves,
            passes,
            fast,
        };
        let knots = Knots {
            start: &start,
            rest: &rest,
            down: [down.0, down.1],
            pair_targets: pair_targets
                .as_slice()
                .map_err(|_| invalid("pair_targets must be a contiguous array"))?,
            bounds: [bounds.0, bounds.1],
        };
        // The buffer is locked with the GIL released: a second thread tracking on this solver
        // waits for it there, not while holding the GIL that the first needs back.
        let sol = py
            .detach(|| {
                let mut frames = self.frames.lock().expect("not poisoned");
                let (buffer, total) = &mut *frames;
                let (sol, times) = snake::solve_frame(
                    &self.problem,
                    &img,
                    before.as_ref(),
                    smoothing,
                    &bands,
                    &more,
                    &knots,
                    buffer,
                )?;
                total.field += times.field;
                total.solver += times.solver;
                Ok::<_, facemime_core::CoreError>(sol)
            })
            .map_err(CoreErr)?;
        Ok((
            array(py, &sol.knots),
            sol.iterations,
            sol.response.into_pyarray(py),
        ))
    }

    /// (image field, solver) seconds that `track` took in all, for benchmarks.
    #[getter]
    fn times(&self) -> (f64, f64) {
        let t = self.frames.lock().expect("not poisoned").1;
        (t.field.as_secs_f64(), t.solver.as_secs_f64())
    }

    /// Energy and each curve's mean H at `start`, without moving; returns (energy, response (C,)).
    #[pyo3(signature = (field, origin, bounds, start, rest, down, pair_targets))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        field: PyReadonlyArray3<f32>,
        origin: (f64, f64),
        bounds: (f64, f64),
        start: PyReadonlyArray2<f64>,
        rest: PyReadonlyArray2<f64>,
        down: (f64, f64),
        pair_targets: PyReadonlyArray1<f64>,
    ) -> PyResult<(f64, Bound<'py, PyArray1<f64>>)> {
        let frame = FrameArgs::new(&field, origin, bounds, &start, &rest, down, &pair_targets)?;
        let (e, response) = py.detach(|| frame.run(|input| self.problem.evaluate_start(input)))?;
        Ok((e, response.into_pyarray(py)))
    }
}

/// One frame's arguments converted from numpy, ready to build a `FrameInput`.
struct FrameArgs<'a> {
    data: &'a [f32],
    shape: Vec<usize>,
    origin: [f64; 2],
    bounds: [f64; 2],
    start: Vec<[f64; 2]>,
    rest: Vec<[f64; 2]>,
    down: [f64; 2],
    targets: Vec<f64>,
}

impl<'a> FrameArgs<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        field: &'a PyReadonlyArray3<'_, f32>,
        origin: (f64, f64),
        bounds: (f64, f64),
        start: &PyReadonlyArray2<f64>,
        rest: &PyReadonlyArray2<f64>,
        down: (f64, f64),
        pair_targets: &PyReadonlyArray1<f64>,
    ) -> PyResult<Self> {
        let shape = field.as_array().shape().to_vec();
        if shape[2] != FIELD_CHANNELS {
            return Err(invalid(format!(
                "field must have shape (H, W, {}), got {shape:?}",
                FIELD_CHANNELS
            )));
        }
        Ok(FrameArgs {
            data: field
                .as_slice()
                .map_err(|_| invalid("field must be a C-contiguous float32 array"))?,
            shape,
            origin: [origin.0, origin.1],
            bounds: [bounds.0, bounds.1],
            start: rows::<2, _>("start", start)?,
            rest: rows::<2, _>("rest", rest)?,
            down: [down.0, down.1],
            targets: pair_targets.as_array().to_vec(),
        })
    }

    fn run<T>(
        &self,
        f: impl FnOnce(&FrameInput<'_>) -> facemime_core::error::Result<T>,
    ) -> Result<T, CoreErr> {
        let field = Field::new(self.data, self.shape[1], self.shape[0], self.origin)?;
        let input = FrameInput {
            field,
            start: &self.start,
            rest: &self.rest,
            down: self.down,
            pair_targets: &self.targets,
            bounds: self.bounds,
        };
        Ok(f(&input)?)
    }
}

/// The (y1 − y0, x1 − x0, FIELD_CHANNELS) float32 field of `frame` over `region`
/// (x0, y0, x1, y1), only inside `bands` ((x0, y0, x1, y1) frame rectangles) when given; see
/// `facemime.track.field`. Written into `out` (a C-contiguous array of that shape, returned)
/// when given, else into a new array.
#[pyfunction]
#[pyo3(signature = (frame, prev, region, sigma, bands=None, out=None))]
fn frame_field<'py>(
    py: Python<'py>,
    frame: PyReadonlyArray3<u8>,
    prev: Option<PyReadonlyArray3<u8>>,
    region: [usize; 4],
    sigma: f64,
    bands: Option<Vec<[usize; 4]>>,
    out: Option<Bound<'py, PyArray3<f32>>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let img = image_view("frame", &frame)?;
    let before = prev.as_ref().map(|p| image_view("prev", p)).transpose()?;
    let shape = snake::field_shape(&img, before.as_ref(), region, sigma).map_err(CoreErr)?;
    let out = match out {
        Some(o) if o.shape() != shape => {
            return Err(invalid(format!(
                "out must have shape {shape:?}, got {:?}",
                o.shape()
            )))
        }
        Some(o) => o,
        None => PyArray3::zeros(py, shape, false),
    };
    {
        let mut buf = out.try_readwrite()?;
        let slice = buf
            .as_slice_mut()
            .map_err(|_| invalid("out must be a C-contiguous float32 array"))?;
        py.detach(|| {
            snake::frame_field(
                &img,
                before.as_ref(),
                region,
                sigma,
                bands.as_deref(),
                slice,
            )
        })
        .map_err(CoreErr)?;
    }
    Ok(out)
}

/// knots: (K, 2) pixels; bands: (knot indices (uintp), margin px) pairs; width, height: the
/// frame's; sigma: the field's smoothing (px). Returns (the field's box, each band's region):
/// integer boxes (x0, y0, x1, y1), exclusive ends, inside the frame, at least 4×4; a band's
/// region is around its knots grown by its margin, the box holds them all grown by the
/// smoothing's radius.
#[pyfunction]
fn field_regions(
    knots: PyReadonlyArray2<f64>,
    bands: Vec<(PyReadonlyArray1<usize>, f64)>,
    width: usize,
    height: usize,
    sigma: f64,
) -> PyResult<([usize; 4], Vec<[usize; 4]>)> {
    let knots = rows::<2, _>("knots", &knots)?;
    let bands = bands_of(&bands, knots.len())?;
    frame_size(width, height)?;
    snake::check_sigma(sigma).map_err(CoreErr)?;
    Ok(snake::band_regions(&knots, &bands, width, height, sigma))
}

/// knots, offset: (K, 2) pixels; linear: the head's 2×2 linear part; down: unit vector;
/// upper, lower: knot indices (uintp) of two curves, pair by pair. Returns the (K, 2) knots
/// less their offsets turned by `linear`, each crossed pair (lower above upper along `down`)
/// put at its midpoint.
#[pyfunction]
fn reported_knots<'py>(
    py: Python<'py>,
    knots: PyReadonlyArray2<f64>,
    offset: PyReadonlyArray2<f64>,
    linear: PyReadonlyArray2<f64>,
    down: (f64, f64),
    upper: PyReadonlyArray1<usize>,
    lower: PyReadonlyArray1<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (knots, offset) = (
        rows::<2, _>("knots", &knots)?,
        rows::<2, _>("offset", &offset)?,
    );
    same_length(&[("knots", knots.len()), ("offset", offset.len())])?;
    let linear = matrix::<2>("linear", &linear)?;
    let (upper, lower) = (upper.as_array().to_vec(), lower.as_array().to_vec());
    if upper.len() != lower.len() {
        return Err(invalid("upper and lower must pair their knots"));
    }
    within("upper", &upper, knots.len())?;
    within("lower", &lower, knots.len())?;
    let out = snake::reported_knots(&knots, &offset, linear, [down.0, down.1], &upper, &lower);
    Ok(array(py, &out))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SnakeSolver>()?;
    m.add_function(wrap_pyfunction!(reported_knots, m)?)?;
    m.add_function(wrap_pyfunction!(field_regions, m)?)?;
    m.add_function(wrap_pyfunction!(frame_field, m)?)?;
    m.add("FIELD_CHANNELS", FIELD_CHANNELS)?;
    Ok(())
}
