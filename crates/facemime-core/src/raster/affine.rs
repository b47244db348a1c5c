//! Bilinear resampling through an affine map, in a fixed arithmetic of facemime's own: the crops
//! the face networks see and the eye tracker's eye patches. `cv2.warpAffine` cannot be that
//! definition: its rounding changed between OpenCV 4.x, 5.0 and 5.1, and the tracker started
//! from a crop one grey level off on a few pixels ends elsewhere. This is what OpenCV 4 computed:
//! positions in 1/32 px, integer weights summing to 1024, the sum rounded.
//!
//! Pixel (x, y): x right, y down, (0, 0) the centre of the top-left pixel.

use super::image::{ImageMut, ImageRef};
use crate::error::Result;
use crate::invalid;

/// Sub-pixel steps per pixel of a sampling position.
pub const SUB: i64 = 32;
/// The fixed-point scale of the map's coefficients (1/1024 px).
pub const SCALE: f64 = 1024.0;

/// Largest magnitude of a map coefficient: positions stay far inside 64-bit fixed point.
pub const MAX_COEFFICIENT: f64 = 1e9;

/// What a sample beyond the picture reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Border {
    /// The picture's nearest border pixel.
    Replicate,
    /// Zero.
    Zero,
}

/// Fills `out` with `img` sampled bilinearly at `m · (col, row, 1)` for each output pixel
/// (col, row): each coordinate is `round_ties_even(m · (col, row, 1) · 1024)` (the row's and the
/// column's parts rounded apart, in that order) plus 16, shifted down 5 bits to 1/32 px; the four
/// taps' weights (32 − f)(32 − g), f(32 − g), (32 − f)g, fg sum to 1024 and the sum is rounded.
/// `img` and `out` must have the same number of channels.
pub fn sample_affine(
    img: &ImageRef,
    m: [[f64; 3]; 2],
    out: &mut ImageMut,
    border: Border,
) -> Result<()> {
    if img.channels != out.channels {
        return invalid!(
            "the picture has {} channels and the output {}",
            img.channels,
            out.channels
        );
    }
    if m.iter()
        .flatten()
        .any(|v| !v.is_finite() || v.abs() > MAX_COEFFICIENT)
    {
        return invalid!(
            "the affine map must be finite, each coefficient within ±{MAX_COEFFICIENT:e}"
        );
    }
    let (w, h, ch) = (img.width as i64, img.height as i64, img.channels);
    let half = (SCALE as i64) / SUB / 2;
    let fixed = |v: f64| (v * SCALE).round_ties_even() as i64;
    let column: Vec<[i64; 2]> = (0..out.width)
        .map(|c| [fixed(m[0][0] * c as f64), fixed(m[1][0] * c as f64)])
        .collect();
    let tap = |x: i64, y: i64, k: usize| -> i32 {
        let inside = (0..w).contains(&x) && (0..h).contains(&y);
        if border == Border::Zero && !inside {
            return 0;
        }
        let (x, y) = (x.clamp(0, w - 1) as usize, y.clamp(0, h - 1) as usize);
        img.data[(y * img.width + x) * ch + k] as i32
    };
    let stride = img.width * ch;
    let sub = SUB as i32;
    for r in 0..out.height {
        let x0 = fixed(m[0][1] * r as f64 + m[0][2]) + half;
        let y0 = fixed(m[1][1] * r as f64 + m[1][2]) + half;
        let row = &mut out.data[r * out.width * ch..(r + 1) * out.width * ch];
        for (c, [cx, cy]) in column.iter().enumerate() {
            let (x, y) = ((x0 + cx) >> 5, (y0 + cy) >> 5);
            let (sx, sy) = (x >> 5, y >> 5);
            let (fx, fy) = ((x & 31) as i32, (y & 31) as i32);
            let weights = [
                (sub - fx) * (sub - fy),
                fx * (sub - fy),
                (sub - fx) * fy,
                fx * fy,
            ];
            let px = &mut row[c * ch..(c + 1) * ch];
            if sx >= 0 && sy >= 0 && sx + 1 < w && sy + 1 < h {
                // all four taps on the picture: no clamping
                let a = sy as usize * stride + sx as usize * ch;
                let top = &img.data[a..a + 2 * ch];
                let bottom = &img.data[a + stride..a + stride + 2 * ch];
                for (k, v) in px.iter_mut().enumerate() {
                    let s = weights[0] * top[k] as i32
                        + weights[1] * top[ch + k] as i32
                        + weights[2] * bottom[k] as i32
                        + weights[3] * bottom[ch + k] as i32;
                    *v = ((s + 512) >> 10) as u8;
                }
            } else {
                for (k, v) in px.iter_mut().enumerate() {
                    let s = weights[0] * tap(sx, sy, k)
                        + weights[1] * tap(sx + 1, sy, k)
                        + weights[2] * tap(sx, sy + 1, k)
                        + weights[3] * tap(sx + 1, sy + 1, k);
                    *v = ((s + 512) >> 10) as u8;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(
        data: &[u8],
        w: usize,
        h: usize,
        m: [[f64; 3]; 2],
        size: (usize, usize),
        b: Border,
    ) -> Vec<u8> {
        let img = ImageRef::new(data, w, h, 1).unwrap();
        let mut buf = vec![0u8; size.0 * size.1];
        let mut out = ImageMut::new(&mut buf, size.0, size.1, 1).unwrap();
        sample_affine(&img, m, &mut out, b).unwrap();
        buf
    }

    #[test]
    fn the_identity_gives_the_picture_back() {
        let data: Vec<u8> = (0..20).map(|v| v * 12).collect();
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(sample(&data, 5, 4, id, (5, 4), Border::Replicate), data);
    }

    #[test]
    fn half_way_between_two_pixels_is_their_mean_rounded() {
        let data = [10u8, 21];
        let m = [[1.0, 0.0, 0.5], [0.0, 1.0, 0.0]];
        assert_eq!(sample(&data, 2, 1, m, (1, 1), Border::Replicate), vec![16]);
        // 15.5 rounds up
    }

    #[test]
    fn beyond_the_picture_the_border_is_replicated_or_zero() {
        let data = [200u8; 4];
        let m = [[1.0, 0.0, -1.5], [0.0, 1.0, 0.0]];
        assert_eq!(sample(&data, 2, 2, m, (1, 1), Border::Replicate), vec![200]);
        assert_eq!(sample(&data, 2, 2, m, (1, 1), Border::Zero), vec![0]);
        let m = [[1.0, 0.0, -0.5], [0.0, 1.0, 0.0]]; // half on the picture
        assert_eq!(sample(&data, 2, 2, m, (1, 1), Border::Zero), vec![100]);
    }

    #[test]
    fn a_map_that_is_not_finite_or_channels_that_differ_are_refused() {
        let data = [0u8; 4];
        let img = ImageRef::new(&data, 2, 2, 1).unwrap();
        let mut buf = vec![0u8; 3];
        let mut out = ImageMut::new(&mut buf, 1, 1, 3).unwrap();
        assert!(sample_affine(&img, [[1.0; 3]; 2], &mut out, Border::Zero).is_err());
        let mut buf = vec![0u8; 1];
        let mut out = ImageMut::new(&mut buf, 1, 1, 1).unwrap();
        let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(sample_affine(&img, nan, &mut out, Border::Zero).is_err());
    }
}
