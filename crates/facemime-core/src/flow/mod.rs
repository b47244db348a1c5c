//! Pyramidal Lucas-Kanade optical flow: Bouguet's iterative formulation, the algorithm of
//! OpenCV's `calcOpticalFlowPyrLK` (same window, Scharr derivatives, stopping rules and
//! minimum-eigenvalue test), over pyramids built once per frame. A frame's pyramid serves the
//! forward flow into it, the backward flow out of it and the next frame's flow, where OpenCV
//! builds two pyramids per call.
//!
//! Coordinates are (x, y) pixels of the whole frame, pixel centres on integers. A pyramid
//! covers a crop of the frame whose top-left pixel is `origin`; level L holds the crop at
//! 1/2^L scale, level-L pixel i lying on level-0 pixel 2^L·i, so a frame point p is at
//! (p − origin)/2^L on level L. Intensities are grey levels (0..=255).

mod kernels;

use crate::border::reflect101;
use crate::error::Result;
use crate::invalid;
use kernels::{Grid, Shape};

/// One level's image, padded by `pad` mirrored pixels on every side.
#[derive(Default)]
struct Level {
    width: usize,
    height: usize,
    pad: usize,
    img: Vec<f32>,
}

impl Level {
    fn stride(&self) -> usize {
        self.width + 2 * self.pad
    }

    /// Resizes to `width`×`height` inside `pad`, keeping the allocation; the caller fills the
    /// interior (see [`Level::interior_row`]) and then calls [`Level::mirror`].
    fn reshape(&mut self, width: usize, height: usize, pad: usize) {
        (self.width, self.height, self.pad) = (width, height, pad);
        let n = self.stride() * (height + 2 * pad);
        self.img.resize(n, 0.0);
    }

    /// Interior row `y` (`width` values).
    fn interior_row(&mut self, y: usize) -> &mut [f32] {
        let (s, p, w) = (self.stride(), self.pad, self.width);
        &mut self.img[(y + p) * s + p..][..w]
    }

    /// Fills the padding by mirroring the interior (OpenCV's BORDER_REFLECT_101).
    fn mirror(&mut self) {
        let (s, p, w, h) = (self.stride(), self.pad, self.width, self.height);
        for y in p..p + h {
            let row = &mut self.img[y * s..][..s];
            if p < w {
                // One reflection reaches: the common case, without index arithmetic.
                for x in 0..p {
                    row[x] = row[2 * p - x];
                    row[p + w + x] = row[p + w - 2 - x];
                }
                continue;
            }
            for x in 0..p {
                row[x] = row[p + reflect101(x as isize - p as isize, w)];
                row[p + w + x] = row[p + reflect101((w + x) as isize, w)];
            }
        }
        for y in (0..p).chain(p + h..h + 2 * p) {
            let from = p + reflect101(y as isize - p as isize, h);
            self.img.copy_within(from * s..(from + 1) * s, y * s);
        }
    }

    /// Writes into `next` (already shaped ((width + 1)/2)×((height + 1)/2)) the binomial 5×5
    /// blur of this level sampled at even pixels (pyrDown); `col` is scratch.
    fn down(&self, next: &mut Level, col: &mut Vec<f32>) {
        let (s, p) = (self.stride(), self.pad);
        col.resize(s, 0.0);
        for y in 0..next.height {
            let rows: [&[f32]; 5] =
                std::array::from_fn(|j| &self.img[(2 * y + j + p - 2) * s..][..s]);
            for (x, c) in col.iter_mut().enumerate() {
                *c = rows[0][x] + rows[4][x] + 4.0 * (rows[1][x] + rows[3][x]) + 6.0 * rows[2][x];
            }
            for (x, o) in next.interior_row(y).iter_mut().enumerate() {
                let t = &col[2 * x + p - 2..][..5];
                *o = (t[0] + t[4] + 4.0 * (t[1] + t[3]) + 6.0 * t[2]) / 256.0;
            }
        }
    }

    /// The bilinear samples of this level on the unit grid whose top-left sample is the level
    /// point (x, y); the grid must fit in the padded plane (see [`Pyramid::inside`]).
    fn grid(&self, x: f32, y: f32) -> Grid<'_> {
        let (ix, iy) = (floor(x), floor(y));
        let (a, b) = (x - ix, y - iy);
        let p = self.pad as isize;
        let start = (iy as isize + p) as usize * self.stride() + (ix as isize + p) as usize;
        Grid {
            plane: &self.img,
            start,
            stride: self.stride(),
            wx: [1.0 - a, a],
            wy: [1.0 - b, b],
        }
    }
}

/// The Gaussian pyramid of one frame's crop, for a fixed window size. Rebuilding it for
/// another frame reuses its memory.
pub struct Pyramid {
    origin: [f64; 2],
    window: usize,
    depth: usize,
    levels: Vec<Level>,
    scratch: Vec<f32>,
}

impl Pyramid {
    /// An empty pyramid for the odd `window` side (pixels) of the Lucas-Kanade window.
    pub fn new(window: usize) -> Result<Self> {
        if window < 3 || window.is_multiple_of(2) {
            return invalid!("the window must be odd and at least 3 pixels, got {window}");
        }
        Ok(Self {
            origin: [0.0; 2],
            window,
            depth: 0,
            levels: Vec::new(),
            scratch: Vec::new(),
        })
    }

    /// [`Pyramid::new`] then [`Pyramid::rebuild`].
    pub fn build(
        gray: &[u8],
        width: usize,
        height: usize,
        crop: [usize; 4],
        max_level: usize,
        window: usize,
    ) -> Result<Self> {
        let mut p = Self::new(window)?;
        p.rebuild(gray, width, height, crop, max_level)?;
        Ok(p)
    }

    /// Builds the pyramid of the crop `[x0, x1)×[y0, y1)` of a row-major `width`×`height` grey
    /// image, with at most `max_level` levels above the crop itself. Like OpenCV, it stops
    /// before a level whose width or height would not exceed the window.
    pub fn rebuild(
        &mut self,
        gray: &[u8],
        width: usize,
        height: usize,
        crop: [usize; 4],
        max_level: usize,
    ) -> Result<()> {
        let [x0, y0, x1, y1] = crop;
        if gray.len() != width * height {
            return invalid!("the image has {} pixels, not {width}×{height}", gray.len());
        }
        if x0 >= x1 || y0 >= y1 || x1 > width || y1 > height {
            return invalid!("crop {crop:?} is empty or outside the {width}×{height} image");
        }
        let window = self.window;
        let pad = Shape::new(window).pad();
        let (mut w, mut h) = (x1 - x0, y1 - y0);
        let mut sizes = vec![(w, h)];
        while sizes.len() <= max_level && w.div_ceil(2) > window && h.div_ceil(2) > window {
            (w, h) = (w.div_ceil(2), h.div_ceil(2));
            sizes.push((w, h));
        }
        if self.levels.len() < sizes.len() {
            self.levels.resize_with(sizes.len(), Level::default);
        }
        for (level, &(w, h)) in self.levels.iter_mut().zip(&sizes) {
            level.reshape(w, h, pad);
        }
        let base = &mut self.levels[0];
        for y in 0..y1 - y0 {
            let src = &gray[(y0 + y) * width + x0..][..x1 - x0];
            base.interior_row(y)
                .iter_mut()
                .zip(src)
                .for_each(|(d, &g)| *d = g as f32);
        }
        base.mirror();
        for l in 1..sizes.len() {
            let (done, rest) = self.levels.split_at_mut(l);
            done[l - 1].down(&mut rest[0], &mut self.scratch);
            rest[0].mirror();
        }
        self.origin = [x0 as f64, y0 as f64];
        self.depth = sizes.len();
        Ok(())
    }

    /// Number of levels above the crop itself (0 also before the first build).
    pub fn max_level(&self) -> usize {
        self.depth.saturating_sub(1)
    }

    /// Whether a window with top-left level point `corner` may be sampled on `level` (OpenCV's
    /// test: the corner's integer part in [−window, size)).
    fn inside(&self, level: usize, corner: [f32; 2]) -> bool {
        let l = &self.levels[level];
        let lo = -(self.window as f32);
        let (x, y) = (floor(corner[0]), floor(corner[1]));
        x >= lo && y >= lo && x < l.width as f32 && y < l.height as f32
    }

    /// Frame point → level point.
    fn to_level(&self, p: [f64; 2], level: usize) -> [f64; 2] {
        let s = (1u64 << level) as f64;
        [(p[0] - self.origin[0]) / s, (p[1] - self.origin[1]) / s]
    }

    /// Level point → frame point.
    fn to_frame(&self, q: [f64; 2], level: usize) -> [f64; 2] {
        let s = (1u64 << level) as f64;
        [q[0] * s + self.origin[0], q[1] * s + self.origin[1]]
    }
}

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
    live: Vec<f32>,
    ext: Vec<f32>,
    gx: Vec<f32>,
    gy: Vec<f32>,
}

impl Windows {
    fn new(win: usize) -> Self {
        let shape = Shape::new(win);
        let mut live = vec![1.0 / 32.0; shape.cols];
        live[win..].fill(0.0);
        Self {
            shape,
            live,
            ext: vec![0.0; (win + 2) * shape.ecols],
            gx: vec![0.0; win * shape.cols],
            gy: vec![0.0; win * shape.cols],
        }
    }
}

/// Follows `points` (frame pixels, in `prev`'s frame) into `next`'s frame. Returns, per point,
/// its position there, or `None` where the flow failed (left the pyramid, too little texture,
/// non-finite input). Both pyramids must have the same window; the shallower one sets the
/// number of levels.
pub fn lucas_kanade(
    prev: &Pyramid,
    next: &Pyramid,
    points: &[[f64; 2]],
    params: &LkParams,
) -> Result<Vec<Option<[f64; 2]>>> {
    lucas_kanade_from(prev, next, points, points, usize::MAX, params)
}

/// [`lucas_kanade`] from a first estimate per point, `guesses` (frame pixels in `next`'s frame,
/// as many as `points`), through levels `top`..=0 at most: a good guess needs fewer levels,
/// each of which costs as much as the frame's own.
pub fn lucas_kanade_from(
    prev: &Pyramid,
    next: &Pyramid,
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
    let mut bufs = Windows::new(prev.window);
    let top = prev.max_level().min(next.max_level()).min(top);
    let follow = |(&p, &g): (&[f64; 2], &[f64; 2])| {
        if !(p[0].is_finite() && p[1].is_finite() && g[0].is_finite() && g[1].is_finite()) {
            return None;
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
        ok.then_some(guess)
    };
    Ok(points.iter().zip(guesses).map(follow).collect())
}

/// One level of the flow of frame point `p` from its current estimate `guess` (frame pixels).
/// Returns the refined estimate, or `None` where OpenCV would refuse the point on this level.
fn track_level(
    prev: &Pyramid,
    next: &Pyramid,
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
    let (lp, ln) = (&prev.levels[level], &next.levels[level]);
    // The window's image grown by one pixel, its derivatives, gradient matrix and image
    // against its derivatives.
    kernels::sample(
        &s,
        &lp.grid(c0[0] - 1.0, c0[1] - 1.0),
        win + 2,
        &mut bufs.ext,
    );
    let [a11, a12, a22, i1, i2] =
        kernels::gradients(&s, &bufs.ext, &bufs.live, &mut bufs.gx, &mut bufs.gy);
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
        let [j1, j2] = kernels::correlate(&s, &ln.grid(c1[0], c1[1]), &bufs.gx, &bufs.gy);
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

    pub(crate) fn pyramid(img: &[u8], w: usize, h: usize) -> Pyramid {
        Pyramid::build(img, w, h, [0, 0, w, h], 5, 21).unwrap()
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
        let crop = Pyramid::build(&img, 320, 240, [10, 20, 40, 50], 5, 21).unwrap();
        assert_eq!(crop.max_level(), 0);
    }

    #[test]
    fn recovers_a_known_shift_at_every_scale_of_motion() {
        let (w, h) = (320, 240);
        let a = pyramid(&texture(w, h, 0.0, 0.0), w, h);
        for (dx, dy) in [(0.3, -0.2), (2.5, 1.25), (-7.75, 4.5), (18.0, -11.0)] {
            let b = pyramid(&texture(w, h, dx, dy), w, h);
            let pts = [[160.0, 120.0], [100.5, 80.25], [220.0, 150.0]];
            let moved = lucas_kanade(&a, &b, &pts, &PARAMS).unwrap();
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
            &pyramid(&ia, w, h),
            &pyramid(&ib, w, h),
            &[[150.0, 110.0]],
            &PARAMS,
        );
        let a = Pyramid::build(&ia, w, h, [40, 8, 300, 230], 5, 21).unwrap();
        let b = Pyramid::build(&ib, w, h, [24, 16, 280, 220], 5, 21).unwrap();
        let cropped = lucas_kanade(&a, &b, &[[150.0, 110.0]], &PARAMS);
        let (m0, m1) = (whole.unwrap()[0].unwrap(), cropped.unwrap()[0].unwrap());
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
        let fresh = lucas_kanade(&pyramid(&ia, w, h), &pyramid(&ib, w, h), &pts, &PARAMS).unwrap();
        let mut a = Pyramid::build(&ib, w, h, [0, 0, w, h], 5, 21).unwrap();
        a.rebuild(&ia, w, h, [100, 50, 180, 120], 5).unwrap();
        assert_eq!(a.max_level(), 1);
        a.rebuild(&ia, w, h, [0, 0, w, h], 5).unwrap();
        let reused = lucas_kanade(&a, &pyramid(&ib, w, h), &pts, &PARAMS).unwrap();
        assert_eq!(fresh, reused);
    }

    #[test]
    fn refuses_flat_windows_points_outside_and_non_finite_points() {
        let (w, h) = (200, 160);
        let flat = vec![90u8; w * h];
        let f = pyramid(&flat, w, h);
        assert_eq!(
            lucas_kanade(&f, &f, &[[100.0, 80.0]], &PARAMS).unwrap(),
            [None]
        );
        let t = pyramid(&texture(w, h, 0.0, 0.0), w, h);
        let far = [[-100.0, 50.0], [50.0, 500.0], [f64::NAN, 3.0]];
        assert_eq!(
            lucas_kanade(&t, &t, &far, &PARAMS).unwrap(),
            [None, None, None]
        );
    }

    #[test]
    fn refuses_bad_arguments() {
        let img = texture(64, 48, 0.0, 0.0);
        assert!(Pyramid::build(&img, 64, 48, [0, 0, 64, 48], 3, 20).is_err());
        assert!(Pyramid::build(&img, 64, 48, [10, 0, 10, 48], 3, 21).is_err());
        assert!(Pyramid::build(&img, 64, 48, [0, 0, 65, 48], 3, 21).is_err());
        assert!(Pyramid::build(&img[1..], 64, 48, [0, 0, 64, 48], 3, 21).is_err());
        let a = Pyramid::build(&img, 64, 48, [0, 0, 64, 48], 3, 21).unwrap();
        let b = Pyramid::build(&img, 64, 48, [0, 0, 64, 48], 3, 11).unwrap();
        assert!(lucas_kanade(&a, &b, &[[30.0, 20.0]], &PARAMS).is_err());
        let empty = Pyramid::new(21).unwrap();
        assert!(lucas_kanade(&a, &empty, &[[30.0, 20.0]], &PARAMS).is_err());
    }
}
