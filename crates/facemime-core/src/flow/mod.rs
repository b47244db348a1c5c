//! Pyramidal Lucas-Kanade optical flow: Bouguet's iterative formulation, the algorithm of
//! OpenCV's `calcOpticalFlowPyrLK` (same window, Scharr derivatives, stopping rules and
//! minimum-eigenvalue test), over pyramids built once per frame. A frame's pyramid serves the
//! forward flow into it, the backward flow out of it and the next frame's flow, where OpenCV
//! builds two pyramids per call.
//!
//! Coordinates are (x, y) pixels of the whole frame, pixel centres on integers; the
//! [`Pyramid`]'s levels are described in its module. Intensities are grey levels (0..=255).

mod kernels;
mod pyramid;

use crate::error::Result;
use crate::invalid;
use kernels::Shape;
pub use pyramid::Pyramid;

/// `x.floor()`, without its libm call (baseline x86-64 has no rounding instruction) for the
/// values windows take; NaN and huge values go to libm.
#[inline]
fn floor(x: f32) -> f32 {
    if x.abs() < 1e9 {
        let t = x as i32 as f32; // truncation towards zero, exact here
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor()
    }
}

/// When the Lucas-Kanade iterations stop and which points are refused.
#[derive(Clone, Copy, Debug)]
pub struct LkParams {
    /// Iterations per level at most.
    pub iterations: usize,
    /// Stop once a step is shorter than this (level pixels).
    pub epsilon: f64,
    /// Refuse a point whose window's smaller gradient-matrix eigenvalue, divided by the window
    /// area, is below this ((grey levels / pixel)²). OpenCV's default 1e-4 is 0.1024 here.
    pub min_eigen: f64,
}

/// Window buffers of one point on one level (layout: [`Shape`]): the image samples of the
/// window grown by one pixel on every side, (win + 2) rows, and the derivatives on the window,
/// win rows, zero past the side.
struct Windows {
    shape: Shape,
    ext: Vec<f32>,
    gx: Vec<f32>,
    gy: Vec<f32>,
}

impl Windows {
    fn new(win: usize) -> Self {
        let shape = Shape::new(win);
        Self {
            shape,
            ext: vec![0.0; (win + 2) * shape.ecols],
            gx: vec![0.0; win * shape.cols],
            gy: vec![0.0; win * shape.cols],
        }
    }
}

/// Follows `points` (frame pixels, in `prev`'s frame) into `next`'s frame. Returns, per point,
/// its position there, or `None` where the flow failed (left the pyramid, too little texture,
/// non-finite input). Both pyramids must have the same window; the shallower one sets the
/// number of levels. The pyramids fill the samples of their own level that the windows read.
pub fn lucas_kanade(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    points: &[[f64; 2]],
    params: &LkParams,
) -> Result<Vec<Option<[f64; 2]>>> {
    lucas_kanade_from(prev, next, points, points, usize::MAX, params)
}

/// [`lucas_kanade`] from a first estimate per point, `guesses` (frame pixels in `next`'s frame,
/// as many as `points`), through levels `top`..=0 at most: a good guess needs fewer levels,
/// each of which costs as much as the frame's own.
pub fn lucas_kanade_from(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    points: &[[f64; 2]],
    guesses: &[[f64; 2]],
    top: usize,
    params: &LkParams,
) -> Result<Vec<Option<[f64; 2]>>> {
    if guesses.len() != points.len() {
        return invalid!("{} guesses for {} points", guesses.len(), points.len());
    }
    if prev.window != next.window {
        return invalid!(
            "the pyramids have different windows ({} and {})",
            prev.window,
            next.window
        );
    }
    if prev.depth == 0 || next.depth == 0 {
        return invalid!("the flow needs two built pyramids");
    }
    let mut bufs = WINDOWS
        .take()
        .filter(|b| b.shape.win == prev.window)
        .unwrap_or_else(|| Windows::new(prev.window));
    let top = prev.max_level().min(next.max_level()).min(top);
    let mut out = Vec::with_capacity(points.len());
    for (&p, &g) in points.iter().zip(guesses) {
        if !(p[0].is_finite() && p[1].is_finite() && g[0].is_finite() && g[1].is_finite()) {
            out.push(None);
            continue;
        }
        let mut guess = g;
        let mut ok = true;
        for level in (0..=top).rev() {
            match track_level(prev, next, level, p, guess, params, &mut bufs) {
                Some(g) => guess = g,
                None if level == 0 => ok = false,
                None => {}
            }
        }
        out.push(ok.then_some(guess));
    }
    WINDOWS.set(Some(bufs));
    Ok(out)
}

thread_local! {
    /// [`lucas_kanade_from`]'s window buffers, kept from one call to the next (a frame makes
    /// several); every value a window reads is written first, or is a dead column's 0.
    static WINDOWS: std::cell::Cell<Option<Windows>> = const { std::cell::Cell::new(None) };
}

/// One level of the flow of frame point `p` from its current estimate `guess` (frame pixels).
/// Returns the refined estimate, or `None` where OpenCV would refuse the point on this level.
fn track_level(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    level: usize,
    p: [f64; 2],
    guess: [f64; 2],
    params: &LkParams,
    bufs: &mut Windows,
) -> Option<[f64; 2]> {
    let s = bufs.shape;
    let win = s.win;
    let half = (win - 1) as f64 / 2.0;
    let corner = |q: [f64; 2]| [(q[0] - half) as f32, (q[1] - half) as f32];
    let c0 = corner(prev.to_level(p, level));
    if !prev.inside(level, c0) {
        return None;
    }
    // The window's image grown by one pixel, its derivatives, gradient matrix and image
    // against its derivatives.
    let grown = prev.grid(level, c0[0] - 1.0, c0[1] - 1.0, s.sampled_block(win + 2));
    kernels::sample(&s, &grown, win + 2, &mut bufs.ext);
    let [a11, a12, a22, i1, i2] = kernels::gradients(&s, &bufs.ext, &mut bufs.gx, &mut bufs.gy);
    let det = a11 * a22 - a12 * a12;
    let min_eigen =
        (a11 + a22 - ((a11 - a22).powi(2) + 4.0 * a12 * a12).sqrt()) / (2.0 * (win * win) as f64);
    // OpenCV's singularity test, det < FLT_EPSILON in its units of (32·gradient)²/2^20.
    if min_eigen < params.min_eigen || det < f32::EPSILON as f64 * 1024.0 * 1024.0 {
        return None;
    }
    let mut q = next.to_level(guess, level);
    let mut last = [0.0f64; 2];
    for it in 0..params.iterations {
        let c1 = corner(q);
        if !next.inside(level, c1) {
            return None;
        }
        // The mismatch Σ(J − I)·∇I, J the next level's samples at the estimate.
        let at = next.grid(level, c1[0], c1[1], s.correlated_block());
        let [j1, j2] = kernels::correlate(&s, &at, &bufs.gx, &bufs.gy);
        let (b1, b2) = (j1 - i1, j2 - i2);
        let step = [(a12 * b2 - a22 * b1) / det, (a12 * b1 - a11 * b2) / det];
        q = [q[0] + step[0], q[1] + step[1]];
        if step[0] * step[0] + step[1] * step[1] <= params.epsilon * params.epsilon {
            break;
        }
        // Oscillating between two positions: settle half-way.
        if it > 0 && (step[0] + last[0]).abs() < 0.01 && (step[1] + last[1]).abs() < 0.01 {
            q = [q[0] - step[0] / 2.0, q[1] - step[1] / 2.0];
            break;
        }
        last = step;
    }
    Some(next.to_frame(q, level))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::raster::ImageRef;

    pub(crate) const PARAMS: LkParams = LkParams {
        iterations: 30,
        epsilon: 0.01,
        min_eigen: 0.1024,
    };

    /// A smooth, textured w×h image (blobs of several sizes) shifted by (dx, dy) pixels.
    pub(crate) fn texture(w: usize, h: usize, dx: f64, dy: f64) -> Vec<u8> {
        let mut out = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let (u, v) = (x as f64 - dx, y as f64 - dy);
                let g = 128.0
                    + 50.0 * (u / 7.0).sin() * (v / 9.0).cos()
                    + 40.0 * ((u + 2.0 * v) / 23.0).sin()
                    + 30.0 * ((u - v) / 41.0).cos();
                out.push(g.round().clamp(0.0, 255.0) as u8);
            }
        }
        out
    }

    /// A w×h grey image.
    pub(crate) fn gray(img: &[u8], w: usize, h: usize) -> ImageRef<'_> {
        ImageRef::named("frame", img, w, h, 1).unwrap()
    }

    /// The pyramid of a w×h grey image's `crop`.
    pub(crate) fn cropped(img: &[u8], w: usize, h: usize, crop: [usize; 4]) -> Pyramid {
        Pyramid::build(&gray(img, w, h), crop, 5, 21).unwrap()
    }

    pub(crate) fn pyramid(img: &[u8], w: usize, h: usize) -> Pyramid {
        cropped(img, w, h, [0, 0, w, h])
    }

    #[test]
    fn floor_matches_libm() {
        for x in [
            -21.0f32,
            -20.5,
            -1.0,
            -0.75,
            -0.0,
            0.0,
            0.25,
            1.0,
            3.999_999_8,
            1e8,
            -1e8,
            2e9,
        ] {
            assert_eq!(floor(x), x.floor(), "floor({x})");
        }
        assert!(floor(f32::NAN).is_nan());
    }

    #[test]
    fn levels_stop_before_the_window() {
        let img = texture(320, 240, 0.0, 0.0);
        // 240 → 120 → 60 → 30 (> 21) → 15 (≤ 21, not built): levels 0..=3.
        assert_eq!(pyramid(&img, 320, 240).max_level(), 3);
        assert_eq!(cropped(&img, 320, 240, [10, 20, 40, 50]).max_level(), 0);
    }

    #[test]
    fn recovers_a_known_shift_at_every_scale_of_motion() {
        let (w, h) = (320, 240);
        let mut a = pyramid(&texture(w, h, 0.0, 0.0), w, h);
        for (dx, dy) in [(0.3, -0.2), (2.5, 1.25), (-7.75, 4.5), (18.0, -11.0)] {
            let mut b = pyramid(&texture(w, h, dx, dy), w, h);
            let pts = [[160.0, 120.0], [100.5, 80.25], [220.0, 150.0]];
            let moved = lucas_kanade(&mut a, &mut b, &pts, &PARAMS).unwrap();
            for (p, m) in pts.iter().zip(moved) {
                let m = m.expect("tracked");
                assert!(
                    (m[0] - p[0] - dx).abs() < 0.1 && (m[1] - p[1] - dy).abs() < 0.1,
                    "shift ({dx}, {dy}): {p:?} -> {m:?}"
                );
            }
        }
    }

    #[test]
    fn crops_at_different_origins_agree_with_the_whole_frame() {
        let (w, h) = (320, 240);
        let (ia, ib) = (texture(w, h, 0.0, 0.0), texture(w, h, 3.0, -2.0));
        let whole = lucas_kanade(
            &mut pyramid(&ia, w, h),
            &mut pyramid(&ib, w, h),
            &[[150.0, 110.0]],
            &PARAMS,
        );
        let mut a = cropped(&ia, w, h, [40, 8, 300, 230]);
        let mut b = cropped(&ib, w, h, [24, 16, 280, 220]);
        let part = lucas_kanade(&mut a, &mut b, &[[150.0, 110.0]], &PARAMS);
        let (m0, m1) = (whole.unwrap()[0].unwrap(), part.unwrap()[0].unwrap());
        assert!(
            (m0[0] - 153.0).abs() < 0.1 && (m0[1] - 108.0).abs() < 0.1,
            "{m0:?}"
        );
        assert!(
            (m1[0] - m0[0]).abs() < 0.1 && (m1[1] - m0[1]).abs() < 0.1,
            "{m1:?}"
        );
    }

    #[test]
    fn a_rebuilt_pyramid_tracks_like_a_fresh_one() {
        let (w, h) = (320, 240);
        let (ia, ib) = (texture(w, h, 0.0, 0.0), texture(w, h, 1.5, 2.5));
        let pts = [[150.0, 110.0], [90.0, 70.0]];
        let (ga, gb) = (gray(&ia, w, h), gray(&ib, w, h));
        let fresh = lucas_kanade(
            &mut pyramid(&ia, w, h),
            &mut pyramid(&ib, w, h),
            &pts,
            &PARAMS,
        )
        .unwrap();
        let mut a = pyramid(&ib, w, h);
        let mut b = pyramid(&ib, w, h);
        lucas_kanade(&mut a, &mut b, &pts, &PARAMS).unwrap();
        a.rebuild(&ga, [100, 50, 180, 120], 5).unwrap();
        assert_eq!(a.max_level(), 1);
        a.rebuild(&ga, [0, 0, w, h], 5).unwrap();
        b.rebuild(&gb, [0, 0, w, h], 5).unwrap();
        let reused = lucas_kanade(&mut a, &mut b, &pts, &PARAMS).unwrap();
        assert_eq!(fresh, reused);
    }

    #[test]
    fn refuses_flat_windows_points_outside_and_non_finite_points() {
        let (w, h) = (200, 160);
        let flat = vec![90u8; w * h];
        let (mut f, mut g) = (pyramid(&flat, w, h), pyramid(&flat, w, h));
        assert_eq!(
            lucas_kanade(&mut f, &mut g, &[[100.0, 80.0]], &PARAMS).unwrap(),
            [None]
        );
        let img = texture(w, h, 0.0, 0.0);
        let (mut t, mut u) = (pyramid(&img, w, h), pyramid(&img, w, h));
        let far = [[-100.0, 50.0], [50.0, 500.0], [f64::NAN, 3.0]];
        assert_eq!(
            lucas_kanade(&mut t, &mut u, &far, &PARAMS).unwrap(),
            [None, None, None]
        );
    }

    #[test]
    fn refuses_bad_arguments() {
        let img = texture(64, 48, 0.0, 0.0);
        let g = gray(&img, 64, 48);
        assert!(Pyramid::build(&g, [0, 0, 64, 48], 3, 20).is_err());
        assert!(Pyramid::build(&g, [10, 0, 10, 48], 3, 21).is_err());
        assert!(Pyramid::build(&g, [0, 0, 65, 48], 3, 21).is_err());
        let two = ImageRef::named("frame", &img, 32, 48, 2).unwrap();
        assert!(Pyramid::build(&two, [0, 0, 32, 48], 3, 21).is_err());
        let mut a = Pyramid::build(&g, [0, 0, 64, 48], 3, 21).unwrap();
        let mut b = Pyramid::build(&g, [0, 0, 64, 48], 3, 11).unwrap();
        assert!(lucas_kanade(&mut a, &mut b, &[[30.0, 20.0]], &PARAMS).is_err());
        let mut empty = Pyramid::new(21).unwrap();
        assert!(lucas_kanade(&mut a, &mut empty, &[[30.0, 20.0]], &PARAMS).is_err());
    }
}
