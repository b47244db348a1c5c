//! The per-frame image field the image energies read: a float32 (H, W, FIELD_CHANNELS) block
//! covering a region of interest of the frame, sampled bilinearly with its spatial derivatives.

use crate::error::Result;
use crate::invalid;

/// Channels of a field, in order: luma derivatives ∂L/∂x, ∂L/∂y; colour-channel derivatives
/// ∂C/∂x, ∂C/∂y; luma L; the previous frame's luma L' on the same pixels. Luma in 0..255 units,
/// derivatives in units per pixel.
pub const FIELD_CHANNELS: usize = 6;
pub(crate) const LX: usize = 0;
pub(crate) const LY: usize = 1;
pub(crate) const CX: usize = 2;
pub(crate) const CY: usize = 3;
pub(crate) const L: usize = 4;
pub(crate) const LPREV: usize = 5;

/// A borrowed (height, width, FIELD_CHANNELS) float32 block whose pixel (0, 0) is the frame
/// pixel `origin` (x, y).
#[derive(Clone, Copy)]
pub struct Field<'a> {
    data: &'a [f32],
    width: usize,
    height: usize,
    origin: [f64; 2],
}

/// Bilinear sample of all channels at one point: values and their x and y derivatives.
pub(crate) struct Sample {
    pub v: [f32; FIELD_CHANNELS],
    pub dx: [f32; FIELD_CHANNELS],
    pub dy: [f32; FIELD_CHANNELS],
}

impl<'a> Field<'a> {
    /// Wraps `data` (row-major, `height * width * FIELD_CHANNELS` values, all finite).
    pub fn new(data: &'a [f32], width: usize, height: usize, origin: [f64; 2]) -> Result<Self> {
        if width < 2 || height < 2 {
            return invalid!("field must be at least 2x2 pixels, got {width}x{height}");
        }
        if data.len() != width * height * FIELD_CHANNELS {
            return invalid!(
                "field must hold {}x{}x{} values, got {}",
                height,
                width,
                FIELD_CHANNELS,
                data.len()
            );
        }
        if !origin.iter().all(|v| v.is_finite()) {
            return invalid!("field origin must be finite");
        }
        Ok(Field {
            data,
            width,
            height,
            origin,
        })
    }

    /// Samples at frame point (x, y) the first `N` channels (the others are 0). Outside the
    /// block the border value is used and the derivative across the border is zero.
    #[inline(always)]
    pub(crate) fn sample<const N: usize>(&self, x: f64, y: f64) -> Sample {
        let (fx, cx, x0) = axis(x - self.origin[0], self.width);
        let (fy, cy, y0) = axis(y - self.origin[1], self.height);
        let row = self.width * FIELD_CHANNELS;
        let a = y0 * row + x0 * FIELD_CHANNELS;
        // The cell's two pixels on its top and its bottom row, one bounds check each.
        let top: &[f32; 2 * FIELD_CHANNELS] = self.data[a..][..2 * FIELD_CHANNELS]
            .try_into()
            .expect("two pixels");
        let bot: &[f32; 2 * FIELD_CHANNELS] = self.data[a + row..][..2 * FIELD_CHANNELS]
            .try_into()
            .expect("two pixels");
        let (fx, fy) = (fx as f32, fy as f32);
        let mut s = Sample {
            v: [0.0; FIELD_CHANNELS],
            dx: [0.0; FIELD_CHANNELS],
            dy: [0.0; FIELD_CHANNELS],
        };
        for ch in 0..N.min(FIELD_CHANNELS) {
            let (va, vb) = (top[ch], top[FIELD_CHANNELS + ch]);
            let (vc, vd) = (bot[ch], bot[FIELD_CHANNELS + ch]);
            let top = va + fx * (vb - va);
            let bottom = vc + fx * (vd - vc);
            s.v[ch] = top + fy * (bottom - top);
            if cx {
                s.dx[ch] = (vb - va) + fy * ((vd - vc) - (vb - va));
            }
            if cy {
                s.dy[ch] = bottom - top;
            }
        }
        s
    }
}

/// Splits a local coordinate into (fraction, inside, cell index) with the cell clamped to the
/// block; `inside` is false when the coordinate was clamped.
#[inline(always)]
fn axis(t: f64, size: usize) -> (f64, bool, usize) {
    let max = (size - 1) as f64;
    if t.is_nan() || t <= 0.0 {
        return (0.0, false, 0);
    }
    if t >= max {
        return (1.0, false, size - 2);
    }
    let i = (t as usize).min(size - 2); // t > 0: truncation is floor, without a libm call
    (t - i as f64, true, i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize) -> Vec<f32> {
        let mut d = vec![0.0f32; w * h * FIELD_CHANNELS];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) * FIELD_CHANNELS;
                d[i + L] = 2.0 * x as f32 + 3.0 * y as f32;
            }
        }
        d
    }

    #[test]
    fn bilinear_value_and_derivatives_of_a_plane_are_exact() {
        let d = ramp(8, 6);
        let f = Field::new(&d, 8, 6, [10.0, 20.0]).unwrap();
        let s = f.sample::<FIELD_CHANNELS>(13.25, 22.5);
        assert!((s.v[L] - (2.0 * 3.25 + 3.0 * 2.5)).abs() < 1e-5);
        assert!((s.dx[L] - 2.0).abs() < 1e-6 && (s.dy[L] - 3.0).abs() < 1e-6);
    }

    #[test]
    fn sampling_the_first_channels_gives_them_as_sampling_all_does() {
        let mut d = ramp(8, 6);
        d.iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v += (i % 7) as f32 * 0.37);
        let f = Field::new(&d, 8, 6, [0.0, 0.0]).unwrap();
        for (x, y) in [(3.3, 2.7), (-1.0, 4.2), (6.9, 5.5)] {
            let (all, first) = (f.sample::<FIELD_CHANNELS>(x, y), f.sample::<4>(x, y));
            for (a, b) in [(all.v, first.v), (all.dx, first.dx), (all.dy, first.dy)] {
                assert_eq!(a[..4], b[..4]);
                assert_eq!(b[4..], [0.0; 2]);
            }
        }
    }

    #[test]
    fn outside_the_block_takes_the_border_with_zero_derivative_across_it() {
        let d = ramp(8, 6);
        let f = Field::new(&d, 8, 6, [0.0, 0.0]).unwrap();
        let s = f.sample::<FIELD_CHANNELS>(-5.0, 2.0);
        assert_eq!(s.v[L], 6.0);
        assert_eq!(s.dx[L], 0.0);
        assert!((s.dy[L] - 3.0).abs() < 1e-6);
        let s = f.sample::<FIELD_CHANNELS>(100.0, 100.0);
        assert_eq!(s.v[L], 2.0 * 7.0 + 3.0 * 5.0);
    }

    #[test]
    fn wrong_sizes_are_refused() {
        let d = ramp(8, 6);
        assert!(Field::new(&d, 8, 5, [0.0, 0.0]).is_err());
        assert!(Field::new(&d[..6], 1, 1, [0.0, 0.0]).is_err());
        assert!(Field::new(&d, 8, 6, [f64::NAN, 0.0]).is_err());
    }
}
