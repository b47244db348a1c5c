//! The per-window arithmetic of the Lucas-Kanade flow, [`LANES`] columns at a time: a portable
//! version and an AVX2 one that computes the same values bit for bit (the same operations in
//! the same order, no fused multiply-add). Window rows are `cols` values long, a multiple of
//! [`LANES`]; each lane keeps its own partial sums, added up in lane order at the end.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// Width of the partial sums.
pub const LANES: usize = 8;

/// Bilinear samples of a padded plane P: the sample at window (row r, column c) is
/// `w[0]·P[a] + w[1]·P[a+1] + w[2]·P[a+s] + w[3]·P[a+s+1]`,
/// with s = stride and a = start + r·s + c.
#[derive(Clone, Copy)]
pub struct Grid<'a> {
    pub plane: &'a [f32],
    pub start: usize,
    pub stride: usize,
    pub w: [f32; 4],
}

impl Grid<'_> {
    /// The two plane rows that window row `r` interpolates between, `len` + 1 values each.
    fn rows(&self, r: usize, len: usize) -> (&[f32], &[f32]) {
        let at = self.start + r * self.stride;
        (
            &self.plane[at..][..len + 1],
            &self.plane[at + self.stride..][..len + 1],
        )
    }
}

#[cfg(target_arch = "x86_64")]
fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}

fn sum(a: [f32; LANES]) -> f64 {
    a.iter().map(|&v| v as f64).sum()
}

/// Fills `out` (`rows` × `cols`) with the grid's samples.
pub fn sample(g: &Grid, rows: usize, cols: usize, out: &mut [f32]) {
    assert!(cols.is_multiple_of(LANES) && out.len() >= rows * cols);
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { sample_avx2(g, rows, cols, out) };
    }
    sample_portable(g, rows, cols, out)
}

fn sample_portable(g: &Grid, rows: usize, cols: usize, out: &mut [f32]) {
    for r in 0..rows {
        let (t, b) = g.rows(r, cols);
        for (c, o) in out[r * cols..][..cols].iter_mut().enumerate() {
            *o = g.w[0] * t[c] + g.w[1] * t[c + 1] + g.w[2] * b[c] + g.w[3] * b[c + 1];
        }
    }
}

/// Scharr derivatives of the window whose samples, grown by one pixel on every side, are
/// `ext` (rows of `ecols` ≥ `cols` + 2 values): window (r, c) is `ext` (r + 1, c + 1).
/// Writes `gx`, `gy` (`win` × `cols`) scaled by `live` per column (1/32 in the window, which
/// makes them grey levels per pixel, as the Scharr weights sum to 32; 0 past it) and returns
/// the gradient matrix (Σgx², Σgx·gy, Σgy²).
pub fn gradients(
    ext: &[f32],
    ecols: usize,
    live: &[f32],
    gx: &mut [f32],
    gy: &mut [f32],
) -> [f64; 3] {
    let cols = live.len();
    let win = gx.len() / cols;
    assert!(cols.is_multiple_of(LANES) && ecols >= cols + 2 && ext.len() >= (win + 2) * ecols);
    assert!(gy.len() == gx.len() && gx.len() == win * cols);
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { gradients_avx2(ext, ecols, live, gx, gy) };
    }
    gradients_portable(ext, ecols, live, gx, gy)
}

fn gradients_portable(
    ext: &[f32],
    ecols: usize,
    live: &[f32],
    gx: &mut [f32],
    gy: &mut [f32],
) -> [f64; 3] {
    let cols = live.len();
    let win = gx.len() / cols;
    let (mut a11, mut a12, mut a22) = ([0.0f32; LANES], [0.0f32; LANES], [0.0f32; LANES]);
    for r in 0..win {
        let row = |k: usize| &ext[(r + k) * ecols..][..ecols];
        let (e0, e1, e2) = (row(0), row(1), row(2));
        for c in 0..cols {
            let (l, s) = (c % LANES, live[c]);
            let x =
                s * (3.0 * (e0[c + 2] - e0[c] + e2[c + 2] - e2[c]) + 10.0 * (e1[c + 2] - e1[c]));
            let y = s
                * (3.0 * (e2[c] + e2[c + 2] - e0[c] - e0[c + 2]) + 10.0 * (e2[c + 1] - e0[c + 1]));
            gx[r * cols + c] = x;
            gy[r * cols + c] = y;
            a11[l] += x * x;
            a12[l] += x * y;
            a22[l] += y * y;
        }
    }
    [sum(a11), sum(a12), sum(a22)]
}

/// Σ(J − I)·gx and Σ(J − I)·gy over the window, J the `next` grid's samples, I the window's
/// samples inside `ext` (see [`gradients`]), `gx`, `gy` as [`gradients`] wrote them.
pub fn mismatch(
    next: &Grid,
    ext: &[f32],
    ecols: usize,
    gx: &[f32],
    gy: &[f32],
    cols: usize,
) -> [f64; 2] {
    let win = gx.len() / cols;
    assert!(cols.is_multiple_of(LANES) && ecols >= cols + 2 && ext.len() >= (win + 2) * ecols);
    assert!(gy.len() == gx.len() && gx.len() == win * cols);
    #[cfg(target_arch = "x86_64")]
    if has_avx2() {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { mismatch_avx2(next, ext, ecols, gx, gy, cols) };
    }
    mismatch_portable(next, ext, ecols, gx, gy, cols)
}

fn mismatch_portable(
    next: &Grid,
    ext: &[f32],
    ecols: usize,
    gx: &[f32],
    gy: &[f32],
    cols: usize,
) -> [f64; 2] {
    let win = gx.len() / cols;
    let (mut b1, mut b2) = ([0.0f32; LANES], [0.0f32; LANES]);
    let w = next.w;
    for r in 0..win {
        let (t, b) = next.rows(r, cols);
        let i = &ext[(r + 1) * ecols + 1..][..cols];
        for c in 0..cols {
            let j = w[0] * t[c] + w[1] * t[c + 1] + w[2] * b[c] + w[3] * b[c + 1];
            let d = j - i[c];
            b1[c % LANES] += d * gx[r * cols + c];
            b2[c % LANES] += d * gy[r * cols + c];
        }
    }
    [sum(b1), sum(b2)]
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;

    /// w0·t0 + w1·t1 + w2·b0 + w3·b1, left to right.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn bilinear(t: *const f32, b: *const f32, w: &[__m256; 4]) -> __m256 {
        let s = _mm256_add_ps(
            _mm256_mul_ps(w[0], _mm256_loadu_ps(t)),
            _mm256_mul_ps(w[1], _mm256_loadu_ps(t.add(1))),
        );
        let s = _mm256_add_ps(s, _mm256_mul_ps(w[2], _mm256_loadu_ps(b)));
        _mm256_add_ps(s, _mm256_mul_ps(w[3], _mm256_loadu_ps(b.add(1))))
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn weights(w: [f32; 4]) -> [__m256; 4] {
        w.map(|v| _mm256_set1_ps(v))
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn lanes(v: __m256) -> [f32; LANES] {
        let mut out = [0.0f32; LANES];
        _mm256_storeu_ps(out.as_mut_ptr(), v);
        out
    }
}

/// # Safety
/// AVX2 must be present and the sizes those [`sample`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sample_avx2(g: &Grid, rows: usize, cols: usize, out: &mut [f32]) {
    let w = avx2::weights(g.w);
    for r in 0..rows {
        let (t, b) = g.rows(r, cols);
        let row = &mut out[r * cols..][..cols];
        for k in (0..cols).step_by(LANES) {
            let v = avx2::bilinear(t.as_ptr().add(k), b.as_ptr().add(k), &w);
            _mm256_storeu_ps(row.as_mut_ptr().add(k), v);
        }
    }
}

/// # Safety
/// AVX2 must be present and the sizes those [`gradients`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gradients_avx2(
    ext: &[f32],
    ecols: usize,
    live: &[f32],
    gx: &mut [f32],
    gy: &mut [f32],
) -> [f64; 3] {
    let cols = live.len();
    let win = gx.len() / cols;
    let (three, ten) = (_mm256_set1_ps(3.0), _mm256_set1_ps(10.0));
    let (mut a11, mut a12, mut a22) = (
        _mm256_setzero_ps(),
        _mm256_setzero_ps(),
        _mm256_setzero_ps(),
    );
    let e = ext.as_ptr();
    for r in 0..win {
        for k in (0..cols).step_by(LANES) {
            let at = |row: usize, dc: usize| _mm256_loadu_ps(e.add((r + row) * ecols + k + dc));
            let (p0, m0, n0) = (at(0, 0), at(0, 1), at(0, 2));
            let (p1, n1) = (at(1, 0), at(1, 2));
            let (p2, m2, n2) = (at(2, 0), at(2, 1), at(2, 2));
            let s = _mm256_loadu_ps(live.as_ptr().add(k));
            let dx = _mm256_sub_ps(_mm256_add_ps(_mm256_sub_ps(n0, p0), n2), p2);
            let x = _mm256_mul_ps(
                s,
                _mm256_add_ps(
                    _mm256_mul_ps(three, dx),
                    _mm256_mul_ps(ten, _mm256_sub_ps(n1, p1)),
                ),
            );
            let dy = _mm256_sub_ps(_mm256_sub_ps(_mm256_add_ps(p2, n2), p0), n0);
            let y = _mm256_mul_ps(
                s,
                _mm256_add_ps(
                    _mm256_mul_ps(three, dy),
                    _mm256_mul_ps(ten, _mm256_sub_ps(m2, m0)),
                ),
            );
            _mm256_storeu_ps(gx.as_mut_ptr().add(r * cols + k), x);
            _mm256_storeu_ps(gy.as_mut_ptr().add(r * cols + k), y);
            a11 = _mm256_add_ps(a11, _mm256_mul_ps(x, x));
            a12 = _mm256_add_ps(a12, _mm256_mul_ps(x, y));
            a22 = _mm256_add_ps(a22, _mm256_mul_ps(y, y));
        }
    }
    [a11, a12, a22].map(|a| sum(avx2::lanes(a)))
}

/// # Safety
/// AVX2 must be present and the sizes those [`mismatch`] checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mismatch_avx2(
    next: &Grid,
    ext: &[f32],
    ecols: usize,
    gx: &[f32],
    gy: &[f32],
    cols: usize,
) -> [f64; 2] {
    let win = gx.len() / cols;
    let w = avx2::weights(next.w);
    let (mut b1, mut b2) = (_mm256_setzero_ps(), _mm256_setzero_ps());
    for r in 0..win {
        let (t, b) = next.rows(r, cols);
        let i = ext.as_ptr().add((r + 1) * ecols + 1);
        for k in (0..cols).step_by(LANES) {
            let j = avx2::bilinear(t.as_ptr().add(k), b.as_ptr().add(k), &w);
            let d = _mm256_sub_ps(j, _mm256_loadu_ps(i.add(k)));
            b1 = _mm256_add_ps(
                b1,
                _mm256_mul_ps(d, _mm256_loadu_ps(gx.as_ptr().add(r * cols + k))),
            );
            b2 = _mm256_add_ps(
                b2,
                _mm256_mul_ps(d, _mm256_loadu_ps(gy.as_ptr().add(r * cols + k))),
            );
        }
    }
    [sum(avx2::lanes(b1)), sum(avx2::lanes(b2))]
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
        if !has_avx2() {
            return;
        }
        let (win, cols, ecols, stride) = (21, 24, 32, 90);
        let plane = values(stride * 40, 1);
        let mut live = vec![1.0f32; cols];
        live[win..].fill(0.0);
        for (seed, w) in [(2, [0.1, 0.2, 0.3, 0.4]), (3, [0.9, 0.05, 0.03, 0.02])] {
            let g = Grid {
                plane: &plane,
                start: 3 * stride + 5,
                stride,
                w,
            };
            let (mut a, mut b) = (vec![0.0; (win + 2) * ecols], vec![0.0; (win + 2) * ecols]);
            sample(&g, win + 2, ecols, &mut a);
            sample_portable(&g, win + 2, ecols, &mut b);
            assert_eq!(a, b);
            let ext = values((win + 2) * ecols, seed);
            let (mut gx, mut gy) = (vec![0.0; win * cols], vec![0.0; win * cols]);
            let (mut hx, mut hy) = (vec![0.0; win * cols], vec![0.0; win * cols]);
            let m = gradients(&ext, ecols, &live, &mut gx, &mut gy);
            assert_eq!(m, gradients_portable(&ext, ecols, &live, &mut hx, &mut hy));
            assert_eq!((&gx, &gy), (&hx, &hy));
            assert!(gx
                .chunks(cols)
                .all(|row| row[win..].iter().all(|&v| v == 0.0)));
            let next = Grid {
                start: 7 * stride + 11,
                ..g
            };
            assert_eq!(
                mismatch(&next, &ext, ecols, &gx, &gy, cols),
                mismatch_portable(&next, &ext, ecols, &gx, &gy, cols)
            );
        }
    }
}
