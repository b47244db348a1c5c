//! The per-window arithmetic of the Lucas-Kanade flow, [`LANES`] columns at a time: a portable
//! version and an AVX2 one that compute the same values bit for bit (the same operations in
//! the same order; products are added with fused multiply-adds, `f32::mul_add` in the portable
//! version).
//!
//! The kernels are bound by their loads and by the latency of their sums, so each reads a plane
//! row once per block of [`LANES`] columns and keeps what the next row needs in registers:
//! bilinear sampling is done along the row, then across rows; the Scharr derivatives are a row
//! difference and a row smoothing, then the same across rows. A block's rows are walked top to
//! bottom, the blocks left to right; lane l of a sum adds up, in that order, the terms of the
//! columns ≡ l (mod [`LANES`]) (in [`correlate`], even and odd rows apart, then the two), and
//! the lanes are added up pairwise at the end (see [`sum`]).
//!
//! The window is `win` × `win` pixels. Its buffers have rows of [`Shape::cols`] values, the
//! side rounded up to [`LANES`]; columns past the side are dead (derivatives 0) and add nothing.

#[cfg(target_arch = "x86_64")]
use crate::cpu::has_avx2_fma;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// Width of the partial sums.
pub const LANES: usize = 8;

/// The buffers' layout for a window side.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Window side (pixels).
    pub win: usize,
    /// Row length of the derivatives: `win` rounded up to [`LANES`].
    pub cols: usize,
    /// Row length of the grown window's samples: room for the `cols` + 2 values the
    /// derivatives read (those past the sampled ones only feed dead columns).
    pub ecols: usize,
}

impl Shape {
    pub fn new(win: usize) -> Self {
        let cols = win.div_ceil(LANES) * LANES;
        Self {
            win,
            cols,
            ecols: cols + LANES,
        }
    }

    /// Columns sampled per row of the grown window: `win` + 2 rounded up to [`LANES`].
    fn sampled(&self) -> usize {
        (self.win + 2).div_ceil(LANES) * LANES
    }

    /// The (columns, rows) of plane values from the grid's top-left sample's integer part that
    /// [`sample`] of `rows` rows reads.
    pub fn sampled_block(&self, rows: usize) -> [usize; 2] {
        [self.sampled() + 1, rows + 1]
    }

    /// The (columns, rows) of plane values from the grid's top-left sample's integer part that
    /// [`correlate`] reads.
    pub fn correlated_block(&self) -> [usize; 2] {
        [self.cols + 1, self.win + 1]
    }

    /// Mirrored pixels a plane needs on every side for windows whose corner's integer part
    /// lies in [−`win`, size): the kernels read from one pixel left of (above) the corner to
    /// `win` + 1 pixels below it and `cols` pixels right of it (sampling the grown window,
    /// [`Shape::sampled`] − 1).
    pub fn pad(&self) -> usize {
        (self.win + 1).max(self.cols).max(self.sampled() - 1)
    }
}

/// Bilinear samples of a padded plane P: with a = start + r·s + c and s = stride, the sample
/// at window (row r, column c) is `wy[0]·h(a) + wy[1]·h(a + s)`, where
/// `h(i) = wx[0]·P[i] + wx[1]·P[i + 1]`.
#[derive(Clone, Copy)]
pub struct Grid<'a> {
    pub plane: &'a [f32],
    pub start: usize,
    pub stride: usize,
    pub wx: [f32; 2],
    pub wy: [f32; 2],
}

impl Grid<'_> {
    /// Plane row `r` of the grid from column `k`, `len` + 1 values.
    fn row(&self, r: usize, k: usize, len: usize) -> &[f32] {
        &self.plane[self.start + r * self.stride + k..][..len + 1]
    }
}

/// The lanes' total, in f64: lanes l and l + 4, then those sums two apart, then the two.
fn sum(a: [f32; LANES]) -> f64 {
    let h: [f64; 4] = std::array::from_fn(|l| a[l] as f64 + a[l + 4] as f64);
    (h[0] + h[2]) + (h[1] + h[3])
}

/// Fills `rows` rows of `out` (rows of `s.ecols`) with the grid's samples, the first
/// `s.win` + 2 columns of each at least.
pub fn sample(s: &Shape, g: &Grid, rows: usize, out: &mut [f32]) {
    assert!(out.len() >= rows * s.ecols && s.ecols >= s.sampled());
    g.row(rows, s.sampled() - LANES, LANES); // the last value read is in the plane
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { sample_avx2(s, g, rows, out) };
    }
    sample_portable(s, g, rows, out)
}

fn sample_portable(s: &Shape, g: &Grid, rows: usize, out: &mut [f32]) {
    let h = |r: usize, k: usize| -> [f32; LANES] {
        let p = g.row(r, k, LANES);
        std::array::from_fn(|l| g.wx[1].mul_add(p[l + 1], g.wx[0] * p[l]))
    };
    for k in (0..s.sampled()).step_by(LANES) {
        let mut above = h(0, k);
        for r in 0..rows {
            let below = h(r + 1, k);
            for (l, o) in out[r * s.ecols + k..][..LANES].iter_mut().enumerate() {
                *o = g.wy[1].mul_add(below[l], g.wy[0] * above[l]);
            }
            above = below;
        }
    }
}

/// Scharr derivatives of the window whose samples, grown by one pixel on every side, are
/// `ext` (see [`sample`]): window (r, c) is `ext` (r + 1, c + 1). Writes `gx`, `gy` (`s.win`
/// rows of `s.cols`) divided by 32, which makes them grey levels per pixel (the Scharr weights
/// sum to 32), and 0 past the window's side; returns the gradient matrix and the window's image
/// against its derivatives: (Σgx², Σgx·gy, Σgy², ΣI·gx, ΣI·gy), I the window's samples. `ext`
/// must be finite.
///
/// Dividing by 32 is exact, so it is applied to the weights: (10/32)·a + (3/32)·b rounds as
/// (10·a + 3·b)/32 does.
pub fn gradients(s: &Shape, ext: &[f32], gx: &mut [f32], gy: &mut [f32]) -> [f64; 5] {
    assert!(s.cols.is_multiple_of(LANES) && s.ecols >= s.cols + 2);
    assert!(ext.len() >= (s.win + 2) * s.ecols);
    assert!(gy.len() == gx.len() && gx.len() == s.win * s.cols);
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { gradients_avx2(s, ext, gx, gy) };
    }
    gradients_portable(s, ext, gx, gy)
}

/// The Scharr weights over 32.
const TEN: f32 = 10.0 / 32.0;
const THREE: f32 = 3.0 / 32.0;

fn gradients_portable(s: &Shape, ext: &[f32], gx: &mut [f32], gy: &mut [f32]) -> [f64; 5] {
    let mut acc = [[0.0f32; LANES]; 5];
    // Per column of ext row e: (row difference n − p, row smoothing (3·(p + n) + 10·m)/32, m).
    let along = |e: usize, k: usize| -> [[f32; LANES]; 3] {
        let v = &ext[e * s.ecols + k..][..LANES + 2];
        [
            std::array::from_fn(|l| v[l + 2] - v[l]),
            std::array::from_fn(|l| TEN.mul_add(v[l + 1], THREE * (v[l] + v[l + 2]))),
            std::array::from_fn(|l| v[l + 1]),
        ]
    };
    for k in (0..s.cols).step_by(LANES) {
        let (mut r0, mut r1) = (along(0, k), along(1, k));
        for r in 0..s.win {
            let r2 = along(r + 2, k);
            for l in 0..LANES {
                let live = k + l < s.win;
                let x = TEN.mul_add(r1[0][l], THREE * (r0[0][l] + r2[0][l]));
                let (x, y) = if live {
                    (x, r2[1][l] - r0[1][l])
                } else {
                    (0.0, 0.0)
                };
                let i = r1[2][l];
                gx[r * s.cols + k + l] = x;
                gy[r * s.cols + k + l] = y;
                for (a, t) in acc.iter_mut().zip([(x, x), (x, y), (y, y), (i, x), (i, y)]) {
                    a[l] = t.0.mul_add(t.1, a[l]);
                }
            }
            (r0, r1) = (r1, r2);
        }
    }
    acc.map(sum)
}

/// ΣJ·gx and ΣJ·gy over the window, J the `next` grid's samples, `gx`, `gy` as [`gradients`]
/// wrote them.
pub fn correlate(s: &Shape, next: &Grid, gx: &[f32], gy: &[f32]) -> [f64; 2] {
    assert!(s.cols.is_multiple_of(LANES));
    assert!(gy.len() == gx.len() && gx.len() == s.win * s.cols);
    next.row(s.win, s.cols - LANES, LANES); // the last value read is in the plane
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { correlate_avx2(s, next, gx, gy) };
    }
    correlate_portable(s, next, gx, gy)
}

fn correlate_portable(s: &Shape, g: &Grid, gx: &[f32], gy: &[f32]) -> [f64; 2] {
    let h = |r: usize, k: usize| -> [f32; LANES] {
        let p = g.row(r, k, LANES);
        std::array::from_fn(|l| g.wx[1].mul_add(p[l + 1], g.wx[0] * p[l]))
    };
    // [row parity][derivative][lane]
    let mut acc = [[[0.0f32; LANES]; 2]; 2];
    for k in (0..s.cols).step_by(LANES) {
        let mut above = h(0, k);
        for r in 0..s.win {
            let below = h(r + 1, k);
            let a = &mut acc[r % 2];
            for l in 0..LANES {
                let j = g.wy[1].mul_add(below[l], g.wy[0] * above[l]);
                a[0][l] = j.mul_add(gx[r * s.cols + k + l], a[0][l]);
                a[1][l] = j.mul_add(gy[r * s.cols + k + l], a[1][l]);
            }
            above = below;
        }
    }
    [0, 1].map(|d| sum(std::array::from_fn(|l| acc[0][d][l] + acc[1][d][l])))
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;

    /// w[0]·P[p] + w[1]·P[p + 1], [`LANES`] columns from `p`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn along(p: *const f32, w: &[__m256; 2]) -> __m256 {
        _mm256_fmadd_ps(
            w[1],
            _mm256_loadu_ps(p.add(1)),
            _mm256_mul_ps(w[0], _mm256_loadu_ps(p)),
        )
    }

    /// w[0]·a + w[1]·b.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn across(a: __m256, b: __m256, w: &[__m256; 2]) -> __m256 {
        _mm256_fmadd_ps(w[1], b, _mm256_mul_ps(w[0], a))
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn weights(w: [f32; 2]) -> [__m256; 2] {
        w.map(|v| _mm256_set1_ps(v))
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn lanes(v: __m256) -> [f32; LANES] {
        let mut out = [0.0f32; LANES];
        _mm256_storeu_ps(out.as_mut_ptr(), v);
        out
    }
}

/// # Safety
/// AVX2 must be present and the sizes those [`sample`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sample_avx2(s: &Shape, g: &Grid, rows: usize, out: &mut [f32]) {
    let (wx, wy) = (avx2::weights(g.wx), avx2::weights(g.wy));
    let p = g.plane.as_ptr().add(g.start);
    for k in (0..s.sampled()).step_by(LANES) {
        let mut above = avx2::along(p.add(k), &wx);
        for r in 0..rows {
            let below = avx2::along(p.add((r + 1) * g.stride + k), &wx);
            let v = avx2::across(above, below, &wy);
            _mm256_storeu_ps(out.as_mut_ptr().add(r * s.ecols + k), v);
            above = below;
        }
    }
}

/// # Safety
/// AVX2 must be present and the sizes those [`gradients`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gradients_avx2(s: &Shape, ext: &[f32], gx: &mut [f32], gy: &mut [f32]) -> [f64; 5] {
    let (three, ten) = (_mm256_set1_ps(THREE), _mm256_set1_ps(TEN));
    let lane = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0);
    let mut acc = [_mm256_setzero_ps(); 5];
    for k in (0..s.cols).step_by(LANES) {
        // All ones in the window's columns, zero past its side.
        let live = _mm256_cmp_ps::<_CMP_LT_OQ>(
            _mm256_add_ps(lane, _mm256_set1_ps(k as f32)),
            _mm256_set1_ps(s.win as f32),
        );
        // Row e's difference n − p, smoothing (3·(p + n) + 10·m)/32 and middle m.
        let along = |e: usize| {
            let v = ext.as_ptr().add(e * s.ecols + k);
            let (p, m, n) = (
                _mm256_loadu_ps(v),
                _mm256_loadu_ps(v.add(1)),
                _mm256_loadu_ps(v.add(2)),
            );
            let smooth = _mm256_fmadd_ps(ten, m, _mm256_mul_ps(three, _mm256_add_ps(p, n)));
            (_mm256_sub_ps(n, p), smooth, m)
        };
        // Rows r and r + 1 of ext held in registers, named rather than in arrays (which the
        // compiler shuffles and spills).
        let (mut d0, mut s0, _) = along(0);
        let (mut d1, mut s1, mut m1) = along(1);
        let [mut xx, mut xy, mut yy, mut ix, mut iy] = acc;
        for r in 0..s.win {
            let (d2, s2, m2) = along(r + 2);
            let x = _mm256_fmadd_ps(ten, d1, _mm256_mul_ps(three, _mm256_add_ps(d0, d2)));
            let x = _mm256_and_ps(live, x);
            let y = _mm256_and_ps(live, _mm256_sub_ps(s2, s0));
            _mm256_storeu_ps(gx.as_mut_ptr().add(r * s.cols + k), x);
            _mm256_storeu_ps(gy.as_mut_ptr().add(r * s.cols + k), y);
            xx = _mm256_fmadd_ps(x, x, xx);
            xy = _mm256_fmadd_ps(x, y, xy);
            yy = _mm256_fmadd_ps(y, y, yy);
            ix = _mm256_fmadd_ps(m1, x, ix);
            iy = _mm256_fmadd_ps(m1, y, iy);
            (d0, s0) = (d1, s1);
            (d1, s1, m1) = (d2, s2, m2);
        }
        acc = [xx, xy, yy, ix, iy];
    }
    acc.map(|a| sum(avx2::lanes(a)))
}

/// # Safety
/// AVX2 must be present and the sizes those [`correlate`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn correlate_avx2(s: &Shape, g: &Grid, gx: &[f32], gy: &[f32]) -> [f64; 2] {
    let (wx, wy) = (avx2::weights(g.wx), avx2::weights(g.wy));
    let p = g.plane.as_ptr().add(g.start);
    // [row parity][derivative]: two chains of additions per sum, not one.
    let mut acc = [[_mm256_setzero_ps(); 2]; 2];
    let step = |acc: &mut [__m256; 2], j: __m256, at: usize| {
        acc[0] = _mm256_fmadd_ps(j, _mm256_loadu_ps(gx.as_ptr().add(at)), acc[0]);
        acc[1] = _mm256_fmadd_ps(j, _mm256_loadu_ps(gy.as_ptr().add(at)), acc[1]);
    };
    for k in (0..s.cols).step_by(LANES) {
        let mut above = avx2::along(p.add(k), &wx);
        let mut r = 0;
        while r < s.win {
            let below = avx2::along(p.add((r + 1) * g.stride + k), &wx);
            step(&mut acc[0], avx2::across(above, below, &wy), r * s.cols + k);
            above = below;
            if r + 1 < s.win {
                let below = avx2::along(p.add((r + 2) * g.stride + k), &wx);
                step(
                    &mut acc[1],
                    avx2::across(above, below, &wy),
                    (r + 1) * s.cols + k,
                );
                above = below;
            }
            r += 2;
        }
    }
    [0, 1].map(|d| sum(avx2::lanes(_mm256_add_ps(acc[0][d], acc[1][d]))))
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// Deterministic values in 0..255 with fractional parts.
    fn values(n: usize, seed: u64) -> Vec<f32> {
        let mut x = seed;
        (0..n)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (x >> 40) as f32 / (1u64 << 24) as f32 * 255.0
            })
            .collect()
    }

    #[test]
    fn avx2_kernels_equal_the_portable_ones_bit_for_bit() {
        if !has_avx2_fma() {
            crate::cpu::simd_missing(
                "avx2_kernels_equal_the_portable_ones_bit_for_bit",
                "AVX2 and FMA",
            );
            return;
        }
        for win in [5, 15, 21] {
            let s = Shape::new(win);
            let stride = 90;
            let plane = values(stride * 40, 1);
            for (seed, wx, wy) in [(2, [0.3, 0.7], [0.6, 0.4]), (3, [0.95, 0.05], [0.02, 0.98])] {
                let g = Grid {
                    plane: &plane,
                    start: 3 * stride + 5,
                    stride,
                    wx,
                    wy,
                };
                let rows = win + 2;
                // The same finite values in the columns neither samples.
                let (mut a, mut b) = (values(rows * s.ecols, seed), values(rows * s.ecols, seed));
                sample(&s, &g, rows, &mut a);
                sample_portable(&s, &g, rows, &mut b);
                assert_eq!(a, b);
                let n = win * s.cols;
                let (mut gx, mut gy, mut hx, mut hy) =
                    (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                let m = gradients(&s, &a, &mut gx, &mut gy);
                assert_eq!(m, gradients_portable(&s, &a, &mut hx, &mut hy));
                assert_eq!((&gx, &gy), (&hx, &hy));
                assert!(gx
                    .chunks(s.cols)
                    .all(|row| row[win..].iter().all(|&v| v == 0.0)));
                let next = Grid {
                    start: 7 * stride + 11,
                    ..g
                };
                assert_eq!(
                    correlate(&s, &next, &gx, &gy),
                    correlate_portable(&s, &next, &gx, &gy)
                );
            }
        }
    }
}
