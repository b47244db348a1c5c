//! One frame of the tracker's snakes: the image field built only where the knots' passes can
//! read it, then the solver's passes over it, the fastest-moving features getting more.
//!
//! Pixels: x right, y down, origin at the centre of the top-left pixel; boxes are
//! `[x0, y0, x1, y1)`, exclusive ends.

use std::time::{Duration, Instant};

use super::field::{Field, FIELD_CHANNELS};
use super::frame_field::{band_field, smoothing_radius};
use super::rest::mean_of;
use super::solver::{FrameInput, Problem, Solution};
use crate::error::Result;
use crate::extent::extent;
use crate::motion::{dot_after, dot_before, transformed};
use crate::raster::ImageRef;

/// Knots whose field is read `margin` pixels around them at most (the tracker's: their reach,
/// and two pixels for the bilinear cell of a point read and the rounding of the band's edges).
pub struct Band<'a> {
    pub knots: &'a [usize],
    pub margin: f64,
}

/// The solver passes after the first for some features: another pass follows while one of
/// `knots` moved at least `fast` pixels in the last, `passes` passes in all at most; a pass
/// solves the features of the curves flagged in `curves` and moves only `knots`.
pub struct MorePasses<'a> {
    pub knots: &'a [usize],
    pub curves: &'a [bool],
    pub passes: usize,
    pub fast: f64,
}

/// Wall time of a frame's two stages.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    pub field: Duration,
    pub solver: Duration,
}

/// The integer box around `points` grown by `margin` pixels, inside the `width`×`height`
/// image (from the floor of the smallest to one past the ceiling of the largest coordinate),
/// at least 4×4. `points` must not be empty.
pub fn region(points: &[[f64; 2]], margin: f64, width: usize, height: usize) -> [usize; 4] {
    let (lo, hi) = extent(points.iter().copied());
    let (w, h) = (width as i64, height as i64);
    let x0 = ((lo[0] - margin).floor() as i64).max(0).min(w - 4);
    let y0 = ((lo[1] - margin).floor() as i64).max(0).min(h - 4);
    let x1 = ((hi[0] + margin).ceil() as i64 + 1).min(w).max(x0 + 4);
    let y1 = ((hi[1] + margin).ceil() as i64 + 1).min(h).max(y0 + 4);
    [x0, y0, x1, y1].map(|v| v as usize)
}

/// Each band's [`region`] around its knots, where the field is computed, and the field's box:
/// the one holding those regions each grown by the radius of a smoothing of `sigma` pixels
/// ([`smoothing_radius`]), so that the smoothing of every pixel read stops short of the box's
/// mirrored edges (a field pixel then holds the same value whatever the box, see
/// [`super::frame_field`]).
pub fn band_regions(
    knots: &[[f64; 2]],
    bands: &[Band<'_>],
    width: usize,
    height: usize,
    sigma: f64,
) -> ([usize; 4], Vec<[usize; 4]>) {
    let grown = smoothing_radius(sigma) as f64;
    let mut boxes = Vec::with_capacity(bands.len());
    let mut all = [usize::MAX, usize::MAX, 0, 0];
    for band in bands {
        let pts: Vec<[f64; 2]> = band.knots.iter().map(|&i| knots[i]).collect();
        boxes.push(region(&pts, band.margin, width, height));
        let b = region(&pts, band.margin + grown, width, height);
        all = [
            all[0].min(b[0]),
            all[1].min(b[1]),
            all[2].max(b[2]),
            all[3].max(b[3]),
        ];
    }
    (all, boxes)
}

/// The knots' start, rest shape, the face's down direction, the pairs' target gaps and the
/// image size, as in [`FrameInput`].
pub struct Knots<'a> {
    pub start: &'a [[f64; 2]],
    pub rest: &'a [[f64; 2]],
    pub down: [f64; 2],
    pub pair_targets: &'a [f64],
    pub bounds: [usize; 2],
}

/// One frame's knots from `knots`' start: the field of `frame` (and `prev`, see
/// [`super::frame_field`]) smoothed by `smoothing` pixels in the `bands` around the start (the
/// solver reads only there), written into `buffer` (grown as needed and reused), a pass of the
/// solver over every curve, then `more`'s passes. Returns the solution (iterations added up;
/// each curve's response from the last pass that solved it) and the time of each stage.
#[allow(clippy::too_many_arguments)]
pub fn solve_frame(
    problem: &Problem,
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    smoothing: f64,
    bands: &[Band<'_>],
    more: &MorePasses<'_>,
    knots: &Knots<'_>,
    buffer: &mut Vec<f32>,
) -> Result<(Solution, FrameTimes)> {
    let t0 = Instant::now();
    let [width, height] = knots.bounds;
    let (b, boxes) = band_regions(knots.start, bands, width, height, smoothing);
    let (w, h) = (b[2] - b[0], b[3] - b[1]);
    let size = w * h * FIELD_CHANNELS;
    if buffer.len() < size {
        buffer.resize(size, 0.0);
    }
    let data = &mut buffer[..size];
    let colour: Vec<bool> = bands
        .iter()
        .map(|band| problem.reads_colour(band.knots))
        .collect();
    band_field(frame, prev, b, smoothing, (&boxes, &colour), data)?;
    let input = FrameInput {
        field: Field::new(data, w, h, [b[0] as f64, b[1] as f64])?,
        start: knots.start,
        rest: knots.rest,
        down: knots.down,
        pair_targets: knots.pair_targets,
        bounds: [width as f64, height as f64],
    };
    let t1 = Instant::now();
    let mut sol = problem.solve(&input)?;
    let mut before = input.start.to_vec();
    for _ in 1..more.passes {
        let moved = more.knots.iter().fold(0.0f64, |m, &i| {
            let (a, z) = (sol.knots[i], before[i]);
            m.max((a[0] - z[0]).abs()).max((a[1] - z[1]).abs())
        });
        if moved < more.fast {
            break;
        }
        before.copy_from_slice(&sol.knots);
        let again = problem.solve_some(
            &FrameInput {
                start: &before,
                ..input
            },
            more.curves,
            None,
        )?;
        for &i in more.knots {
            sol.knots[i] = again.knots[i];
        }
        for (c, _) in more.curves.iter().enumerate().filter(|(_, &on)| on) {
            sol.response[c] = again.response[c];
        }
        sol.iterations += again.iterations;
    }
    let times = FrameTimes {
        field: t1 - t0,
        solver: t1.elapsed(),
    };
    Ok((sol, times))
}

/// Slides the `inner` knots along `along` (a unit vector) by `amount` of their drift along it
/// from where they sat relative to the `outer` knots in the `rest` shape: the difference of
/// the two groups' mean knots, less that of their mean rest knots (in place; pixels).
pub(crate) fn centre_group(
    knots: &mut [[f64; 2]],
    rest: &[[f64; 2]],
    inner: &[usize],
    outer: &[usize],
    along: [f64; 2],
    amount: f64,
) {
    let (mi, mo) = (mean_of(knots, inner), mean_of(knots, outer));
    let (ri, ro) = (mean_of(rest, inner), mean_of(rest, outer));
    let drift = [
        (mi[0] - mo[0]) - (ri[0] - ro[0]),
        (mi[1] - mo[1]) - (ri[1] - ro[1]),
    ];
    let shift = amount * dot_after(drift[0], along[0], drift[1], along[1]);
    for &i in inner {
        knots[i] = [
            knots[i][0] - shift * along[0],
            knots[i][1] - shift * along[1],
        ];
    }
}

/// The knots' starting positions in a frame: where the head's `step` (a 2×3 similarity)
/// carries `knots`, or where the optical flow put them (`flow`, NaN where it failed). Returns
/// them and which came from the flow.
pub(crate) fn start_knots(
    step: &[[f64; 3]; 2],
    knots: &[[f64; 2]],
    flow: &[[f64; 2]],
) -> (Vec<[f64; 2]>, Vec<bool>) {
    let mut start = transformed(step, knots);
    let followed: Vec<bool> = flow.iter().map(|f| f[0].is_finite()).collect();
    for ((s, f), _) in start
        .iter_mut()
        .zip(flow)
        .zip(&followed)
        .filter(|(_, &ok)| ok)
    {
        *s = *f;
    }
    (start, followed)
}

/// Per (first, last) knot pair of `ends`: whether the chord between them in `knots` is at
/// least `least` times and at most twice its length in `rest`.
pub(crate) fn chords_within(
    knots: &[[f64; 2]],
    rest: &[[f64; 2]],
    ends: &[[usize; 2]],
    least: &[f64],
) -> Vec<bool> {
    let chord = |pts: &[[f64; 2]], [a, b]: [usize; 2]| {
        let d = [pts[b][0] - pts[a][0], pts[b][1] - pts[a][1]];
        (d[0] * d[0] + d[1] * d[1]).sqrt()
    };
    ends.iter()
        .zip(least)
        .map(|(&e, &lo)| {
            let (c, r) = (chord(knots, e), chord(rest, e));
            lo * r <= c && c <= 2.0 * r
        })
        .collect()
}

/// The knots as reported: each moved back by its `offset` (pixels) turned and scaled by
/// `linear` (the head's 2×2 part), then, where a `lower` knot lies above its `upper` one along
/// `down` (a unit vector), both put at their midpoint, so that those curves never cross.
pub fn reported_knots(
    knots: &[[f64; 2]],
    offset: &[[f64; 2]],
    linear: [[f64; 2]; 2],
    down: [f64; 2],
    upper: &[usize],
    lower: &[usize],
) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = knots
        .iter()
        .zip(offset)
        .map(|(k, o)| {
            std::array::from_fn(|j| k[j] - dot_after(o[0], linear[j][0], o[1], linear[j][1]))
        })
        .collect();
    for (&u, &l) in upper.iter().zip(lower) {
        let d = [out[l][0] - out[u][0], out[l][1] - out[u][1]];
        let gap = dot_before(d[0], down[0], d[1], down[1]);
        if gap < 0.0 {
            let shift = [0.5 * gap * down[0], 0.5 * gap * down[1]];
            out[u] = [out[u][0] + shift[0], out[u][1] + shift[1]];
            out[l] = [out[l][0] - shift[0], out[l][1] - shift[1]];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::energy::{CurveParams, Operator};
    use super::super::solver::Settings;
    use super::*;

    #[test]
    fn the_passes_read_the_field_only_inside_their_bands() {
        // Bright ground, a dark bar for a brow (rows 20..26) and one for the lips (70..78);
        // a brow curve 4 px above its bar's edge, a lip curve 6 px above its own, which gets
        // more passes while it moves.
        let (w, h) = (120, 100);
        let rgb: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let dark = ((20..26).contains(&y) && (25..95).contains(&x))
                    || ((70..78).contains(&y) && (35..85).contains(&x));
                let v = if dark { 60 } else { 200 } + ((x * 7 + y * 3) % 5) as u8;
                [v, v - 10, v]
            })
            .collect();
        let frame = ImageRef::new(&rgb, w, h, 3).unwrap();
        let line = |x0: f64, y: f64| (0..5).map(move |k| [x0 + 12.0 * k as f64, y]);
        let start: Vec<[f64; 2]> = line(30.0, 16.0).chain(line(36.0, 64.0)).collect();
        let params = CurveParams {
            alpha: 1.0,
            beta: 1.0,
            tau: 0.1,
            rho: 1.0,
            gamma: 0.0,
            luma: -1.0,
            chroma: 0.0,
            operator: Operator::Directional,
        };
        let settings = Settings {
            points_per_segment: 3,
            delta0: 2.0,
            sigma: 0.75,
            iterations: 15,
            tol: 0.0,
        };
        let (brow, lip): (Vec<usize>, Vec<usize>) = ((0..5).collect(), (5..10).collect());
        let curves = vec![(brow.clone(), params), (lip.clone(), params)];
        let problem = Problem::new(curves, vec![], 10, settings).unwrap();
        // The tracker's margins: its passes' reach and the cell's.
        let margin = |passes: f64| passes * 8.0 + 2.0;
        let bands = [
            Band {
                knots: &brow,
                margin: margin(1.0),
            },
            Band {
                knots: &lip,
                margin: margin(3.0),
            },
        ];
        let more = MorePasses {
            knots: &lip,
            curves: &[false, true],
            passes: 3,
            fast: 0.5,
        };
        let knots = Knots {
            start: &start,
            rest: &start,
            down: [0.0, 1.0],
            pair_targets: &[],
            bounds: [w, h],
        };
        let mut buffer = Vec::new();
        let (sol, _) = solve_frame(
            &problem,
            &frame,
            None,
            1.5,
            &bands,
            &more,
            &knots,
            &mut buffer,
        )
        .unwrap();
        // Outside the bands the field holds NaN in debug builds: a read there would show here.
        assert!(
            sol.response.iter().all(|r| r.is_finite()),
            "{:?}",
            sol.response
        );
        assert!(sol.knots.iter().flatten().all(|v| v.is_finite()));
        assert!(sol.iterations > 15, "the lips took more than one pass");
        assert!(
            lip.iter().all(|&i| (sol.knots[i][1] - 69.5).abs() < 1.5),
            "{:?}",
            sol.knots
        );
    }

    #[test]
    fn regions_cover_the_points_with_their_margin_inside_the_image() {
        let points = [[10.5, 50.0], [90.2, 61.7]];
        assert_eq!(region(&points, 5.0, 100, 80), [5, 45, 97, 68]);
        assert_eq!(region(&[[99.0, 79.0]], 0.0, 100, 80), [96, 76, 100, 80]);
        let knots = [[10.0, 10.0], [20.0, 12.0], [60.0, 40.0]];
        let bands = [
            Band {
                knots: &[0, 1],
                margin: 2.0,
            },
            Band {
                knots: &[2],
                margin: 1.0,
            },
        ];
        // σ = 0.25: a 3-tap Gaussian, radius 1.
        let (all, boxes) = band_regions(&knots, &bands, 100, 80, 0.25);
        assert_eq!(boxes, [[8, 8, 23, 15], [59, 39, 63, 43]], "at least 4×4");
        assert_eq!(all, [7, 7, 63, 43], "grown by the radius, inside the image");
    }

    #[test]
    fn a_group_that_drifted_sideways_is_slid_back_part_of_the_way() {
        let rest = [[0.0, 0.0], [10.0, 0.0], [4.0, 1.0], [6.0, 1.0]];
        // The inner pair drifted 2 px right and 1 px down relative to the outer pair.
        let mut knots = [[0.0, 0.0], [10.0, 0.0], [6.0, 2.0], [8.0, 2.0]];
        centre_group(&mut knots, &rest, &[2, 3], &[0, 1], [1.0, 0.0], 0.5);
        assert_eq!(knots, [[0.0, 0.0], [10.0, 0.0], [5.0, 2.0], [7.0, 2.0]]);
    }

    #[test]
    fn knots_start_where_the_flow_put_them_or_else_where_the_head_moved_them() {
        let step = [[0.0, -1.0, 10.0], [1.0, 0.0, 0.0]]; // a quarter turn, then 10 px right
        let knots = [[1.0, 2.0], [3.0, 4.0]];
        let (start, followed) = start_knots(&step, &knots, &[[f64::NAN; 2], [7.5, 8.5]]);
        assert_eq!(start, [[8.0, 1.0], [7.5, 8.5]]);
        assert_eq!(followed, [false, true]);
    }

    #[test]
    fn chords_may_shrink_to_their_least_and_grow_to_twice() {
        let rest = [[0.0, 0.0], [10.0, 0.0]];
        let ends = [[0, 1]; 3];
        let at = |x: f64| [[0.0, 0.0], [x, 0.0]];
        assert_eq!(
            chords_within(&at(5.0), &rest, &ends, &[0.5, 0.6, 0.25]),
            [true, false, true]
        );
        assert_eq!(chords_within(&at(20.0), &rest, &ends[..1], &[0.5]), [true]);
        assert_eq!(chords_within(&at(20.5), &rest, &ends[..1], &[0.5]), [false]);
    }

    #[test]
    fn reported_knots_take_out_the_turned_offset_and_never_cross() {
        let knots = [[0.0, 10.0], [0.0, 8.0], [5.0, 10.0], [5.0, 12.0]];
        let offset = [[1.0, 0.0]; 4];
        // Turned a quarter: each offset (1, 0) becomes (0, 1).
        let linear = [[0.0, -1.0], [1.0, 0.0]];
        let out = reported_knots(&knots, &offset, linear, [0.0, 1.0], &[0, 2], &[1, 3]);
        // The first pair crossed (lower 2 px above upper): both go to their midpoint.
        assert_eq!(out, [[0.0, 8.0], [0.0, 8.0], [5.0, 9.0], [5.0, 11.0]]);
    }
}
