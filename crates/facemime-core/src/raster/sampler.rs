//! Texture lookups. Texture coordinates are texel pixels in 16.16 fixed point with texel centres
//! on integers (the image convention of the crate); lookups outside the texture clamp to its edge.

use super::image::ImageRef;

/// Fractional bits of the fixed-point texture coordinates.
pub const FRAC_BITS: u32 = 16;
/// 1.0 in fixed point.
pub const ONE: i64 = 1 << FRAC_BITS;

/// Reads one texel value (C channels) at a fixed-point texture position.
pub trait Sampler {
    /// Lookup with edge clamping, valid for any position.
    fn sample<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C];

    /// Whether a lookup at (u, v) reads only texels inside the texture, so that it needs no
    /// clamping.
    fn in_bounds(tex: &ImageRef, u: i64, v: i64) -> bool;

    /// Fills every span of one triangle: pixel k of span `s` takes the sample at
    /// (s.u + k·du, s.v + k·dv).
    ///
    /// # Safety
    /// `Self::in_bounds` must hold at the first and the last pixel of every span, and every
    /// span must lie inside `data`.
    unsafe fn fill_spans_unchecked<const C: usize>(
        tex: &ImageRef,
        du: i64,
        dv: i64,
        spans: &[SpanStart],
        data: &mut [u8],
    );
}

/// A run of pixels on one image row: its first byte in the image data, its length in pixels
/// and the texture position at its first pixel (16.16 fixed point).
#[derive(Clone, Copy, Debug)]
pub struct SpanStart {
    pub at: usize,
    pub len: usize,
    pub u: i64,
    pub v: i64,
}

impl SpanStart {
    /// The span's pixels in `data` (C bytes each).
    ///
    /// # Safety
    /// The span must lie inside `data`.
    #[inline(always)]
    pub unsafe fn pixels<'a, const C: usize>(&self, data: &'a mut [u8]) -> &'a mut [u8] {
        data.get_unchecked_mut(self.at..self.at + self.len * C)
    }
}

/// Nearest texel (round half up).
pub struct Nearest;

/// Bilinear interpolation of the four surrounding texels: 16-bit weights, within 0.53 level of
/// exact.
pub struct Bilinear;

#[inline(always)]
fn clamp_index(i: i64, n: usize) -> usize {
    i.clamp(0, n as i64 - 1) as usize
}

impl Sampler for Nearest {
    #[inline(always)]
    fn sample<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let x = clamp_index((u + ONE / 2) >> FRAC_BITS, tex.width);
        let y = clamp_index((v + ONE / 2) >> FRAC_BITS, tex.height);
        let i = (y * tex.width + x) * C;
        let mut px = [0u8; C];
        px.copy_from_slice(&tex.data[i..i + C]);
        px
    }

    #[inline(always)]
    fn in_bounds(tex: &ImageRef, u: i64, v: i64) -> bool {
        let (x, y) = ((u + ONE / 2) >> FRAC_BITS, (v + ONE / 2) >> FRAC_BITS);
        x >= 0 && y >= 0 && x < tex.width as i64 && y < tex.height as i64
    }

    #[inline(always)]
    unsafe fn fill_spans_unchecked<const C: usize>(
        tex: &ImageRef,
        du: i64,
        dv: i64,
        spans: &[SpanStart],
        data: &mut [u8],
    ) {
        // The texture's pointer and row length in locals: the writes to `data` would otherwise
        // make the compiler reload them for every pixel.
        let (texels, stride) = (tex.data.as_ptr(), tex.width * C);
        for s in spans {
            let (mut u, mut v) = (s.u + ONE / 2, s.v + ONE / 2);
            for px in s.pixels::<C>(data).chunks_exact_mut(C) {
                let i = (v >> FRAC_BITS) as usize * stride + (u >> FRAC_BITS) as usize * C;
                px.copy_from_slice(&std::ptr::read_unaligned(texels.add(i) as *const [u8; C]));
                u += du;
                v += dv;
            }
        }
    }
}

/// Integer texel (x, y) below-left of (u, v) and the fractions (fx, fy) in 0.16 fixed point.
#[inline(always)]
fn bilinear_weights(u: i64, v: i64) -> (i64, i64, u32, u32) {
    let frac = |t: i64| (t & (ONE - 1)) as u32;
    (u >> FRAC_BITS, v >> FRAC_BITS, frac(u), frac(v))
}

/// `a + (b - a) · f` for values in 8.8 fixed point and a 0.16 fraction, as two truncated
/// 16-bit products (weights 1 - f ≈ 0xFFFF - f and f): the arithmetic of the SIMD samplers'
/// `mulhi_epu16`, which they must match bit for bit. Never above max(a, b).
#[inline(always)]
fn lerp16(a: u32, b: u32, f: u32) -> u32 {
    ((a * (f ^ 0xFFFF)) >> 16) + ((b * f) >> 16)
}

/// Bilinear blend of four texels (each C bytes): across in 8.8 fixed point, then down, then
/// rounded. Each truncated product loses under 1/256 level, so the result is within 0.53 level
/// of exact bilinear interpolation.
#[inline(always)]
fn blend<const C: usize>(p: [&[u8]; 4], fx: u32, fy: u32) -> [u8; C] {
    let mut px = [0u8; C];
    for c in 0..C {
        let q = |k: usize| (p[k][c] as u32) << 8;
        let top = lerp16(q(0), q(1), fx);
        let bottom = lerp16(q(2), q(3), fx);
        px[c] = ((lerp16(top, bottom, fy) + 128) >> 8) as u8;
    }
    px
}

impl Sampler for Bilinear {
    #[inline(always)]
    fn sample<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let (xi, yi, fx, fy) = bilinear_weights(u, v);
        let (x0, x1) = (clamp_index(xi, tex.width), clamp_index(xi + 1, tex.width));
        let (y0, y1) = (clamp_index(yi, tex.height), clamp_index(yi + 1, tex.height));
        let at = |x: usize, y: usize| &tex.data[(y * tex.width + x) * C..][..C];
        blend::<C>([at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)], fx, fy)
    }

    #[inline(always)]
    fn in_bounds(tex: &ImageRef, u: i64, v: i64) -> bool {
        let (x, y) = (u >> FRAC_BITS, v >> FRAC_BITS);
        x >= 0 && y >= 0 && x + 1 < tex.width as i64 && y + 1 < tex.height as i64
    }

    #[inline(always)]
    unsafe fn fill_spans_unchecked<const C: usize>(
        tex: &ImageRef,
        du: i64,
        dv: i64,
        spans: &[SpanStart],
        data: &mut [u8],
    ) {
        #[cfg(target_arch = "x86_64")]
        if super::simd::bilinear_spans::<C>(tex, du, dv, spans, data, super::simd::Kernel::Best) {
            return;
        }
        for s in spans {
            Self::fill_span_scalar::<C>(tex, s.u, s.v, du, dv, s.pixels::<C>(data));
        }
    }
}

impl Bilinear {
    /// Fills `out` (whole pixels of C bytes) with the samples at (u + k·du, v + k·dv), one
    /// pixel at a time.
    ///
    /// # Safety
    /// `Self::in_bounds` must hold at the first and the last pixel.
    #[inline(always)]
    pub(super) unsafe fn fill_span_scalar<const C: usize>(
        tex: &ImageRef,
        mut u: i64,
        mut v: i64,
        du: i64,
        dv: i64,
        out: &mut [u8],
    ) {
        for px in out.chunks_exact_mut(C) {
            px.copy_from_slice(&Self::sample_unchecked::<C>(tex, u, v));
            u += du;
            v += dv;
        }
    }

    /// Lookup without clamping or bounds checks.
    ///
    /// # Safety
    /// `Self::in_bounds(tex, u, v)` must hold.
    #[inline(always)]
    unsafe fn sample_unchecked<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let (xi, yi, fx, fy) = bilinear_weights(u, v);
        let stride = tex.width * C;
        let i00 = yi as usize * stride + xi as usize * C;
        let d = tex.data;
        blend::<C>(
            [
                d.get_unchecked(i00..i00 + C),
                d.get_unchecked(i00 + C..i00 + 2 * C),
                d.get_unchecked(i00 + stride..i00 + stride + C),
                d.get_unchecked(i00 + stride + C..i00 + stride + 2 * C),
            ],
            fx,
            fy,
        )
    }
}
