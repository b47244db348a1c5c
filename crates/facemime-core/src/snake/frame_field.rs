//! Building a frame's [`Field`](super::Field) from RGB pixels: over a region of the frame, the
//! luma L = 0.299 R + 0.587 G + 0.114 B and the lip-sensitive colour channel C = R − G, each
//! smoothed by a Gaussian, their central differences, and the previous frame's smoothed luma.
//!
//! The filters match OpenCV's `GaussianBlur` (kernel side round(8σ + 1) | 1, taps normalised to
//! sum 1) and `Sobel(ksize=1, scale=0.5)`, both with BORDER_REFLECT_101 at the region's edges, to
//! within float rounding. Values are in 0..255 levels, derivatives in levels per pixel.

use super::field::FIELD_CHANNELS;
use crate::border::reflect101;
use crate::error::Result;
use crate::invalid;
use crate::raster::ImageRef;

/// Largest Gaussian σ (pixels) accepted.
pub const MAX_SIGMA: f64 = 16.0;

/// Writes into `out` the region `[x0, y0, x1, y1)` (pixels, exclusive ends) of `frame` as a
/// row-major (y1 − y0, x1 − x0, [`FIELD_CHANNELS`]) float32 field smoothed by a Gaussian of
/// `sigma` pixels. `frame` and `prev` are (H, W, 3) RGB; without `prev`, L′ = L. With `bands`,
/// frame rectangles `[bx0, by0, bx1, by1)`, only the region's pixels inside a band are computed
/// (the same values as without) and the others are set to 0: the snakes of a frame read two
/// bands, around the brows and around the mouth. `out` may hold anything before: the tracker
/// reuses one buffer frame after frame.
pub fn frame_field(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    bands: Option<&[[usize; 4]]>,
    out: &mut [f32],
) -> Result<()> {
    let colour = bands.map(|b| vec![true; b.len()]);
    let bands = bands.zip(colour.as_deref());
    field_into(frame, prev, region, sigma, bands, true, out)
}

/// [`frame_field`] with `bands`, for a reader that stays inside them (the solver of a frame,
/// whose bands' margins cover every knot's reach): the pixels outside the bands are left as
/// they were (NaN in debug builds, so that a read there shows), which saves zeroing the rows
/// between the brows and the mouth frame after frame. The colour derivatives are computed only
/// in the bands flagged in `colour` (one flag per band), and are 0 in the others: the brows'
/// curves do not weigh the colour channel.
pub(crate) fn band_field(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    (bands, colour): (&[[usize; 4]], &[bool]),
    out: &mut [f32],
) -> Result<()> {
    if colour.len() != bands.len() {
        return invalid!("{} colour flags for {} bands", colour.len(), bands.len());
    }
    field_into(
        frame,
        prev,
        region,
        sigma,
        Some((bands, colour)),
        false,
        out,
    )
}

/// [`frame_field`]: the colour derivatives computed in the bands flagged, the pixels outside
/// the bands set to 0 when `zero`.
fn field_into(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    bands: Option<(&[[usize; 4]], &[bool])>,
    zero: bool,
    out: &mut [f32],
) -> Result<()> {
    let size = field_shape(frame, prev, region, sigma)?.iter().product();
    if out.len() != size {
        return invalid!(
            "the field of region {region:?} has {size} values, its buffer {}",
            out.len()
        );
    }
    let [x0, y0, x1, y1] = region;
    // Per region row, the span of the bands (those flagged, with `only`) holding it.
    let spans = |only: bool| -> Vec<Span> {
        let Some((b, colour)) = bands else {
            return vec![[0, x1 - x0]; y1 - y0];
        };
        (y0..y1)
            .map(|y| {
                let mut span = NONE;
                for (&[bx0, by0, bx1, by1], &c) in b.iter().zip(colour) {
                    if (by0..by1).contains(&y) && (c || !only) {
                        join(&mut span, bx0.clamp(x0, x1) - x0, bx1.clamp(x0, x1) - x0);
                    }
                }
                span
            })
            .collect()
    };
    let rows = Rows {
        wanted: spans(false),
        colour: spans(true),
        zero,
    };
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: AVX-512F is present.
        unsafe { build_avx512(frame, prev, region, sigma, &rows, out) };
        return Ok(());
    } else if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present.
        unsafe { build_avx2(frame, prev, region, sigma, &rows, out) };
        return Ok(());
    }
    build(frame, prev, region, sigma, &rows, out);
    Ok(())
}

/// What [`build`] computes, per region row: the columns of every channel (`wanted`), those of
/// the colour derivatives among them (`colour`; 0 in the rest of `wanted`), and whether the
/// columns outside `wanted` are set to 0.
struct Rows {
    wanted: Vec<Span>,
    colour: Vec<Span>,
    zero: bool,
}

/// The columns `[c0, c1)` of one region row that a stage computes; empty when c0 ≥ c1.
type Span = [usize; 2];

const NONE: Span = [0, 0];

/// Grows `span` to cover the columns `[c0, c1)` too (one span per row: the smallest that
/// holds both).
fn join(span: &mut Span, c0: usize, c1: usize) {
    if c0 >= c1 {
        return;
    }
    *span = if span[0] >= span[1] {
        [c0, c1]
    } else {
        [span[0].min(c0), span[1].max(c1)]
    };
}

/// The spans each stage needs for the output spans `wanted` of a region `w` columns wide,
/// through the mirrored borders: (smoothed, blurred across, converted to planes).
fn needed(wanted: &[Span], radius: usize, w: usize) -> (Vec<Span>, Vec<Span>, Vec<Span>) {
    let h = wanted.len();
    let reach = |spans: &[Span], rows: usize, cols: usize| -> Vec<Span> {
        let mut out = vec![NONE; h];
        for (y, &[c0, c1]) in spans.iter().enumerate().filter(|(_, s)| s[0] < s[1]) {
            let (c0, c1) = (c0.saturating_sub(cols), (c1 + cols).min(w));
            for k in -(rows as isize)..=rows as isize {
                join(&mut out[reflect101(y as isize + k, h)], c0, c1);
            }
        }
        out
    };
    // The derivatives read one row and one column around each output pixel, the vertical
    // blur `radius` rows, the horizontal blur `radius` columns.
    let smoothed = reach(wanted, 1, 1);
    let across = reach(&smoothed, radius, 0);
    let planes = reach(&across, 0, radius);
    (smoothed, across, planes)
}

/// The (rows, columns, channels) shape of [`frame_field`]'s output, once its arguments are
/// checked.
pub fn field_shape(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
) -> Result<[usize; 3]> {
    if frame.channels != 3 {
        return invalid!("the frame must be RGB (3 channels), got {}", frame.channels);
    }
    if let Some(p) = prev {
        if (p.width, p.height, p.channels) != (frame.width, frame.height, 3) {
            return invalid!(
                "the previous frame must be {}x{} RGB like the frame, got {}x{}x{}",
                frame.width,
                frame.height,
                p.width,
                p.height,
                p.channels
            );
        }
    }
    let [x0, y0, x1, y1] = region;
    if x1 > frame.width || y1 > frame.height || x1 < x0 + 2 || y1 < y0 + 2 {
        return invalid!(
            "the region ({x0}, {y0}, {x1}, {y1}) must lie inside the {}x{} frame and be at \
             least 2x2 pixels",
            frame.width,
            frame.height
        );
    }
    check_sigma(sigma)?;
    Ok([y1 - y0, x1 - x0, FIELD_CHANNELS])
}

/// An error unless `sigma` (pixels) is a smoothing the field takes: in (0, [`MAX_SIGMA`]].
pub fn check_sigma(sigma: f64) -> Result<()> {
    if !(sigma > 0.0 && sigma <= MAX_SIGMA) {
        return invalid!("sigma must be in (0, {MAX_SIGMA}] pixels, got {sigma}");
    }
    Ok(())
}

/// The radius (pixels) of the Gaussian of `sigma` pixels (see [`gaussian`]): a field pixel
/// whose derivatives read no mirrored pixel lies more than this plus one inside its region's
/// edges (those not on the frame's), and holds the same value in any such region.
pub fn smoothing_radius(sigma: f64) -> usize {
    (((sigma * 8.0 + 1.0).round() as usize) | 1) / 2
}

/// OpenCV's Gaussian taps for a float image: side round(8σ + 1) | 1, computed in f64.
fn gaussian(sigma: f64) -> Vec<f32> {
    let side = 2 * smoothing_radius(sigma) + 1;
    let r = (side / 2) as f64;
    let taps: Vec<f64> = (0..side)
        .map(|i| (-(i as f64 - r).powi(2) / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.iter().map(|t| (t / sum) as f32).collect()
}

/// `out[i] = Σ_t taps[t] · base[starts[t] + i]`, summed in tap order, [`BLOCK`] outputs at a
/// time so that the sums stay in registers; a ragged end is one more block overlapping the last
/// one (every output is the same sum whichever block computes it).
#[inline(always)]
fn weighted(out: &mut [f32], taps: &[f32], base: &[f32], starts: &[usize]) {
    let n = out.len();
    let row = |t: usize| &base[starts[t]..][..n];
    let mut x = 0;
    while x < n && n >= BLOCK {
        x = x.min(n - BLOCK);
        let mut acc = [0.0f32; BLOCK];
        for (t, &k) in taps.iter().enumerate() {
            for (a, s) in acc.iter_mut().zip(&row(t)[x..x + BLOCK]) {
                *a += k * s;
            }
        }
        out[x..x + BLOCK].copy_from_slice(&acc);
        x += BLOCK;
    }
    for (i, o) in out.iter_mut().enumerate().skip(x) {
        *o = taps
            .iter()
            .enumerate()
            .fold(0.0, |a, (t, &k)| a + k * row(t)[i]);
    }
}

/// Outputs per block of [`weighted`]: four AVX2 registers (two AVX-512 ones).
const BLOCK: usize = 64;

/// Smooths the (h, w) plane `img` in place with the separable `taps`, in the spans `smoothed`
/// (reading the spans `across`, which must hold all that they reach).
#[inline(always)]
fn blur(
    img: &mut [f32],
    w: usize,
    taps: &[f32],
    smoothed: &[Span],
    across: &[Span],
    scratch: &mut BlurScratch,
) {
    let BlurScratch { pad, rows, starts } = scratch;
    let (r, h) = (taps.len() / 2, smoothed.len());
    rows.resize(w * h, 0.0);
    for (y, &[c0, c1]) in across.iter().enumerate().filter(|(_, s)| s[0] < s[1]) {
        let line = &img[y * w..][..w];
        let n = c1 - c0;
        // pad[i] is column c0 + i − r: those inside the region copied, the others mirrored.
        pad.resize(n + 2 * r, 0.0);
        let (first, last) = (r.saturating_sub(c0), (n + 2 * r).min(w + r - c0));
        pad[first..last].copy_from_slice(&line[c0 + first - r..c0 + last - r]);
        for i in (0..first).chain(last..n + 2 * r) {
            pad[i] = line[reflect101((c0 + i) as isize - r as isize, w)];
        }
        starts.clear();
        starts.extend(0..taps.len());
        weighted(&mut rows[y * w + c0..][..n], taps, pad, starts);
    }
    for (y, &[c0, c1]) in smoothed.iter().enumerate().filter(|(_, s)| s[0] < s[1]) {
        starts.clear();
        starts
            .extend((0..taps.len()).map(|t| reflect101((y + t) as isize - r as isize, h) * w + c0));
        weighted(&mut img[y * w + c0..][..c1 - c0], taps, rows, starts);
    }
}

/// The luma plane of the region of `frame` in its spans `spans`, and with `chroma`, the R − G
/// plane in that plane's spans (the rest as it was).
#[inline(always)]
fn planes(
    frame: &ImageRef,
    region: [usize; 4],
    spans: &[Span],
    luma: &mut Vec<f32>,
    chroma: Option<(&mut Vec<f32>, &[Span])>,
) {
    let [x0, y0, x1, y1] = region;
    let w = x1 - x0;
    // The pixels of row y's columns [c0, c1).
    let pixels = |y: usize, c0: usize, c1: usize| {
        let row = &frame.data[((y0 + y) * frame.width + x0 + c0) * 3..][..(c1 - c0) * 3];
        row.chunks_exact(3)
    };
    luma.resize(w * (y1 - y0), 0.0);
    for (y, &[c0, c1]) in spans.iter().enumerate().filter(|(_, s)| s[0] < s[1]) {
        let at = y * w + c0;
        for (l, p) in luma[at..at + c1 - c0].iter_mut().zip(pixels(y, c0, c1)) {
            *l = 0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32;
        }
    }
    if let Some((c, spans)) = chroma {
        c.resize(w * (y1 - y0), 0.0);
        for (y, &[c0, c1]) in spans.iter().enumerate().filter(|(_, s)| s[0] < s[1]) {
            let at = y * w + c0;
            for (c, p) in c[at..at + c1 - c0].iter_mut().zip(pixels(y, c0, c1)) {
                *c = p[0] as f32 - p[1] as f32;
            }
        }
    }
}

/// The planes and row buffers of [`build`], kept per thread from call to call: the tracker asks
/// for a field of about the same size every frame, and zeroing fresh buffers cost more than
/// filling them. A call reads only the rows it has written.
#[derive(Default)]
struct Scratch {
    luma: Vec<f32>,
    chroma: Vec<f32>,
    prev_luma: Vec<f32>,
    blur: BlurScratch,
}

/// [`blur`]'s buffers: a mirrored row, the rows blurred along, the rows a sum reads.
#[derive(Default)]
struct BlurScratch {
    pad: Vec<f32>,
    rows: Vec<f32>,
    starts: Vec<usize>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// [`frame_field`] once its arguments are checked; `wanted`: per region row, the columns to
/// compute, and whether to zero the others.
#[inline(always)]
fn build(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    rows: &Rows,
    out: &mut [f32],
) {
    let [x0, y0, x1, y1] = region;
    let (w, h) = (x1 - x0, y1 - y0);
    let taps = gaussian(sigma);
    let (smoothed, across, converted) = needed(&rows.wanted, taps.len() / 2, w);
    let (c_smoothed, c_across, c_converted) = needed(&rows.colour, taps.len() / 2, w);
    // Taken out and put back rather than borrowed in `SCRATCH.with(|s| ...)`, and no
    // `prev.map(|p| ...)`: a closure would not inherit `build_avx2`'s target feature.
    let mut scratch = SCRATCH.take();
    let Scratch {
        luma,
        chroma,
        prev_luma,
        blur: buffers,
    } = &mut scratch;
    planes(
        frame,
        region,
        &converted,
        luma,
        Some((chroma, &c_converted)),
    );
    blur(luma, w, &taps, &smoothed, &across, buffers);
    blur(chroma, w, &taps, &c_smoothed, &c_across, buffers);
    if let Some(p) = prev {
        planes(p, region, &converted, prev_luma, None);
        blur(prev_luma, w, &taps, &smoothed, &across, buffers);
    }
    let (luma, chroma) = (&*luma, &*chroma);
    let before = if prev.is_some() { &*prev_luma } else { luma };
    let mut d = [
        vec![0.0f32; w],
        vec![0.0f32; w],
        vec![0.0f32; w],
        vec![0.0f32; w],
    ];
    fn line(plane: &[f32], w: usize, y: usize) -> &[f32] {
        &plane[y * w..][..w]
    }
    // What the columns outside the wanted ones get: 0, or nothing (NaN in debug builds).
    let outside = if rows.zero {
        Some(0.0)
    } else if cfg!(debug_assertions) {
        Some(f32::NAN)
    } else {
        None
    };
    for (y, ((o, &[c0, c1]), &colour)) in out
        .chunks_exact_mut(w * FIELD_CHANNELS)
        .zip(&rows.wanted)
        .zip(&rows.colour)
        .enumerate()
    {
        if let Some(v) = outside {
            o[..c0.min(c1) * FIELD_CHANNELS].fill(v);
            o[c1 * FIELD_CHANNELS..].fill(v);
        }
        if c0 >= c1 {
            continue;
        }
        // Central differences with mirrored borders: across an edge both neighbours are the
        // same pixel, so the first and last columns (and rows) get 0.
        let (up, down) = (reflect101(y as isize - 1, h), reflect101(y as isize + 1, h));
        let [dlx, dly, dcx, dcy] = &mut d;
        // The colour derivatives are 0 in the wanted columns outside the colour span.
        dcx[c0..c1].fill(0.0);
        dcy[c0..c1].fill(0.0);
        for (plane, dx, dy, [a0, a1]) in [(luma, dlx, dly, [c0, c1]), (chroma, dcx, dcy, colour)] {
            if a0 >= a1 {
                continue;
            }
            let (i0, i1) = (a0.max(1), a1.min(w - 1));
            let l = line(plane, w, y);
            dx[0] = 0.0;
            dx[w - 1] = 0.0;
            if i0 < i1 {
                for ((o, a), b) in dx[i0..i1].iter_mut().zip(&l[i0 + 1..]).zip(&l[i0 - 1..]) {
                    *o = 0.5 * (a - b);
                }
            }
            let (u, v) = (line(plane, w, up), line(plane, w, down));
            for ((o, a), b) in dy[a0..a1].iter_mut().zip(&v[a0..]).zip(&u[a0..]) {
                *o = 0.5 * (a - b);
            }
        }
        let (l, lp) = (line(luma, w, y), line(before, w, y));
        for (px, x) in o[c0 * FIELD_CHANNELS..c1 * FIELD_CHANNELS]
            .chunks_exact_mut(FIELD_CHANNELS)
            .zip(c0..)
        {
            px.copy_from_slice(&[d[0][x], d[1][x], d[2][x], d[3][x], l[x], lp[x]]);
        }
    }
    SCRATCH.set(scratch);
}

/// [`build`] compiled for AVX2; the same operations in the same order, so the same values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn build_avx2(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    rows: &Rows,
    out: &mut [f32],
) {
    build(frame, prev, region, sigma, rows, out)
}

/// [`build`] compiled for AVX-512; the same operations in the same order, so the same values.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn build_avx512(
    frame: &ImageRef,
    prev: Option<&ImageRef>,
    region: [usize; 4],
    sigma: f64,
    rows: &Rows,
    out: &mut [f32],
) {
    build(frame, prev, region, sigma, rows, out)
}

#[cfg(test)]
mod tests {
    use super::super::field::{CX, CY, L, LX, LY};
    use super::*;

    /// [`frame_field`] into a buffer of NaN: every value it leaves is one it wrote.
    fn field(
        img: &ImageRef,
        prev: Option<&ImageRef>,
        region: [usize; 4],
        sigma: f64,
        bands: Option<&[[usize; 4]]>,
    ) -> Result<Vec<f32>> {
        let size = (region[2] - region[0]) * (region[3] - region[1]) * FIELD_CHANNELS;
        let mut out = vec![f32::NAN; size];
        frame_field(img, prev, region, sigma, bands, &mut out)?;
        Ok(out)
    }

    fn rgb(w: usize, h: usize, f: impl Fn(usize, usize) -> [u8; 3]) -> Vec<u8> {
        (0..h)
            .flat_map(|y| (0..w).flat_map(move |x| (0..3).map(move |c| (x, y, c))))
            .map(|(x, y, c)| f(x, y)[c])
            .collect()
    }

    #[test]
    fn taps_are_opencvs() {
        let t = gaussian(1.5);
        assert_eq!(t.len(), 13);
        assert!((t.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert!((t[6] - 0.265_962).abs() < 1e-4);
        assert_eq!(gaussian(0.3).len(), 3);
    }

    #[test]
    fn a_linear_ramp_keeps_its_slope_and_level() {
        // Smoothing leaves a linear ramp unchanged away from the borders.
        let (w, h) = (40, 30);
        let data = rgb(w, h, |x, y| [(2 * x + y) as u8, (x + y) as u8, 7]);
        let img = ImageRef::new(&data, w, h, 3).unwrap();
        let f = field(&img, None, [5, 4, 35, 26], 1.5, None).unwrap();
        let (fw, at) = (30, |x: usize, y: usize, c: usize| {
            (y * 30 + x) * FIELD_CHANNELS + c
        });
        let (x, y) = (15, 11);
        let luma = |x: f32, y: f32| 0.299 * (2.0 * x + y) + 0.587 * (x + y) + 0.114 * 7.0;
        assert!((f[at(x, y, 4)] - luma(20.0, 15.0)).abs() < 1e-3);
        assert!((f[at(x, y, 0)] - (2.0 * 0.299 + 0.587)).abs() < 1e-4);
        assert!((f[at(x, y, 1)] - (0.299 + 0.587)).abs() < 1e-4);
        assert!((f[at(x, y, 2)] - 1.0).abs() < 1e-4);
        assert!((f[at(x, y, 3)] - 0.0).abs() < 1e-4);
        assert_eq!(f[at(x, y, 5)], f[at(x, y, 4)]);
        // Mirrored borders: the outermost derivatives across the edge vanish.
        assert_eq!(f[at(0, y, 0)], 0.0);
        assert_eq!(f[at(fw - 1, y, 2)], 0.0);
        assert_eq!(f[at(x, 0, 1)], 0.0);
    }

    #[test]
    fn the_previous_frame_fills_the_last_channel() {
        let (w, h) = (12, 10);
        let a = rgb(w, h, |x, _| [x as u8 * 10, 0, 0]);
        let b = rgb(w, h, |_, _| [100, 100, 100]);
        let (fa, fb) = (
            ImageRef::new(&a, w, h, 3).unwrap(),
            ImageRef::new(&b, w, h, 3).unwrap(),
        );
        let f = field(&fa, Some(&fb), [0, 0, w, h], 1.0, None).unwrap();
        for px in f.chunks_exact(FIELD_CHANNELS) {
            assert!((px[5] - 100.0).abs() < 1e-3);
        }
    }

    /// A `w`×`h` RGB image with fine texture in red and green.
    fn textured(w: usize, h: usize) -> Vec<u8> {
        rgb(w, h, |x, y| {
            [((x * 37 + y * 11) % 251) as u8, ((x * y) % 253) as u8, 9]
        })
    }

    #[test]
    fn simd_equals_portable() {
        let data = textured(64, 48);
        let img = ImageRef::new(&data, 64, 48, 3).unwrap();
        let region = [3, 2, 61, 45];
        let bands = [[0, 10, 64, 14], [20, 40, 50, 60]];
        let wanted: Vec<Span> = (2..45)
            .map(|y| match y {
                10..14 => [0, 58],
                40.. => [17, 47],
                _ => NONE,
            })
            .collect();
        // Every band in colour (as frame_field computes it), and the lower one only.
        let lower: Vec<Span> = wanted
            .iter()
            .zip(2..)
            .map(|(&s, y)| if y >= 40 { s } else { NONE })
            .collect();
        let all = Rows {
            wanted: wanted.clone(),
            colour: wanted.clone(),
            zero: true,
        };
        let part = Rows {
            wanted,
            colour: lower,
            zero: true,
        };
        let portable = |rows: &Rows| {
            let mut out = vec![f32::NAN; 58 * 43 * FIELD_CHANNELS];
            build(&img, Some(&img), region, 1.5, rows, &mut out);
            out
        };
        let got = field(&img, Some(&img), region, 1.5, Some(&bands)).unwrap();
        assert_eq!(got, portable(&all));
        // Each SIMD build this machine has, not only the one `frame_field` picks.
        #[cfg(target_arch = "x86_64")]
        {
            type Build =
                unsafe fn(&ImageRef, Option<&ImageRef>, [usize; 4], f64, &Rows, &mut [f32]);
            let builds: [(&str, bool, Build); 2] = [
                (
                    "avx2",
                    std::arch::is_x86_feature_detected!("avx2"),
                    build_avx2,
                ),
                (
                    "avx512f",
                    std::arch::is_x86_feature_detected!("avx512f"),
                    build_avx512,
                ),
            ];
            for (name, present, build) in builds {
                if !present {
                    crate::cpu::simd_missing("simd_equals_portable", name);
                }
                for rows in [&all, &part] {
                    if present {
                        let mut out = vec![f32::NAN; 58 * 43 * FIELD_CHANNELS];
                        // SAFETY: the CPU has the build's feature.
                        unsafe { build(&img, Some(&img), region, 1.5, rows, &mut out) };
                        assert_eq!(out, portable(rows), "{name}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_colour_derivatives_are_computed_only_in_the_bands_that_want_them() {
        let data = textured(50, 60);
        let img = ImageRef::new(&data, 50, 60, 3).unwrap();
        let region = [2, 3, 48, 57];
        let bands = [[5, 6, 40, 15], [10, 40, 45, 52]];
        let full = field(&img, None, region, 1.5, Some(&bands)).unwrap();
        let mut out = vec![f32::NAN; full.len()];
        band_field(&img, None, region, 1.5, (&bands, &[false, true]), &mut out).unwrap();
        let w = region[2] - region[0];
        for (i, (px, want)) in out
            .chunks(FIELD_CHANNELS)
            .zip(full.chunks(FIELD_CHANNELS))
            .enumerate()
        {
            let (x, y) = (region[0] + i % w, region[1] + i / w);
            let inside = |b: &[usize; 4]| (b[0]..b[2]).contains(&x) && (b[1]..b[3]).contains(&y);
            if inside(&bands[1]) {
                assert_eq!(px, want, "({x}, {y})");
            } else if inside(&bands[0]) {
                assert_eq!([px[CX], px[CY]], [0.0, 0.0], "({x}, {y})");
                assert_eq!(
                    [px[LX], px[LY], px[L]],
                    [want[LX], want[LY], want[L]],
                    "({x}, {y})"
                );
            }
        }
        assert!(band_field(&img, None, region, 1.5, (&bands, &[true]), &mut out).is_err());
    }

    #[test]
    fn bands_compute_the_same_pixels_and_leave_the_others_zero() {
        let data = textured(50, 60);
        let img = ImageRef::new(&data, 50, 60, 3).unwrap();
        let region = [4, 3, 46, 57];
        let full = field(&img, Some(&img), region, 1.5, None).unwrap();
        // Bands at the region's top-left corner, inside it, past its bottom-right corner, and
        // two that share rows.
        let bands = [
            [0, 0, 12, 5],
            [20, 20, 30, 24],
            [40, 55, 60, 70],
            [6, 30, 10, 36],
            [25, 33, 33, 40],
        ];
        let part = field(&img, Some(&img), region, 1.5, Some(&bands)).unwrap();
        let inside = |x: usize, y: usize| {
            bands
                .iter()
                .any(|b| (b[0]..b[2]).contains(&x) && (b[1]..b[3]).contains(&y))
        };
        let w = region[2] - region[0];
        for (i, (a, b)) in full
            .chunks(FIELD_CHANNELS)
            .zip(part.chunks(FIELD_CHANNELS))
            .enumerate()
        {
            let (x, y) = (i % w + region[0], i / w + region[1]);
            if inside(x, y) {
                assert_eq!(a, b, "pixel ({x}, {y})");
            } else if !(30..40).contains(&y) {
                // (Rows that two bands share are computed from the one's left to the other's
                // right.)
                assert!(b.iter().all(|&v| v == 0.0), "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn a_field_does_not_depend_on_earlier_calls() {
        // The planes are reused from call to call: stale rows of another image and region
        // must not leak into a banded field.
        let (data, other) = (
            textured(50, 60),
            rgb(50, 60, |x, y| [(x * y % 256) as u8, 200, 3]),
        );
        let field = |d: &[u8], region, bands: Option<&[[usize; 4]]>| {
            let img = ImageRef::new(d, 50, 60, 3).unwrap();
            field(&img, Some(&img), region, 1.5, bands).unwrap()
        };
        let bands = [[0, 8, 60, 12], [12, 30, 30, 41]];
        let moved = data.clone();
        let fresh = std::thread::spawn(move || field(&moved, [4, 3, 46, 57], Some(&bands)))
            .join()
            .unwrap();
        field(&other, [0, 0, 50, 60], None);
        field(&other, [10, 5, 30, 50], Some(&[[0, 9, 60, 40]]));
        assert_eq!(field(&data, [4, 3, 46, 57], Some(&bands)), fresh);
    }

    #[test]
    fn refuses_bad_arguments() {
        let data = rgb(8, 8, |_, _| [1, 2, 3]);
        let img = ImageRef::new(&data, 8, 8, 3).unwrap();
        let gray = ImageRef::new(&data[..64], 8, 8, 1).unwrap();
        let small = ImageRef::new(&data[..48], 4, 4, 3).unwrap();
        assert!(field(&gray, None, [0, 0, 8, 8], 1.0, None).is_err());
        assert!(field(&img, Some(&small), [0, 0, 8, 8], 1.0, None).is_err());
        assert!(field(&img, None, [0, 0, 9, 8], 1.0, None).is_err());
        assert!(field(&img, None, [3, 0, 4, 8], 1.0, None).is_err());
        assert!(field(&img, None, [0, 0, 8, 8], 0.0, None).is_err());
        assert!(field(&img, None, [0, 0, 8, 8], f64::NAN, None).is_err());
        let mut short = vec![0.0; 8 * 8 * FIELD_CHANNELS - 1];
        assert!(frame_field(&img, None, [0, 0, 8, 8], 1.0, None, &mut short).is_err());
    }
}
