//! Corners to follow: OpenCV's `goodFeaturesToTrack` with its minimum-eigenvalue measure
//! (Shi-Tomasi), over a masked box of a grey image. The measure is computed from integer Sobel
//! derivatives and integer block sums, so it is exact up to one square root, the same on every
//! machine (OpenCV's single-precision sums depend on where its box starts).
//!
//! Pixels are (x, y) of the whole frame, centres on integers; intensities are grey levels.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::border::reflect101;
use crate::error::Result;
use crate::invalid;

/// The largest block: its sums of squared Sobel derivatives (at most 1020² each) fit in i32.
const MAX_BLOCK: usize = 31;

/// What [`good_features`] keeps.
#[derive(Clone, Copy, Debug)]
pub struct CornerSettings {
    /// Corners at most, strongest first (0: no limit).
    pub max_corners: usize,
    /// A corner's measure must exceed this fraction of the strongest one's in the mask.
    pub quality: f64,
    /// No two corners closer than this (pixels).
    pub min_distance: f64,
    /// Odd side of the square over which the derivatives' products are summed (pixels), at
    /// most 31.
    pub block: usize,
}

/// The corners, as OpenCV's `goodFeaturesToTrack(gray[y0:y1, x0:x1], max_corners, quality,
/// min_distance, mask, block)` finds them, moved into frame pixels: the pixels of `mask`
/// (row-major over the `box` = [x0, y0, x1, y1), exclusive ends; nonzero: allowed), off the
/// box's outermost ring, whose minimum eigenvalue of the summed gradient products is above
/// `quality` times the mask's largest and the largest in their 3×3 neighbourhood, strongest
/// first (ties: the later pixel in row-major order first), each dropped when within
/// `min_distance` of one kept before. Like OpenCV on a box of an image, the derivatives and
/// their block sums read the box alone, mirrored at its edges. `gray` is a row-major
/// `width`×`height` grey image.
pub fn good_features(
    gray: &[u8],
    width: usize,
    height: usize,
    area: [usize; 4],
    mask: &[u8],
    s: &CornerSettings,
) -> Result<Vec<[f32; 2]>> {
    let [x0, y0, x1, y1] = area;
    if gray.len() != width * height {
        return invalid!("the image has {} pixels, not {width}×{height}", gray.len());
    }
    if x0 >= x1 || y0 >= y1 || x1 > width || y1 > height {
        return invalid!("box {area:?} is empty or outside the {width}×{height} image");
    }
    let (bw, bh) = (x1 - x0, y1 - y0);
    if mask.len() != bw * bh {
        return invalid!(
            "the mask has {} pixels, not the box's {bw}×{bh}",
            mask.len()
        );
    }
    let usable = |v: f64| v.is_finite() && v >= 0.0;
    if s.block.is_multiple_of(2)
        || s.block > MAX_BLOCK
        || !usable(s.quality)
        || !usable(s.min_distance)
    {
        return invalid!(
            "bad corner settings {s:?}: the block must be odd and at most {MAX_BLOCK}, the rest \
             finite and not negative"
        );
    }
    let search = Search {
        gray,
        width,
        area,
        mask,
        settings: s,
    };
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present.
        return Ok(unsafe { corners_avx2(&search) });
    }
    Ok(corners(&search))
}

/// [`good_features`]'s checked arguments.
struct Search<'a> {
    gray: &'a [u8],
    width: usize,
    area: [usize; 4],
    mask: &'a [u8],
    settings: &'a CornerSettings,
}

/// [`corners`] compiled for AVX2: the same integer sums and f64 steps, so the same corners.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn corners_avx2(search: &Search) -> Vec<[f32; 2]> {
    corners(search)
}

/// [`good_features`] on checked arguments.
#[inline(always)]
fn corners(search: &Search) -> Vec<[f32; 2]> {
    let &Search {
        gray,
        width,
        area,
        mask,
        settings: s,
    } = search;
    let [x0, y0, x1, y1] = area;
    let (bw, bh) = (x1 - x0, y1 - y0);
    let measure = Measure {
        gray,
        width,
        origin: [x0, y0],
        size: [bw, bh],
        block: s.block,
    };
    // The measure on each band of the mask, grown by the 3×3 neighbourhood of the
    // local-maximum test (a band's pixels have all their neighbours in it).
    let mut bands: Vec<Band> = Vec::new();
    for b in mask_bands(mask, bw, bh) {
        let grown = [
            b[0].saturating_sub(1),
            b[1].saturating_sub(1),
            (b[2] + 1).min(bw),
            (b[3] + 1).min(bh),
        ];
        let eig = measure.min_eigen(grown);
        bands.push(Band {
            mask: b,
            grown,
            eig,
        });
    }
    let mut best = f64::NEG_INFINITY;
    for band in &bands {
        for y in band.mask[1]..band.mask[3] {
            let m = &mask[y * bw..][band.mask[0]..band.mask[2]];
            let e = &band.eig[band.at(band.mask[0], y)..][..m.len()];
            best = best.max(masked_max(m, e));
        }
    }
    let floor = best * s.quality;
    // Local maxima in the mask above the floor, off the box's outermost ring.
    let mut found: Vec<(f64, usize, usize)> = Vec::new();
    let mut peaks: Vec<bool> = Vec::new();
    for band in &mut bands {
        band.eig
            .iter_mut()
            .filter(|v| **v <= floor)
            .for_each(|v| *v = 0.0);
        let [gx0, gy0, gx1, _] = band.grown;
        let gw = gx1 - gx0;
        let (xa, xb) = (band.mask[0].max(1), band.mask[2].min(bw - 1));
        if xa >= xb {
            continue; // the band's mask lies on the ring
        }
        for y in band.mask[1].max(1)..band.mask[3].min(bh - 1) {
            // The band's rows y − 1, y, y + 1 from column xa − 1.
            let row = |y: usize| &band.eig[(y - gy0) * gw + xa - 1 - gx0..][..xb - xa + 2];
            let (above, here, below) = (row(y - 1), row(y), row(y + 1));
            let m = &mask[y * bw + xa..][..xb - xa];
            // Branch-free flags first (most pixels are not peaks), then the few peaks.
            peaks.clear();
            peaks.resize(m.len(), false);
            for (i, p) in peaks.iter_mut().enumerate() {
                let v = here[i + 1];
                let mut top = (v != 0.0) & (m[i] != 0);
                for r in [above, here, below] {
                    top &= (r[i] <= v) & (r[i + 1] <= v) & (r[i + 2] <= v);
                }
                *p = top;
            }
            for (i, _) in peaks.iter().enumerate().filter(|(_, &p)| p) {
                found.push((here[i + 1], xa + i, y));
            }
        }
    }
    // Strongest first, taken from a heap as far as `spaced` reads: most are never needed.
    let mut heap: BinaryHeap<Peak> = found.into_iter().map(Peak).collect();
    spaced(std::iter::from_fn(|| heap.pop().map(|p| p.0)), [bw, bh], s)
        .into_iter()
        .map(|[x, y]| [(x0 + x) as f32, (y0 + y) as f32])
        .collect()
}

/// The largest of `values` where `mask` is nonzero (−∞ for none), in independent lanes.
fn masked_max(mask: &[u8], values: &[f64]) -> f64 {
    let mut lanes = [f64::NEG_INFINITY; 4];
    for (m, v) in mask.chunks(4).zip(values.chunks(4)) {
        for k in 0..m.len() {
            if m[k] != 0 && v[k] > lanes[k] {
                lanes[k] = v[k];
            }
        }
    }
    lanes.into_iter().fold(f64::NEG_INFINITY, f64::max)
}

/// The measure over one band of the mask.
struct Band {
    /// [x0, y0, x1, y1) of the band's mask pixels (box coordinates).
    mask: [usize; 4],
    /// `mask` grown by 1 pixel, inside the box: where `eig` is.
    grown: [usize; 4],
    eig: Vec<f64>,
}

impl Band {
    /// Index in `eig` of box pixel (x, y).
    fn at(&self, x: usize, y: usize) -> usize {
        (y - self.grown[1]) * (self.grown[2] - self.grown[0]) + (x - self.grown[0])
    }
}

/// The indices of the first and the last nonzero byte of `row`, read 8 bytes at a time.
fn nonzero_ends(row: &[u8]) -> Option<[usize; 2]> {
    let mut ends: Option<[usize; 2]> = None;
    for (k, bytes) in row.chunks(8).enumerate() {
        let mut word = [0u8; 8];
        word[..bytes.len()].copy_from_slice(bytes);
        let v = u64::from_le_bytes(word);
        if v != 0 {
            let last = 8 * k + 7 - v.leading_zeros() as usize / 8;
            let first = ends.map_or(8 * k + v.trailing_zeros() as usize / 8, |e| e[0]);
            ends = Some([first, last]);
        }
    }
    ends
}

/// The bands of a `w`×`h` mask: for each run of rows with nonzero pixels, [x0, y0, x1, y1) of
/// those pixels.
fn mask_bands(mask: &[u8], w: usize, h: usize) -> Vec<[usize; 4]> {
    let mut out: Vec<[usize; 4]> = Vec::new();
    let mut open = false;
    for (y, row) in mask.chunks(w).take(h).enumerate() {
        let Some([first, last]) = nonzero_ends(row) else {
            open = false;
            continue;
        };
        match out.last_mut() {
            Some(b) if open => *b = [b[0].min(first), b[1], b[2].max(last + 1), y + 1],
            _ => out.push([first, y, last + 1, y + 1]),
        }
        open = true;
    }
    out
}

/// A local maximum (measure, x, y), ordered by its measure, then (ties) by its row-major
/// position, the later the greater.
struct Peak((f64, usize, usize));

impl Ord for Peak {
    fn cmp(&self, o: &Self) -> Ordering {
        let (a, b) = (&self.0, &o.0);
        a.0.total_cmp(&b.0).then((a.2, a.1).cmp(&(b.2, b.1)))
    }
}

impl PartialOrd for Peak {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl PartialEq for Peak {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

impl Eq for Peak {}

/// The corners of `found` (measure, x, y; strongest first) kept greedily in that order when
/// none kept before lies within `min_distance` (OpenCV's grid of cells of that side, rounded),
/// at most `max_corners` of them.
fn spaced(
    found: impl Iterator<Item = (f64, usize, usize)>,
    size: [usize; 2],
    s: &CornerSettings,
) -> Vec<[usize; 2]> {
    let limit = if s.max_corners == 0 {
        usize::MAX
    } else {
        s.max_corners
    };
    if s.min_distance < 1.0 {
        return found.take(limit).map(|(_, x, y)| [x, y]).collect();
    }
    let cell = s.min_distance.round_ties_even() as usize;
    let (gw, gh) = (size[0].div_ceil(cell), size[1].div_ceil(cell));
    let mut grid: Vec<Vec<[usize; 2]>> = vec![Vec::new(); gw * gh];
    let near = s.min_distance * s.min_distance;
    let mut kept = Vec::new();
    for (_, x, y) in found {
        let (cx, cy) = (x / cell, y / cell);
        let close = (cy.saturating_sub(1)..=(cy + 1).min(gh - 1)).any(|gy| {
            (cx.saturating_sub(1)..=(cx + 1).min(gw - 1)).any(|gx| {
                grid[gy * gw + gx].iter().any(|&[px, py]| {
                    let (dx, dy) = (x as f64 - px as f64, y as f64 - py as f64);
                    dx * dx + dy * dy < near
                })
            })
        });
        if !close {
            grid[cy * gw + cx].push([x, y]);
            kept.push([x, y]);
            if kept.len() == limit {
                break;
            }
        }
    }
    kept
}

/// The minimum-eigenvalue measure over a box of a frame.
struct Measure<'a> {
    gray: &'a [u8],
    /// Row length of `gray`.
    width: usize,
    origin: [usize; 2],
    size: [usize; 2],
    block: usize,
}

impl Measure<'_> {
    /// The measure at the box pixels of `[x0, y0, x1, y1)` (box coordinates), row-major:
    /// twice the smaller eigenvalue of the block sums of the Sobel products (dx², dx·dy, dy²;
    /// the box mirrored at its edges), in squared Sobel units.
    #[inline(always)]
    fn min_eigen(&self, [x0, y0, x1, y1]: [usize; 4]) -> Vec<f64> {
        let (r, b) = (self.block / 2, self.block);
        let (w, h) = (x1 - x0, y1 - y0);
        let (qw, qh) = (w + 2 * r, h + 2 * r);
        // Frame coordinates of box coordinate i − r and its two neighbours, along axis `at`.
        let frame = |at: usize, i: usize| {
            let size = self.size[at];
            let inside = reflect101(i as isize - r as isize, size) as isize;
            [-1, 0, 1].map(|d| self.origin[at] + reflect101(inside + d, size))
        };
        let cols: Vec<[usize; 3]> = (0..qw).map(|i| frame(0, x0 + i)).collect();
        // Frame columns c0 − 1 ..= c0 + qw in order, mirrored nowhere: the common case.
        let c0 = cols[0][1];
        let straight = cols
            .iter()
            .enumerate()
            .all(|(i, c)| *c == [c0 + i - 1, c0 + i, c0 + i + 1]);
        // Block sums along the rows, per product.
        let mut along = [vec![0i32; qh * w], vec![0i32; qh * w], vec![0i32; qh * w]];
        let mut line = [vec![0i32; qw], vec![0i32; qw], vec![0i32; qw]];
        for j in 0..qh {
            let [up, mid, down] =
                frame(1, y0 + j).map(|y| &self.gray[y * self.width..][..self.width]);
            let [xx, xy, yy] = &mut line;
            if straight {
                let n = qw + 2;
                let (u, m, d) = (
                    &up[c0 - 1..][..n],
                    &mid[c0 - 1..][..n],
                    &down[c0 - 1..][..n],
                );
                for i in 0..qw {
                    let g = |row: &[u8], k: usize| row[i + k] as i32;
                    let dx = g(u, 2) - g(u, 0) + 2 * (g(m, 2) - g(m, 0)) + g(d, 2) - g(d, 0);
                    let dy = g(d, 0) - g(u, 0) + 2 * (g(d, 1) - g(u, 1)) + g(d, 2) - g(u, 2);
                    (xx[i], xy[i], yy[i]) = (dx * dx, dx * dy, dy * dy);
                }
            } else {
                for (i, &[l, c, rt]) in cols.iter().enumerate() {
                    let g = |row: &[u8], x: usize| row[x] as i32;
                    let dx = g(up, rt) - g(up, l) + 2 * (g(mid, rt) - g(mid, l)) + g(down, rt)
                        - g(down, l);
                    let dy = g(down, l) - g(up, l) + 2 * (g(down, c) - g(up, c)) + g(down, rt)
                        - g(up, rt);
                    (xx[i], xy[i], yy[i]) = (dx * dx, dx * dy, dy * dy);
                }
            }
            for (sums, p) in along.iter_mut().zip(&line) {
                let out = &mut sums[j * w..][..w];
                out.copy_from_slice(&p[..w]);
                for k in 1..b {
                    out.iter_mut().zip(&p[k..k + w]).for_each(|(o, v)| *o += v);
                }
            }
        }
        // Then down the columns: the block's rows added as it moves down.
        let mut sums = [vec![0i32; w], vec![0i32; w], vec![0i32; w]];
        for (s, a) in sums.iter_mut().zip(&along) {
            for row in a[..(b - 1) * w].chunks(w) {
                s.iter_mut().zip(row).for_each(|(o, v)| *o += v);
            }
        }
        let mut out = vec![0.0f64; w * h];
        for y in 0..h {
            for (s, a) in sums.iter_mut().zip(&along) {
                s.iter_mut()
                    .zip(&a[(y + b - 1) * w..][..w])
                    .for_each(|(o, v)| *o += v);
            }
            let [xx, xy, yy] = &sums;
            for (x, o) in out[y * w..][..w].iter_mut().enumerate() {
                let (a, b, c) = (xx[x] as f64, xy[x] as f64, yy[x] as f64);
                *o = (a + c) - ((a - c) * (a - c) + 4.0 * b * b).sqrt();
            }
            for (s, a) in sums.iter_mut().zip(&along) {
                s.iter_mut()
                    .zip(&a[y * w..][..w])
                    .for_each(|(o, v)| *o -= v);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTINGS: CornerSettings = CornerSettings {
        max_corners: 0,
        quality: 0.01,
        min_distance: 5.0,
        block: 5,
    };

    /// A 60×50 image, dark, with bright filled rectangles [x0, y0, x1, y1).
    fn rectangles(rects: &[[usize; 4]]) -> Vec<u8> {
        let (w, h) = (60, 50);
        let mut img = vec![20u8; w * h];
        for &[x0, y0, x1, y1] in rects {
            for y in y0..y1 {
                img[y * w + x0..y * w + x1].fill(200);
            }
        }
        img
    }

    fn find(
        img: &[u8],
        area: [usize; 4],
        mask: Option<&[u8]>,
        s: &CornerSettings,
    ) -> Vec<[f32; 2]> {
        let n = (area[2] - area[0]) * (area[3] - area[1]);
        let all = vec![1u8; n];
        good_features(img, 60, 50, area, mask.unwrap_or(&all), s).unwrap()
    }

    #[test]
    fn finds_the_corners_of_a_rectangle_and_nothing_on_flat_ground() {
        let img = rectangles(&[[20, 15, 40, 35]]);
        let found = find(&img, [0, 0, 60, 50], None, &SETTINGS);
        assert_eq!(found.len(), 4, "{found:?}");
        for corner in [[20.0, 15.0], [39.0, 15.0], [20.0, 34.0], [39.0, 34.0]] {
            assert!(
                found
                    .iter()
                    .any(|p| (p[0] - corner[0]).abs() <= 1.0 && (p[1] - corner[1]).abs() <= 1.0),
                "{corner:?} not in {found:?}"
            );
        }
        let flat = vec![90u8; 60 * 50];
        assert!(find(&flat, [0, 0, 60, 50], None, &SETTINGS).is_empty());
    }

    #[test]
    fn keeps_the_strongest_first_spaced_and_inside_the_mask() {
        // Two rectangles, eight corners.
        let img = rectangles(&[[5, 8, 17, 20], [25, 10, 52, 40]]);
        let whole = |s: CornerSettings| find(&img, [0, 0, 60, 50], None, &s);
        let all = whole(SETTINGS);
        assert_eq!(all.len(), 8, "{all:?}");
        let two = whole(CornerSettings {
            max_corners: 2,
            ..SETTINGS
        });
        assert_eq!(two, all[..2]);
        let apart = whole(CornerSettings {
            min_distance: 10.0,
            ..SETTINGS
        });
        for (i, p) in apart.iter().enumerate() {
            for q in &apart[i + 1..] {
                assert!((p[0] - q[0]).hypot(p[1] - q[1]) >= 10.0, "{p:?} {q:?}");
            }
        }
        assert!(apart.len() < all.len());
        // The box's left half only, in frame pixels.
        let mut mask = vec![0u8; 50 * 56];
        for row in mask.chunks_mut(56) {
            row[..20].fill(255);
        }
        let left = find(&img, [2, 0, 58, 50], Some(&mask), &SETTINGS);
        assert_eq!(left.len(), 4);
        assert!(left.iter().all(|p| p[0] < 22.0), "{left:?}");
        // A mask on the box's outermost ring alone finds nothing.
        let mut ring = vec![0u8; 20 * 10];
        ring[..20].fill(1);
        ring.chunks_mut(20).for_each(|row| row[19] = 1);
        assert!(find(&img, [20, 10, 40, 20], Some(&ring), &SETTINGS).is_empty());
        let mut left_column = vec![0u8; 20 * 10];
        left_column.chunks_mut(20).for_each(|row| row[0] = 1);
        assert!(find(&img, [25, 5, 45, 15], Some(&left_column), &SETTINGS).is_empty());
    }

    #[test]
    fn refuses_bad_arguments() {
        let img = rectangles(&[]);
        let mask = vec![1u8; 10 * 10];
        let bad = |area, mask: &[u8], s: &CornerSettings| {
            good_features(&img, 60, 50, area, mask, s).is_err()
        };
        assert!(bad([0, 0, 10, 10], &mask[1..], &SETTINGS));
        assert!(bad([55, 0, 65, 10], &mask, &SETTINGS));
        assert!(bad([5, 5, 5, 15], &mask, &SETTINGS));
        assert!(bad(
            [0, 0, 10, 10],
            &mask,
            &CornerSettings {
                block: 4,
                ..SETTINGS
            }
        ));
        assert!(good_features(&img[1..], 60, 50, [0, 0, 10, 10], &mask, &SETTINGS).is_err());
    }
}
