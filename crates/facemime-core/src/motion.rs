//! Robust 2D similarity fit between two point sets: the frame-to-frame head motion of the
//! tracker, fitted despite points that the optical flow lost or that moved with the face's
//! non-rigid parts.
//!
//! Points are (x, y) pixels. The similarity is written as complex numbers, z ↦ a·z + b with
//! z = x + iy; as a 2×3 matrix it is [[Re a, −Im a, Re b], [Im a, Re a, Im b]].

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

/// Median (the mean of the two middle values for an even count); NaN when empty.
fn median(values: &mut [f64]) -> f64 {
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    values.sort_unstable_by(f64::total_cmp);
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
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

#[cfg(test)]
mod tests {
    use super::*;

    fn apply(m: &[[f64; 3]; 2], p: [f64; 2]) -> [f64; 2] {
        [
            m[0][0] * p[0] + m[0][1] * p[1] + m[0][2],
            m[1][0] * p[0] + m[1][1] * p[1] + m[1][2],
        ]
    }

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
}
