//! The Gaussian pyramid of one frame's crop for the Lucas-Kanade flow ([`super`]), built from
//! grey or RGB pixels (RGB converted to grey as OpenCV's `cvtColor(RGB2GRAY)` does, exactly).
//!
//! Level 0, the crop itself, is read only by windows around the tracked points, so its samples
//! are filled in [`TILE`]-pixel tiles the first time a window reaches them. Level 1 is summed
//! from the crop's grey levels in integers; the coarser levels from the level below in floats.
//! Every level holds the values an eagerly built float pyramid holds, bit for bit.
//!
//! Coordinates: a pyramid covers a crop of the frame whose top-left pixel is `origin`; level L
//! holds the crop at 1/2^L scale, level-L pixel i lying on level-0 pixel 2^L·i, so a frame
//! point p is at (p − origin)/2^L on level L. Intensities are grey levels (0..=255).

use super::floor;
use super::kernels::{Grid, Shape};
use crate::border::reflect101;
use crate::error::Result;
use crate::grey::grey_box;
use crate::invalid;
use crate::raster::ImageRef;

/// Side of the square tiles of level 0's padded plane, filled as windows reach them (pixels).
const TILE: usize = 32;

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
                // One reflection reaches: the common case, each side a reversed copy of the
                // interior beside it (apart, so that the copies vectorise).
                let (left, rest) = row.split_at_mut(p);
                let (interior, right) = rest.split_at_mut(w);
                for (d, v) in left.iter_mut().zip(interior[1..=p].iter().rev()) {
                    *d = *v;
                }
                for (d, v) in right
                    .iter_mut()
                    .zip(interior[w - 1 - p..w - 1].iter().rev())
                {
                    *d = *v;
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
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 is present.
            return unsafe { self.down_avx2(next, col) };
        }
        self.down_body(next, col)
    }

    /// [`Level::down`] compiled for AVX2: the same operations, eight columns at a time.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn down_avx2(&self, next: &mut Level, col: &mut Vec<f32>) {
        self.down_body(next, col)
    }

    #[inline(always)]
    fn down_body(&self, next: &mut Level, col: &mut Vec<f32>) {
        let (s, p) = (self.stride(), self.pad);
        col.resize(s, 0.0);
        // The columns the sums at even pixels read: p − 2 ..= p + 2·next.width.
        let (c0, c1) = (p - 2, (p + 2 * next.width + 1).min(s));
        for y in 0..next.height {
            let rows: [&[f32]; 5] =
                std::array::from_fn(|j| &self.img[(2 * y + j + p - 2) * s..][c0..c1]);
            for (x, c) in col[c0..c1].iter_mut().enumerate() {
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

/// Level 1's column sums at their even and at their odd positions apart (scratch of
/// [`down_gray`]), so that the 5-tap sums at even positions read their taps contiguously, which
/// vectorises where the strided reads did not.
#[derive(Default)]
struct Halves {
    even: Vec<u16>,
    odd: Vec<u16>,
}

impl Halves {
    /// The taps of the 5-tap sums at positions 0, 2, .., 2(n − 1) of `row` (2n + 4 values):
    /// for output x, `row[2x ..= 2x + 4]` is (e0[x], o0[x], e1[x], o1[x], e2[x]).
    #[inline(always)]
    fn taps(&mut self, row: &[u16], n: usize) -> [&[u16]; 5] {
        self.even.resize(n + 2, 0);
        self.odd.resize(n + 2, 0);
        for ((e, o), pair) in self
            .even
            .iter_mut()
            .zip(&mut self.odd)
            .zip(row.chunks_exact(2))
        {
            (*e, *o) = (pair[0], pair[1]);
        }
        let (e, o) = (&self.even[..n + 2], &self.odd[..n + 2]);
        [&e[..n], &e[1..n + 1], &e[2..], &o[..n], &o[1..n + 1]]
    }
}

/// The Gaussian pyramid of one frame's crop, for a fixed window size. Rebuilding it for
/// another frame reuses its memory.
pub struct Pyramid {
    pub(super) origin: [f64; 2],
    pub(super) window: usize,
    pub(super) depth: usize,
    /// The crop's grey levels, row-major, level 0's width per row.
    gray: Vec<u8>,
    /// Per tile of level 0's padded plane, row by row: whether it holds its samples.
    filled: Vec<bool>,
    tiles_across: usize,
    levels: Vec<Level>,
    /// Scratch rows of the reductions: level 1's integer column sums (and their even and odd
    /// columns apart), the others' float ones.
    sums: Vec<u16>,
    halves: Halves,
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
            gray: Vec::new(),
            filled: Vec::new(),
            tiles_across: 0,
            levels: Vec::new(),
            sums: Vec::new(),
            halves: Halves::default(),
            scratch: Vec::new(),
        })
    }

    /// [`Pyramid::new`] then [`Pyramid::rebuild`].
    pub fn build(
        frame: &ImageRef,
        crop: [usize; 4],
        max_level: usize,
        window: usize,
    ) -> Result<Self> {
        let mut p = Self::new(window)?;
        p.rebuild(frame, crop, max_level)?;
        Ok(p)
    }

    /// Builds the pyramid of the crop `[x0, x1)×[y0, y1)` of a grey (1 channel) or RGB (3
    /// channels) `frame`, with at most `max_level` levels above the crop itself. Like OpenCV,
    /// it stops before a level whose width or height would not exceed the window.
    pub fn rebuild(&mut self, frame: &ImageRef, crop: [usize; 4], max_level: usize) -> Result<()> {
        let [x0, y0, x1, y1] = crop;
        let (width, height) = (frame.width, frame.height);
        if frame.channels != 1 && frame.channels != 3 {
            return invalid!(
                "the flow takes grey or RGB frames, got {} channels",
                frame.channels
            );
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
        let (w, h) = sizes[0];
        grey_box(frame, crop, &mut self.gray);
        let base = &mut self.levels[0];
        if cfg!(debug_assertions) {
            // A sample read before its tile is filled shows as NaN.
            base.img.fill(f32::NAN);
        }
        self.tiles_across = base.stride().div_ceil(TILE);
        self.filled.clear();
        self.filled
            .resize(self.tiles_across * (h + 2 * pad).div_ceil(TILE), false);
        if sizes.len() > 1 {
            down_gray(
                &self.gray,
                w,
                &mut self.levels[1],
                (&mut self.sums, &mut self.halves),
            );
            self.levels[1].mirror();
        }
        for l in 2..sizes.len() {
            let (done, rest) = self.levels.split_at_mut(l);
            done[l - 1].down(&mut rest[0], &mut self.scratch);
            rest[0].mirror();
        }
        self.origin = [x0 as f64, y0 as f64];
        self.depth = sizes.len();
        Ok(())
    }

    /// The crop's grey levels (row-major) and the crop [x0, y0, x1, y1) (frame pixels,
    /// exclusive ends); empty before the first build.
    pub fn grey_levels(&self) -> (&[u8], [usize; 4]) {
        let (w, h) = self.levels.first().map_or((0, 0), |l| (l.width, l.height));
        let [x0, y0] = self.origin.map(|v| v as usize);
        (&self.gray, [x0, y0, x0 + w, y0 + h])
    }

    /// Number of levels above the crop itself (0 also before the first build).
    pub fn max_level(&self) -> usize {
        self.depth.saturating_sub(1)
    }

    /// Whether a window with top-left level point `corner` may be sampled on `level` (OpenCV's
    /// test: the corner's integer part in [−window, size)).
    pub(super) fn inside(&self, level: usize, corner: [f32; 2]) -> bool {
        let l = &self.levels[level];
        let lo = -(self.window as f32);
        let (x, y) = (floor(corner[0]), floor(corner[1]));
        x >= lo && y >= lo && x < l.width as f32 && y < l.height as f32
    }

    /// The bilinear samples of `level` on the unit grid whose top-left sample is the level
    /// point (x, y), with the `block` (columns, rows) of plane values from that sample's integer
    /// part on filled; the block must fit in the padded plane (see [`Pyramid::inside`]).
    /// Inlined into the flow's iterations: about 1% of the tracker's time, measured.
    #[inline(always)]
    pub(super) fn grid(&mut self, level: usize, x: f32, y: f32, block: [usize; 2]) -> Grid<'_> {
        if level == 0 {
            let p = self.levels[0].pad as isize;
            let (cx, cy) = (
                (floor(x) as isize + p) as usize,
                (floor(y) as isize + p) as usize,
            );
            for ty in cy / TILE..=(cy + block[1] - 1) / TILE {
                for tx in cx / TILE..=(cx + block[0] - 1) / TILE {
                    if !self.filled[ty * self.tiles_across + tx] {
                        self.fill_tile(tx, ty);
                    }
                }
            }
        }
        self.levels[level].grid(x, y)
    }

    /// Level 0's samples in tile (`tx`, `ty`) of its padded plane, from the crop's grey levels
    /// (mirrored into the padding).
    fn fill_tile(&mut self, tx: usize, ty: usize) {
        self.filled[ty * self.tiles_across + tx] = true;
        let base = &mut self.levels[0];
        let (s, p, h) = (base.stride(), base.pad, base.height);
        let tile = Tile {
            pad: p,
            rows: [ty * TILE, ((ty + 1) * TILE).min(h + 2 * p)],
            cols: [tx * TILE, ((tx + 1) * TILE).min(s)],
        };
        fill(&self.gray, base.width, tile, &mut base.img);
    }

    /// Frame point → level point.
    pub(super) fn to_level(&self, p: [f64; 2], level: usize) -> [f64; 2] {
        let s = (1u64 << level) as f64;
        [(p[0] - self.origin[0]) / s, (p[1] - self.origin[1]) / s]
    }

    /// Level point → frame point.
    pub(super) fn to_frame(&self, q: [f64; 2], level: usize) -> [f64; 2] {
        let s = (1u64 << level) as f64;
        [q[0] * s + self.origin[0], q[1] * s + self.origin[1]]
    }
}

/// A block of a level's padded plane: its rows and columns (padded-plane indices, ends
/// exclusive) and the padding's width.
#[derive(Clone, Copy)]
struct Tile {
    pad: usize,
    rows: [usize; 2],
    cols: [usize; 2],
}

/// The `tile` of a `plane` padded around `gray` (rows of `w`) filled with its grey levels as
/// floats, mirrored into the padding.
fn fill(gray: &[u8], w: usize, tile: Tile, plane: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present.
        return unsafe { fill_avx2(gray, w, tile, plane) };
    }
    fill_body(gray, w, tile, plane)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn fill_avx2(gray: &[u8], w: usize, tile: Tile, plane: &mut [f32]) {
    fill_body(gray, w, tile, plane)
}

#[inline(always)]
fn fill_body(gray: &[u8], w: usize, tile: Tile, plane: &mut [f32]) {
    let (p, h) = (tile.pad, gray.len() / w);
    let s = w + 2 * p;
    let [c0, c1] = tile.cols;
    let (inner0, inner1) = (c0.clamp(p, p + w), c1.clamp(p, p + w));
    for r in tile.rows[0]..tile.rows[1] {
        let src = &gray[reflect101(r as isize - p as isize, h) * w..][..w];
        let row = &mut plane[r * s..][..s];
        for (d, &g) in row[inner0..inner1]
            .iter_mut()
            .zip(&src[inner0 - p..inner1 - p])
        {
            *d = g as f32;
        }
        for c in (c0..inner0).chain(inner1..c1) {
            row[c] = src[reflect101(c as isize - p as isize, w)] as f32;
        }
    }
}

/// Level 1 into `next` (shaped, its padding not filled) from the crop's grey levels `gray`
/// (rows of `w`): [`Level::down`] of level 0, summed in integers, which is exact (a sum is at
/// most 255·256) and so gives the same values. `scratch` is the column sums and their halves.
fn down_gray(gray: &[u8], w: usize, next: &mut Level, scratch: (&mut Vec<u16>, &mut Halves)) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present.
        return unsafe { down_gray_avx2(gray, w, next, scratch) };
    }
    down_gray_body(gray, w, next, scratch)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn down_gray_avx2(
    gray: &[u8],
    w: usize,
    next: &mut Level,
    scratch: (&mut Vec<u16>, &mut Halves),
) {
    down_gray_body(gray, w, next, scratch)
}

#[inline(always)]
fn down_gray_body(
    gray: &[u8],
    w: usize,
    next: &mut Level,
    (sums, halves): (&mut Vec<u16>, &mut Halves),
) {
    let h = gray.len() / w;
    let n = next.width;
    // Column sums with two mirrored columns on either side (and, for an odd width, one more
    // that no output reads).
    sums.resize(2 * n + 4, 0);
    for y in 0..next.height {
        let rows: [&[u8]; 5] =
            std::array::from_fn(|j| &gray[reflect101((2 * y + j) as isize - 2, h) * w..][..w]);
        for (x, c) in sums[2..w + 2].iter_mut().enumerate() {
            let v = |j: usize| rows[j][x] as u16;
            *c = v(0) + v(4) + 4 * (v(1) + v(3)) + 6 * v(2);
        }
        for i in 0..2 {
            sums[i] = sums[2 + reflect101(i as isize - 2, w)];
            sums[w + 2 + i] = sums[2 + reflect101((w + i) as isize, w)];
        }
        let row = next.interior_row(y);
        let [e0, e1, e2, o0, o1] = halves.taps(sums, row.len());
        for x in 0..row.len() {
            let v = e0[x] + e2[x] + 4 * (o0[x] + o1[x]) + 6 * e1[x];
            row[x] = v as f32 / 256.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flow::tests::texture;

    /// The planes of an eagerly built float pyramid of a grey image's crop: level 0 the crop's
    /// grey levels, mirrored; each level above [`Level::down`] of the one below.
    fn eager(img: &[u8], w: usize, crop: [usize; 4], depth: usize, pad: usize) -> Vec<Vec<f32>> {
        let [x0, y0, x1, y1] = crop;
        let mut levels: Vec<Level> = (0..depth).map(|_| Level::default()).collect();
        let (mut cw, mut ch) = (x1 - x0, y1 - y0);
        for level in &mut levels {
            level.reshape(cw, ch, pad);
            (cw, ch) = (cw.div_ceil(2), ch.div_ceil(2));
        }
        for y in 0..y1 - y0 {
            let src = &img[(y0 + y) * w + x0..][..x1 - x0];
            for (d, &g) in levels[0].interior_row(y).iter_mut().zip(src) {
                *d = g as f32;
            }
        }
        levels[0].mirror();
        let mut col = Vec::new();
        for l in 1..depth {
            let (done, rest) = levels.split_at_mut(l);
            done[l - 1].down(&mut rest[0], &mut col);
            rest[0].mirror();
        }
        levels.into_iter().map(|l| l.img).collect()
    }

    #[test]
    fn every_level_holds_the_values_of_an_eagerly_built_float_pyramid() {
        let (w, h) = (203, 151);
        let img = texture(w, h, 0.3, 0.0);
        let frame = ImageRef::named("frame", &img, w, h, 1).unwrap();
        // The whole image, an odd crop, and one narrower than the padding.
        for crop in [[0, 0, w, h], [7, 12, 190, 149], [100, 40, 118, 140]] {
            let mut p = Pyramid::build(&frame, crop, 5, 11).unwrap();
            for ty in 0..p.filled.len() / p.tiles_across {
                for tx in 0..p.tiles_across {
                    p.fill_tile(tx, ty);
                }
            }
            let want = eager(&img, w, crop, p.depth, p.levels[0].pad);
            assert!(p.depth >= 2 || crop[2] - crop[0] < 30, "{crop:?}");
            for (l, plane) in want.iter().enumerate() {
                assert_eq!(&p.levels[l].img, plane, "level {l} of crop {crop:?}");
            }
        }
    }

    #[test]
    fn an_rgb_frame_builds_the_pyramid_of_its_grey_levels() {
        let (w, h) = (96, 80);
        let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i * 7919 % 251) as u8).collect();
        let grey: Vec<u8> = rgb
            .chunks_exact(3)
            .map(|p| {
                let v = 9798 * p[0] as u32 + 19235 * p[1] as u32 + 3735 * p[2] as u32 + (1 << 14);
                (v >> 15) as u8
            })
            .collect();
        let mut converted = vec![0u8; w * h];
        crate::grey::rgb_to_gray(&rgb, &mut converted);
        assert_eq!(converted, grey);
        let crop = [5, 3, 91, 77];
        let mut a = Pyramid::build(&ImageRef::named("rgb", &rgb, w, h, 3).unwrap(), crop, 2, 9);
        let b = Pyramid::build(
            &ImageRef::named("grey", &grey, w, h, 1).unwrap(),
            crop,
            2,
            9,
        );
        let (a, b) = (a.as_mut().unwrap(), b.unwrap());
        assert_eq!((a.gray.as_slice(), a.depth), (b.gray.as_slice(), b.depth));
        assert_eq!(a.levels[1].img, b.levels[1].img);
    }
}
