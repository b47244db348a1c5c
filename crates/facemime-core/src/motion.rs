//! Robust 2D similarity fit between two point sets: the frame-to-frame head motion of the
//! tracker, fitted despite points that the optical flow lost or that moved with the face's
//! non-rigid parts.
//!
//! Points are (x, y) pixels. The similarity is written as complex numbers, z ↦ a·z + b with
//! z = x + iy; as a 2×3 matrix it is [[Re a, −Im a, Re b], [Im a, Re a, Im b]].

use crate::error::Result;
use crate::flow::{lucas_kanade_from, LkParams, Pyramid};
use crate::median::median;

/// Tukey's biweight constant (95 % efficiency on Gaussian residuals).
const TUKEY: f64 = 4.685;
/// Median absolute residual to the standard deviation of Gaussian residuals.
const MAD_SCALE: f64 = 1.4826;
/// The fit has converged when no point of the source moves more than this (pixels).
const CONVERGED: f64 = 1e-3;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn of(p: [f64; 2]) -> Self {
        Self { re: p[0], im: p[1] }
    }
    fn add(self, o: Self) -> Self {
        Self {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    fn sub(self, o: Self) -> Self {
        Self {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn mul(self, o: Self) -> Self {
        Self {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn scale(self, s: f64) -> Self {
        Self {
            re: self.re * s,
            im: self.im * s,
        }
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// The similarity (rotation, uniform scale, translation) that maps `src` onto `dst` (same
/// length) despite outliers, as a 2×3 matrix, and which points fit it (residual below `limit`
/// pixels).
///
/// Iteratively reweighted least squares with Tukey's biweight, at most `rounds` rounds, started
/// from the median displacement; the biweight's cut-off is 4.685 robust standard deviations of
/// the residuals but never below `limit / 2`. Deterministic. With no points it returns the
/// identity and no inliers.
pub fn robust_similarity(
    src: &[[f64; 2]],
    dst: &[[f64; 2]],
    limit: f64,
    rounds: usize,
) -> ([[f64; 3]; 2], Vec<bool>) {
    assert_eq!(
        src.len(),
        dst.len(),
        "src and dst must have the same length"
    );
    let zs: Vec<Complex> = src.iter().map(|&p| Complex::of(p)).collect();
    let zd: Vec<Complex> = dst.iter().map(|&p| Complex::of(p)).collect();
    if zs.is_empty() {
        return ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], Vec::new());
    }
    let reach = zs.iter().map(|z| z.abs()).fold(0.0, f64::max);
    let mut dx: Vec<f64> = zs.iter().zip(&zd).map(|(s, d)| d.re - s.re).collect();
    let mut dy: Vec<f64> = zs.iter().zip(&zd).map(|(s, d)| d.im - s.im).collect();
    let mut a = Complex { re: 1.0, im: 0.0 };
    let mut b = Complex {
        re: median(&mut dx),
        im: median(&mut dy),
    };
    let residuals = |a: Complex, b: Complex| -> Vec<f64> {
        zs.iter()
            .zip(&zd)
            .map(|(&s, &d)| a.mul(s).add(b).sub(d).abs())
            .collect()
    };
    let mut w = vec![0.0; zs.len()];
    for _ in 0..rounds {
        let r = residuals(a, b);
        let cut = TUKEY * (MAD_SCALE * median(&mut r.clone())).max(limit / 2.0);
        for (wk, rk) in w.iter_mut().zip(&r) {
            *wk = (1.0 - (rk / cut).powi(2)).max(0.0).powi(2);
        }
        if w.iter().filter(|&&wk| wk != 0.0).count() < 2 {
            break;
        }
        let total: f64 = w.iter().sum();
        let mean = |z: &[Complex]| {
            z.iter()
                .zip(&w)
                .fold(Complex { re: 0.0, im: 0.0 }, |acc, (zk, &wk)| {
                    acc.add(zk.scale(wk))
                })
                .scale(1.0 / total)
        };
        let (ms, md) = (mean(&zs), mean(&zd));
        let (mut num, mut den) = (Complex { re: 0.0, im: 0.0 }, 0.0);
        for ((s, d), &wk) in zs.iter().zip(&zd).zip(&w) {
            let (cs, cd) = (s.sub(ms), d.sub(md));
            // conj(cs) · cd
            num = num.add(
                Complex {
                    re: cs.re * cd.re + cs.im * cd.im,
                    im: cs.re * cd.im - cs.im * cd.re,
                }
                .scale(wk),
            );
            den += wk * (cs.re * cs.re + cs.im * cs.im);
        }
        let new_a = num.scale(1.0 / den.max(1e-12));
        let new_b = md.sub(new_a.mul(ms));
        let done = new_a.sub(a).abs() * reach + new_b.sub(b).abs() < CONVERGED;
        (a, b) = (new_a, new_b);
        if done {
            break;
        }
    }
    let inliers = residuals(a, b).iter().map(|&r| r < limit).collect();
    ([[a.re, -a.im, b.re], [a.im, a.re, b.im]], inliers)
}

/// One frame's step of [`follow_rigid`].
#[derive(Clone, Debug, PartialEq)]
pub struct RigidStep {
    /// The head's similarity from the previous frame to the current one; None when fewer than
    /// the minimum of points passed the forward-backward check or fit it.
    pub similarity: Option<[[f64; 3]; 2]>,
    /// With a similarity: the indices of the rigid points that fit it, and their positions in
    /// the current frame (the others are to be dropped); else empty.
    pub kept: Vec<usize>,
    pub moved: Vec<[f64; 2]>,
    /// Per extra point: its position in the current frame, None where the flow failed or its
    /// forward-backward check.
    pub extra: Vec<Option<[f64; 2]>>,
}

/// The 2×3 similarity `m` applied to `p`.
pub(crate) fn apply(m: &[[f64; 3]; 2], p: [f64; 2]) -> [f64; 2] {
    [
        m[0][0] * p[0] + m[0][1] * p[1] + m[0][2],
        m[1][0] * p[0] + m[1][1] * p[1] + m[1][2],
    ]
}

/// `x·m0 + y·m1` rounded as numpy's small matrix products round it here (one fused
/// multiply-add after the first product), so that the tracker's knots stay what they were
/// when these steps ran in numpy.
pub(crate) fn dot_after(x: f64, m0: f64, y: f64, m1: f64) -> f64 {
    y.mul_add(m1, x * m0)
}

/// `x·m0 + y·m1` rounded as numpy's small matrix-vector products round it here (one fused
/// multiply-add after the second product).
pub(crate) fn dot_before(x: f64, m0: f64, y: f64, m1: f64) -> f64 {
    x.mul_add(m0, y * m1)
}

/// The 2×3 transform `m` applied to each of `points` (pixels).
pub fn transformed(m: &[[f64; 3]; 2], points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    points
        .iter()
        .map(|p| std::array::from_fn(|j| dot_after(p[0], m[j][0], p[1], m[j][1]) + m[j][2]))
        .collect()
}

/// The 2×3 transform `a ∘ b` (`b` first). Each entry of the linear product is rounded as
/// numpy's matrix product rounds it (the second product fused with the sum of the first), so
/// that the tracker's accumulated head motion stays what it was when numpy composed it.
pub fn compose(a: &[[f64; 3]; 2], b: &[[f64; 3]; 2]) -> [[f64; 3]; 2] {
    std::array::from_fn(|i| {
        let mut row: [f64; 3] =
            std::array::from_fn(|j| dot_after(a[i][0], b[0][j], a[i][1], b[1][j]));
        row[2] += a[i][2];
        row
    })
}

/// The head's uniform scale (the square root of the determinant's magnitude of `m`'s linear
/// part) and the unit vector `v` becomes under that linear part (rounded as numpy rounds
/// the product and the length).
pub fn scale_and_turn(m: &[[f64; 3]; 2], v: [f64; 2]) -> (f64, [f64; 2]) {
    let scale = (m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs().sqrt();
    let t: [f64; 2] = std::array::from_fn(|j| dot_before(v[0], m[j][0], v[1], m[j][1]));
    let length = dot_after(t[0], t[0], t[1], t[1]).sqrt();
    (scale, [t[0] / length, t[1] / length])
}

/// The inverse of a 2×3 similarity (z ↦ a·z + b inverts to z ↦ (z − b)/a).
fn invert(m: &[[f64; 3]; 2]) -> [[f64; 3]; 2] {
    let (a, b) = (
        Complex::of([m[0][0], m[1][0]]),
        Complex::of([m[0][2], m[1][2]]),
    );
    let n = a.re * a.re + a.im * a.im;
    let inv = Complex {
        re: a.re / n,
        im: -a.im / n,
    };
    let c = inv.mul(b).scale(-1.0);
    [[inv.re, -inv.im, c.re], [inv.im, inv.re, c.im]]
}

/// The 2×3 identity.
const IDENTITY: [[f64; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// Each of `start` (pixels of `prev`'s frame) followed into `next`'s frame and back: its
/// position there, None where the flow failed or came back more than `limit` px from where it
/// started. The flow starts where the similarity `m` (from `prev`'s frame to `next`'s) carries
/// each point, its inverse on the way back, and runs through `levels` levels above the frame
/// at most.
fn forward_backward(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    start: &[[f64; 2]],
    (m, levels): (&[[f64; 3]; 2], usize),
    lk: &LkParams,
    limit: f64,
) -> Result<Vec<Option<[f64; 2]>>> {
    let guess: Vec<[f64; 2]> = start.iter().map(|&p| apply(m, p)).collect();
    let there = lucas_kanade_from(prev, next, start, &guess, levels, lk)?;
    back_checked(prev, next, start, &there, (&invert(m), levels), lk, limit)
}

/// The forward-backward check of the flow of `start` (pixels of `prev`'s frame) to `there`
/// (`next`'s frame; None where it failed): each of `there` followed back into `prev`'s frame,
/// from where the transform `back` carries it and through `levels` levels above the frame at
/// most. Returns `there` where the flow came back within `limit` px of `start`, else None.
fn back_checked(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    start: &[[f64; 2]],
    there: &[Option<[f64; 2]>],
    (back, levels): (&[[f64; 3]; 2], usize),
    lk: &LkParams,
    limit: f64,
) -> Result<Vec<Option<[f64; 2]>>> {
    let ahead: Vec<[f64; 2]> = there.iter().map(|q| q.unwrap_or([f64::NAN; 2])).collect();
    let guess: Vec<[f64; 2]> = ahead.iter().map(|&q| apply(back, q)).collect();
    let returned = lucas_kanade_from(next, prev, &ahead, &guess, levels, lk)?;
    Ok((0..start.len())
        .map(|i| match (there[i], returned[i]) {
            (Some(q), Some(b)) => {
                let d = [b[0] - start[i][0], b[1] - start[i][1]];
                (d[0] * d[0] + d[1] * d[1] < limit * limit).then_some(q)
            }
            _ => None,
        })
        .collect())
}

/// The head's motion from `prev`'s frame to `next`'s: the rigid `points` (pixels of the
/// previous frame) followed by the Lucas-Kanade flow forwards, from where they were through
/// every level, and back; those that come back within `limit` px of where they started are
/// fitted by [`robust_similarity`] (inliers within `limit` px, at most `rounds` rounds), which
/// counts when at least `min_points` passed the check and fit it. The way back starts where
/// the inverse of the similarity fitted to the forward flow alone carries each point and runs
/// through `guided_levels` levels above the frame at most (each level costs as much as the
/// frame's own). The `extra` points are followed and checked alike (not fitted), both
/// ways from where the similarity carries them through `guided_levels` levels; those that fail
/// the check then, or all of them without a similarity, are followed like the rigid points
/// from where they were, both ways through every level.
#[allow(clippy::too_many_arguments)]
pub fn follow_rigid(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    points: &[[f64; 2]],
    extra: &[[f64; 2]],
    guided_levels: usize,
    lk: &LkParams,
    limit: f64,
    min_points: usize,
    rounds: usize,
) -> Result<RigidStep> {
    let unguided = (&IDENTITY, usize::MAX);
    let checked = rigid_checked(
        prev,
        next,
        points,
        guided_levels,
        lk,
        limit,
        min_points,
        rounds,
    )?;
    let good: Vec<usize> = (0..points.len())
        .filter(|&i| checked[i].is_some())
        .collect();
    let mut step = RigidStep {
        similarity: None,
        kept: Vec::new(),
        moved: Vec::new(),
        extra: Vec::new(),
    };
    if good.len() >= min_points {
        let src: Vec<[f64; 2]> = good.iter().map(|&i| points[i]).collect();
        let dst: Vec<[f64; 2]> = good.iter().map(|&i| checked[i].expect("checked")).collect();
        let (m, inliers) = robust_similarity(&src, &dst, limit, rounds);
        if inliers.iter().filter(|&&k| k).count() >= min_points {
            step.similarity = Some(m);
            for (j, _) in inliers.iter().enumerate().filter(|(_, &k)| k) {
                step.kept.push(good[j]);
                step.moved.push(dst[j]);
            }
        }
    }
    step.extra = match &step.similarity {
        None => forward_backward(prev, next, extra, unguided, lk, limit)?,
        Some(m) => {
            let mut found = forward_backward(prev, next, extra, (m, guided_levels), lk, limit)?;
            let missed: Vec<usize> = (0..extra.len()).filter(|&i| found[i].is_none()).collect();
            let again: Vec<[f64; 2]> = missed.iter().map(|&i| extra[i]).collect();
            let wider = forward_backward(prev, next, &again, unguided, lk, limit)?;
            for (&i, f) in missed.iter().zip(wider) {
                found[i] = f;
            }
            found
        }
    };
    Ok(step)
}

/// The rigid `points` followed forwards from where they were, through every level, and checked
/// back ([`back_checked`]) from where the inverse of the similarity fitted to the forward flow
/// carries them, through `levels` levels. All None when fewer than `min_points` were followed
/// forwards.
///
/// A point that fails that check is not followed back again from where it is through every
/// level, as the extra points are: over 246 runs of the tracker on the six shared videos (on
/// each, the reference start, 23 noisy ones, the automatic start and 16 noisy ones of it), such
/// a second way back found 1 of the 100,923 points that failed, and it cost lp_d12 some 11
/// flows a frame.
#[allow(clippy::too_many_arguments)]
fn rigid_checked(
    prev: &mut Pyramid,
    next: &mut Pyramid,
    points: &[[f64; 2]],
    levels: usize,
    lk: &LkParams,
    limit: f64,
    min_points: usize,
    rounds: usize,
) -> Result<Vec<Option<[f64; 2]>>> {
    let there = lucas_kanade_from(prev, next, points, points, usize::MAX, lk)?;
    let (src, dst) = followed_pairs(points, &there);
    if src.len() < min_points {
        return Ok(vec![None; points.len()]);
    }
    let (ahead, _) = robust_similarity(&src, &dst, limit, rounds);
    back_checked(
        prev,
        next,
        points,
        &there,
        (&invert(&ahead), levels),
        lk,
        limit,
    )
}

/// The `points` the flow followed and where it took them (`there`, None where it failed).
fn followed_pairs(
    points: &[[f64; 2]],
    there: &[Option<[f64; 2]>],
) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    points
        .iter()
        .zip(there)
        .filter_map(|(&p, q)| q.map(|q| (p, q)))
        .unzip()
}

/// Which of `points` lie inside (or on the border of) any of the convex quadrilaterals
/// `quads` (corners in order, either winding).
pub fn inside_quads(points: &[[f64; 2]], quads: &[[[f64; 2]; 4]]) -> Vec<bool> {
    let inside = |p: &[f64; 2], q: &[[f64; 2]; 4]| {
        let cross: [f64; 4] = std::array::from_fn(|k| {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        });
        cross.iter().all(|&c| c >= 0.0) || cross.iter().all(|&c| c <= 0.0)
    };
    points
        .iter()
        .map(|p| quads.iter().any(|q| inside(p, q)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_similarity_and_rejects_gross_outliers() {
        let (c, s) = (1.03 * 0.07f64.cos(), 1.03 * 0.07f64.sin());
        let truth = [[c, -s, 4.0], [s, c, -2.5]];
        let src: Vec<[f64; 2]> = (0..30)
            .map(|k| [(k * 37 % 101) as f64 * 2.0, (k * 53 % 89) as f64 * 2.0])
            .collect();
        let mut dst: Vec<[f64; 2]> = src.iter().map(|&p| apply(&truth, p)).collect();
        for k in [3, 11, 17, 25] {
            dst[k][0] += 30.0;
        }
        let (m, inliers) = robust_similarity(&src, &dst, 1.0, 10);
        for p in &src {
            let (got, want) = (apply(&m, *p), apply(&truth, *p));
            assert!((got[0] - want[0]).abs() < 1e-6 && (got[1] - want[1]).abs() < 1e-6);
        }
        assert_eq!(inliers.iter().filter(|&&i| !i).count(), 4);
        assert!(!inliers[3] && !inliers[11] && !inliers[17] && !inliers[25]);
    }

    #[test]
    fn composition_applies_the_second_transform_first() {
        let (a, b) = (
            [[0.0, -1.0, 5.0], [1.0, 0.0, 0.0]],
            [[2.0, 0.0, 1.0], [0.0, 2.0, 3.0]],
        );
        let ab = compose(&a, &b);
        for p in [[0.0, 0.0], [1.5, -2.0]] {
            assert_eq!(apply(&ab, p), apply(&a, apply(&b, p)));
        }
        let (scale, down) = scale_and_turn(&ab, [0.0, 1.0]);
        assert_eq!((scale, down), (2.0, [-1.0, 0.0]));
    }

    #[test]
    fn no_points_give_the_identity() {
        let (m, inliers) = robust_similarity(&[], &[], 1.0, 10);
        assert_eq!(m, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert!(inliers.is_empty());
    }

    #[test]
    fn median_of_even_count_is_the_mean_of_the_middle_pair() {
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [5.0, 1.0, 3.0]), 3.0);
    }

    /// The pyramids of a w×h texture and of the same texture shifted by `by` pixels.
    fn shifted(w: usize, h: usize, by: [f64; 2]) -> (Pyramid, Pyramid) {
        use crate::flow::tests::{pyramid, texture};
        let (a, b) = (texture(w, h, 0.0, 0.0), texture(w, h, by[0], by[1]));
        (pyramid(&a, w, h), pyramid(&b, w, h))
    }

    #[test]
    fn follow_rigid_finds_the_shift_and_checks_every_point() {
        use crate::flow::tests::PARAMS;
        let (mut pa, mut pb) = shifted(96, 96, [1.5, -0.5]);
        let points: Vec<[f64; 2]> = (0..9)
            .map(|k| [30.0 + 6.0 * (k % 3) as f64, 30.0 + 6.0 * (k / 3) as f64])
            .collect();
        let extra = [[48.0, 50.0], [f64::NAN, 3.0], [-500.0, 40.0]];
        let step = follow_rigid(&mut pa, &mut pb, &points, &extra, 1, &PARAMS, 1.0, 6, 10).unwrap();
        let m = step.similarity.expect("a similarity");
        for p in &points {
            let q = apply(&m, *p);
            assert!((q[0] - p[0] - 1.5).abs() < 0.05 && (q[1] - p[1] + 0.5).abs() < 0.05);
        }
        assert_eq!(step.kept, (0..9).collect::<Vec<_>>());
        let e = step.extra[0].expect("followed");
        assert!((e[0] - 49.5).abs() < 0.05 && (e[1] - 49.5).abs() < 0.05);
        assert_eq!(step.extra[1..], [None, None]);
        // Fewer points than the minimum: no similarity, nothing kept.
        let few =
            follow_rigid(&mut pa, &mut pb, &points[..5], &[], 1, &PARAMS, 1.0, 6, 10).unwrap();
        assert_eq!((few.similarity, few.kept.len()), (None, 0));
    }

    #[test]
    fn extra_points_start_where_the_head_moved_them_and_are_looked_for_wider_if_that_fails() {
        use crate::flow::tests::{pyramid, texture, PARAMS};
        let (w, h) = (384, 256);
        // The head moves by (30, -20); inside a 140 px square on the left, the image moves by
        // (-30, -20) instead, beyond the frame level's reach from where the head puts it.
        let a = texture(w, h, 0.0, 0.0);
        let mut b = texture(w, h, 30.0, -20.0);
        let part = texture(w, h, -30.0, -20.0);
        for y in 50..190 {
            for x in 0..140 {
                b[y * w + x] = part[y * w + x];
            }
        }
        let (mut pa, mut pb) = (pyramid(&a, w, h), pyramid(&b, w, h));
        let points: Vec<[f64; 2]> = (0..12)
            .map(|k| [220.0 + 12.0 * (k % 4) as f64, 120.0 + 15.0 * (k / 4) as f64])
            .collect();
        let extra = [[240.0, 150.0], [70.0, 130.0]];
        let step = follow_rigid(&mut pa, &mut pb, &points, &extra, 0, &PARAMS, 1.0, 6, 10).unwrap();
        let m = step.similarity.expect("a similarity");
        assert!(
            (m[0][2] - 30.0).abs() < 0.1 && (m[1][2] + 20.0).abs() < 0.1,
            "{m:?}"
        );
        let off = |q: Option<[f64; 2]>, want: [f64; 2]| {
            q.map_or(f64::INFINITY, |q| {
                (q[0] - want[0]).abs().max((q[1] - want[1]).abs())
            })
        };
        // On the frame's level only, from where the head moved it.
        assert!(
            off(step.extra[0], [270.0, 130.0]) < 0.05,
            "{:?}",
            step.extra[0]
        );
        // Found again through every level.
        assert!(
            off(step.extra[1], [40.0, 110.0]) < 0.1,
            "{:?}",
            step.extra[1]
        );
        // On the frame's level alone, the first is not found from where it was, nor the
        // second from where the head moved it.
        let alone =
            crate::flow::lucas_kanade_from(&mut pa, &mut pb, &extra, &extra, 0, &PARAMS).unwrap();
        assert!(off(alone[0], [270.0, 130.0]) > 1.0, "{:?}", alone[0]);
        let moved = [apply(&m, extra[1])];
        let guided =
            crate::flow::lucas_kanade_from(&mut pa, &mut pb, &extra[1..], &moved, 0, &PARAMS);
        assert!(off(guided.unwrap()[0], [40.0, 110.0]) > 1.0);
    }

    #[test]
    fn rigid_points_come_back_from_where_the_head_moved_them() {
        use crate::flow::tests::PARAMS;
        // The head moves by (30, -20), beyond the frame level's reach from where the points
        // were: the way back, on the frame's level alone, finds them only from where the
        // head's step carries them back.
        let (mut pa, mut pb) = shifted(384, 256, [30.0, -20.0]);
        let points: Vec<[f64; 2]> = (0..12)
            .map(|k| [150.0 + 12.0 * (k % 4) as f64, 110.0 + 15.0 * (k / 4) as f64])
            .collect();
        let step = follow_rigid(&mut pa, &mut pb, &points, &[], 0, &PARAMS, 1.0, 6, 10).unwrap();
        let m = step.similarity.expect("a similarity");
        assert!(
            (m[0][2] - 30.0).abs() < 0.1 && (m[1][2] + 20.0).abs() < 0.1,
            "{m:?}"
        );
        assert_eq!(step.kept, (0..12).collect::<Vec<_>>());
        // On the frame's level alone, the way back finds them all from where the head's
        // step carries them back, not from where they are.
        let there: Vec<Option<[f64; 2]>> = points
            .iter()
            .map(|p| Some([p[0] + 30.0, p[1] - 20.0]))
            .collect();
        let mut back = |guide: [[f64; 3]; 2]| {
            let found = back_checked(&mut pa, &mut pb, &points, &there, (&guide, 0), &PARAMS, 1.0);
            found.unwrap().iter().filter(|q| q.is_some()).count()
        };
        assert_eq!(back(invert(&m)), 12);
        assert!(back(IDENTITY) < 6);
    }

    #[test]
    fn inside_quads_takes_either_winding_and_the_border() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let mut reversed = square;
        reversed.reverse();
        let far = [[10.0, 10.0], [12.0, 10.0], [12.0, 12.0], [10.0, 12.0]];
        let pts = [[1.0, 1.0], [2.0, 1.0], [3.0, 1.0], [11.0, 11.5]];
        for q in [square, reversed] {
            assert_eq!(inside_quads(&pts, &[q, far]), [true, true, false, true]);
        }
        assert_eq!(inside_quads(&pts, &[]), [false; 4]);
    }
}
