//! Template matching: where a grey template best matches a grey window, by the normalised
//! cross-correlation of OpenCV's `matchTemplate(TM_CCOEFF_NORMED)`,
//!
//!   Σ(T − T̄)(W − W̄) / √(Σ(T − T̄)² · Σ(W − W̄)²)   over the template's pixels,
//!
//! computed directly with exact integer sums (OpenCV's goes through floating-point DFTs) and
//! coarse to fine: where the template has more than [`COARSE_PLACEMENTS`] placements in the
//! window, both are halved and matched first (a sixteenth of the work), and at full size only
//! the placements within ± [`REFINE`] px of the coarse candidates are scored: the best coarse
//! placement and up to three others within [`GAP`] of its correlation. Of the 177 mouth
//! regions that lp_d6's tracking from its automatic start matched (several peaks: lips,
//! teeth), that found the full search's peak in all but one (0.534 against 0.546); the best
//! coarse placement alone missed it in six. A placement is the (x, y) pixel of the window under the
//! template's top-left pixel.

use crate::error::Result;
use crate::grey::grey_box;
use crate::invalid;
use crate::raster::ImageRef;

/// Placements above which the halved images are matched first.
pub const COARSE_PLACEMENTS: usize = 400;
/// Pixels around twice each coarse candidate scored at full size.
pub const REFINE: usize = 2;
/// Candidates carried from one size to the next at most: the best placement and others
/// within [`GAP`] of its correlation, none next to another.
pub const CANDIDATES: usize = 4;
/// How much lower than the best a candidate's correlation may be.
pub const GAP: f64 = 0.1;
/// A template is halved only when both its halved sides are at least this long (pixels).
const MIN_SIDE: usize = 8;
/// Products summed per correlation kernel step.
const CHUNK: usize = 16;

/// A grey image, row-major (width values per row).
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    pub data: Vec<u8>,
    pub width: usize,
    pub height: usize,
}

impl Grey {
    /// A `width` × `height` grey image of `data`; an error unless non-empty and of that size.
    pub fn new(data: Vec<u8>, width: usize, height: usize) -> Result<Self> {
        if width == 0 || height == 0 || data.len() != width * height {
            return invalid!(
                "a grey image of {width}x{height} pixels needs that many values, got {}",
                data.len()
            );
        }
        Ok(Self {
            data,
            width,
            height,
        })
    }

    fn row(&self, y: usize) -> &[u8] {
        &self.data[y * self.width..][..self.width]
    }

    /// Each 2×2 block's mean, rounded half up; an odd last row or column is dropped (the
    /// image must be at least 2×2).
    fn halved(&self) -> Grey {
        let (width, height) = (self.width / 2, self.height / 2);
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            let (a, b) = (self.row(2 * y), self.row(2 * y + 1));
            data.extend((0..width).map(|x| {
                let sum: u32 = [a[2 * x], a[2 * x + 1], b[2 * x], b[2 * x + 1]]
                    .iter()
                    .map(|&v| v as u32)
                    .sum();
                ((sum + 2) / 4) as u8
            }));
        }
        Grey {
            data,
            width,
            height,
        }
    }
}

/// The grey levels (as [`crate::grey`] converts RGB) of the box `area` = [x0, y0, x1, y1)
/// (pixels, exclusive ends) of a grey or RGB `frame`.
pub fn grey_area(frame: &ImageRef, area: [usize; 4]) -> Result<Grey> {
    let [x0, y0, x1, y1] = area;
    if frame.channels != 1 && frame.channels != 3 {
        return invalid!(
            "template matching takes grey or RGB images, got {} channels",
            frame.channels
        );
    }
    if x0 >= x1 || y0 >= y1 || x1 > frame.width || y1 > frame.height {
        return invalid!(
            "box {area:?} is empty or outside the {}x{} image",
            frame.width,
            frame.height
        );
    }
    let mut data = Vec::new();
    grey_box(frame, area, &mut data);
    Grey::new(data, x1 - x0, y1 - y0)
}

/// The best placement of a template in a window and its correlation (−1..=1; 0 where the
/// window's or the template's pixels are all alike).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Match {
    pub x: usize,
    pub y: usize,
    pub score: f64,
}

/// Where `template` matches `window` best (the first such placement in row-major order, as
/// OpenCV's `minMaxLoc` reports it); an error when the template is larger than the window.
pub fn best_match(window: &Grey, template: &Grey) -> Result<Match> {
    if template.width > window.width || template.height > window.height {
        return invalid!(
            "a {}x{} template does not fit a {}x{} window",
            template.width,
            template.height,
            window.width,
            window.height
        );
    }
    Ok(candidates(window, template)[0])
}

/// The best placement and, best first, up to [`CANDIDATES`] − 1 others nearly as good
/// (within [`GAP`] of it) and apart from those before them; with many placements, from the
/// candidates of the halved images, each refined at full size.
fn candidates(window: &Grey, template: &Grey) -> Vec<Match> {
    let (nx, ny) = (
        window.width - template.width + 1,
        window.height - template.height + 1,
    );
    let scorer = Scorer::new(window, template);
    let mut scored = Vec::new();
    if nx * ny > COARSE_PLACEMENTS && template.width.min(template.height) >= 2 * MIN_SIDE {
        let mut seen = vec![false; nx * ny];
        for c in candidates(&window.halved(), &template.halved()) {
            let (cx, cy) = (2 * c.x, 2 * c.y);
            for y in cy.saturating_sub(REFINE)..=(cy + REFINE).min(ny - 1) {
                for x in cx.saturating_sub(REFINE)..=(cx + REFINE).min(nx - 1) {
                    if !std::mem::replace(&mut seen[y * nx + x], true) {
                        scored.push(scorer.scored(x, y));
                    }
                }
            }
        }
    } else {
        for y in 0..ny {
            for x in 0..nx {
                scored.push(scorer.scored(x, y));
            }
        }
    }
    // Best first; of equal scores, the first in row-major order.
    scored.sort_by(|a, b| {
        b.score
            .total_cmp(&a.score)
            .then((a.y, a.x).cmp(&(b.y, b.x)))
    });
    let mut kept: Vec<Match> = Vec::with_capacity(CANDIDATES);
    for m in scored {
        if kept.len() == CANDIDATES || m.score < kept.first().map_or(m.score, |b| b.score) - GAP {
            break;
        }
        if kept
            .iter()
            .all(|k| k.x.abs_diff(m.x) > 1 || k.y.abs_diff(m.y) > 1)
        {
            kept.push(m);
        }
    }
    kept
}

/// The correlation of a template at placements in a window. The sums are integers, and exact
/// in f64 up to templates of 370,000 pixels (n·ΣTW ≤ 255²·n² < 2⁵³).
struct Scorer {
    /// The template's pixels, the sum of its levels and n·Σ(T − T̄)².
    n: f64,
    st: f64,
    t_var: f64,
    /// The template's rows widened and padded with zeros to whole chunks, and the window's rows
    /// padded alike, so that every dot product runs over whole chunks.
    t16: Vec<i16>,
    padded: usize,
    rows: usize,
    w8: Vec<u8>,
    stride: usize,
    integral: Integral,
    size: [usize; 2],
}

impl Scorer {
    fn new(window: &Grey, template: &Grey) -> Self {
        let (tw, th) = (template.width, template.height);
        let n = (tw * th) as f64;
        let (st, stt) = sums(&template.data);
        let padded = tw.div_ceil(CHUNK) * CHUNK;
        let mut t16 = vec![0i16; th * padded];
        for (row, out) in template
            .data
            .chunks_exact(tw)
            .zip(t16.chunks_exact_mut(padded))
        {
            for (o, &v) in out.iter_mut().zip(row) {
                *o = v as i16;
            }
        }
        let stride = window.width + padded;
        let mut w8 = vec![0u8; window.height * stride];
        for (row, out) in window
            .data
            .chunks_exact(window.width)
            .zip(w8.chunks_exact_mut(stride))
        {
            out[..window.width].copy_from_slice(row);
        }
        Self {
            n,
            st: st as f64,
            t_var: n * stt as f64 - (st * st) as f64,
            t16,
            padded,
            rows: th,
            w8,
            stride,
            integral: Integral::new(window),
            size: [tw, th],
        }
    }

    /// The placement (x, y) and its correlation.
    fn scored(&self, x: usize, y: usize) -> Match {
        let w8 = &self.w8[y * self.stride + x..];
        let stw = correlation(&self.t16, self.padded, self.rows, w8, self.stride) as f64;
        let (sw, sww) = self.integral.sums(x, y, self.size[0], self.size[1]);
        let num = self.n * stw - self.st * sw as f64;
        let w_var = self.n * sww as f64 - (sw * sw) as f64;
        let t = (w_var * self.t_var).sqrt();
        let score = if t > 0.0 {
            (num / t).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        Match { x, y, score }
    }
}

/// (Σv, Σv²) of grey levels.
fn sums(values: &[u8]) -> (i64, i64) {
    values.iter().fold((0, 0), |(s, ss), &v| {
        let v = v as i64;
        (s + v, ss + v * v)
    })
}

/// Summed-area tables of a window's levels and squared levels.
struct Integral {
    stride: usize,
    sum: Vec<i64>,
    sq: Vec<i64>,
}

impl Integral {
    fn new(g: &Grey) -> Self {
        let stride = g.width + 1;
        let (mut sum, mut sq) = (
            vec![0i64; stride * (g.height + 1)],
            vec![0i64; stride * (g.height + 1)],
        );
        for y in 0..g.height {
            let (mut row_sum, mut row_sq) = (0i64, 0i64);
            for (x, &v) in g.row(y).iter().enumerate() {
                row_sum += v as i64;
                row_sq += v as i64 * v as i64;
                let at = (y + 1) * stride + x + 1;
                sum[at] = sum[at - stride] + row_sum;
                sq[at] = sq[at - stride] + row_sq;
            }
        }
        Self { stride, sum, sq }
    }

    /// (Σv, Σv²) over the w×h block from (x, y).
    fn sums(&self, x: usize, y: usize, w: usize, h: usize) -> (i64, i64) {
        let s = self.stride;
        let block = |t: &[i64]| {
            t[(y + h) * s + x + w] - t[y * s + x + w] - t[(y + h) * s + x] + t[y * s + x]
        };
        (block(&self.sum), block(&self.sq))
    }
}

/// Σ T·W over the template's `rows` rows (`t16`, rows of `padded` values, zero past its width)
/// and the window's rows from `w8` (rows `stride` apart, at least `padded` values each).
fn correlation(t16: &[i16], padded: usize, rows: usize, w8: &[u8], stride: usize) -> i64 {
    assert!(t16.len() >= rows * padded && w8.len() >= (rows - 1) * stride + padded);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present and the sizes are checked above.
        return unsafe { correlation_avx2(t16, padded, rows, w8, stride) };
    }
    (0..rows)
        .map(|r| {
            let (t, w) = (&t16[r * padded..][..padded], &w8[r * stride..][..padded]);
            t.iter()
                .zip(w)
                .map(|(&a, &b)| a as i64 * b as i64)
                .sum::<i64>()
        })
        .sum()
}

/// [`correlation`], sixteen products at a time: each 32-bit lane adds pairs of products
/// (at most 2·255² each) and is moved into the 64-bit total before it could overflow.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn correlation_avx2(
    t16: &[i16],
    padded: usize,
    rows: usize,
    w8: &[u8],
    stride: usize,
) -> i64 {
    use std::arch::x86_64::*;
    const FLUSH: usize = 8192; // steps: 8192 · 2 · 255² < 2³¹
    let flush = |acc: __m256i| -> i64 {
        let mut lanes = [0i32; 8];
        _mm256_storeu_si256(lanes.as_mut_ptr() as *mut __m256i, acc);
        lanes.iter().map(|&v| v as i64).sum()
    };
    let (mut total, mut acc, mut steps) = (0i64, _mm256_setzero_si256(), 0);
    for r in 0..rows {
        let (t, w) = (t16.as_ptr().add(r * padded), w8.as_ptr().add(r * stride));
        for k in (0..padded).step_by(CHUNK) {
            let a = _mm256_loadu_si256(t.add(k) as *const __m256i);
            let b = _mm256_cvtepu8_epi16(_mm_loadu_si128(w.add(k) as *const __m128i));
            acc = _mm256_add_epi32(acc, _mm256_madd_epi16(a, b));
            steps += 1;
            if steps == FLUSH {
                (total, acc, steps) = (total + flush(acc), _mm256_setzero_si256(), 0);
            }
        }
    }
    total + flush(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth, textured w×h grey image, its pattern shifted by (dx, dy) pixels.
    fn texture(w: usize, h: usize, dx: f64, dy: f64) -> Grey {
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - dx, (i / w) as f64 - dy);
                let g = 128.0
                    + 60.0 * (x / 5.0).sin() * (y / 7.0).cos()
                    + 40.0 * ((x + 2.0 * y) / 13.0).sin();
                g.round().clamp(0.0, 255.0) as u8
            })
            .collect();
        Grey::new(data, w, h).unwrap()
    }

    fn crop(g: &Grey, x: usize, y: usize, w: usize, h: usize) -> Grey {
        let data = (y..y + h)
            .flat_map(|r| g.row(r)[x..x + w].iter().copied())
            .collect();
        Grey::new(data, w, h).unwrap()
    }

    /// OpenCV's score, in floating point, at one placement.
    fn score(window: &Grey, template: &Grey, x: usize, y: usize) -> f64 {
        let t: Vec<f64> = template.data.iter().map(|&v| v as f64).collect();
        let w: Vec<f64> = crop(window, x, y, template.width, template.height)
            .data
            .iter()
            .map(|&v| v as f64)
            .collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (mt, mw) = (mean(&t), mean(&w));
        let num: f64 = t.iter().zip(&w).map(|(a, b)| (a - mt) * (b - mw)).sum();
        let norm = |v: &[f64], m: f64| v.iter().map(|a| (a - m) * (a - m)).sum::<f64>().sqrt();
        num / (norm(&t, mt) * norm(&w, mw))
    }

    #[test]
    fn scores_every_placement_as_the_normalised_cross_correlation() {
        let window = texture(40, 30, 0.0, 0.0);
        let template = crop(&texture(40, 30, 1.0, 2.0), 10, 8, 17, 11);
        for (x, y) in [(0, 0), (3, 5), (23, 19), (11, 6)] {
            let got = Scorer::new(&window, &template).scored(x, y);
            let want = score(&window, &template, x, y);
            assert!(
                (got.score - want).abs() < 1e-12,
                "({x}, {y}): {got:?} vs {want}"
            );
        }
        // The template's pattern came from (9, 6) of the window's.
        assert_eq!(
            best_match(&window, &template).map(|m| (m.x, m.y)),
            Ok((9, 6))
        );
    }

    #[test]
    fn coarse_to_fine_finds_the_peak_of_a_wide_search() {
        let window = texture(160, 120, 0.0, 0.0);
        for (x, y) in [(37, 52), (0, 0), (100, 71), (63, 8)] {
            let template = crop(&window, x, y, 60, 49);
            let found = best_match(&window, &template).unwrap();
            assert_eq!((found.x, found.y), (x, y));
            assert!((found.score - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_flat_window_or_template_scores_zero() {
        let flat = Grey::new(vec![90; 12 * 10], 12, 10).unwrap();
        let template = crop(&texture(12, 10, 0.0, 0.0), 2, 2, 5, 4);
        assert_eq!(best_match(&flat, &template).unwrap().score, 0.0);
        assert_eq!(
            best_match(&texture(12, 10, 0.0, 0.0), &crop(&flat, 0, 0, 5, 4))
                .unwrap()
                .score,
            0.0
        );
    }

    #[test]
    fn the_avx2_correlation_equals_the_plain_sum() {
        let (t, w) = (texture(37, 9, 0.0, 0.0), texture(80, 9, 3.0, 1.0));
        let padded = 48;
        let mut t16 = vec![0i16; 9 * padded];
        for (row, out) in t.data.chunks_exact(37).zip(t16.chunks_exact_mut(padded)) {
            for (o, &v) in out.iter_mut().zip(row) {
                *o = v as i16;
            }
        }
        let plain: i64 = (0..9)
            .flat_map(|r| (0..37).map(move |c| (r, c)))
            .map(|(r, c)| t.data[r * 37 + c] as i64 * w.data[r * 80 + 5 + c] as i64)
            .sum();
        assert_eq!(correlation(&t16, padded, 9, &w.data[5..], 80), plain);
    }

    #[test]
    fn grey_areas_are_the_frames_grey_levels() {
        let rgb: Vec<u8> = (0..8 * 6 * 3).map(|i| (i * 37 % 256) as u8).collect();
        let frame = ImageRef::named("frame", &rgb, 8, 6, 3).unwrap();
        let area = grey_area(&frame, [1, 2, 8, 6]).unwrap();
        assert_eq!((area.width, area.height), (7, 4));
        let p = &rgb[(2 * 8 + 1) * 3..][..3];
        let grey =
            (9798 * p[0] as u32 + 19235 * p[1] as u32 + 3735 * p[2] as u32 + (1 << 14)) >> 15;
        assert_eq!(area.data[0] as u32, grey);
        assert!(grey_area(&frame, [1, 1, 9, 6]).is_err());
        assert!(grey_area(&frame, [4, 1, 4, 6]).is_err());
        let two = ImageRef::named("frame", &rgb[..8 * 6 * 2], 8, 6, 2).unwrap();
        assert!(grey_area(&two, [0, 0, 4, 4]).is_err());
    }

    #[test]
    fn halving_takes_block_means() {
        let g = texture(7, 5, 0.0, 0.0);
        let half = g.halved();
        assert_eq!((half.width, half.height), (3, 2));
        let sum: u32 = [g.data[16], g.data[17], g.data[23], g.data[24]]
            .iter()
            .map(|&v| v as u32)
            .sum();
        assert_eq!(half.data[4] as u32, (sum + 2) / 4);
    }

    #[test]
    fn refuses_a_template_larger_than_the_window() {
        let (w, t) = (texture(20, 10, 0.0, 0.0), texture(10, 11, 0.0, 0.0));
        assert!(best_match(&w, &t).is_err());
        assert!(Grey::new(vec![1, 2, 3], 2, 2).is_err());
    }
}
