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

    /// Whether [`Sampler::sample_unchecked`] is valid at (u, v): every texel it reads exists.
    fn in_bounds(tex: &ImageRef, u: i64, v: i64) -> bool;

    /// Lookup without clamping or bounds checks.
    ///
    /// # Safety
    /// `Self::in_bounds(tex, u, v)` must hold and `tex.data` must hold W·H·C bytes.
    unsafe fn sample_unchecked<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C];
}

/// Nearest texel (round half up).
pub struct Nearest;

/// Bilinear interpolation of the four surrounding texels, 8-bit weights.
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
    unsafe fn sample_unchecked<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let x = ((u + ONE / 2) >> FRAC_BITS) as usize;
        let y = ((v + ONE / 2) >> FRAC_BITS) as usize;
        let p = tex.data.as_ptr().add((y * tex.width + x) * C);
        std::ptr::read_unaligned(p as *const [u8; C])
    }
}

impl Sampler for Bilinear {
    #[inline(always)]
    fn sample<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let (xi, yi) = (u >> FRAC_BITS, v >> FRAC_BITS);
        // 8-bit fractional weights: the top 8 of the 16 fractional bits.
        let fx = ((u >> (FRAC_BITS - 8)) & 0xFF) as u32;
        let fy = ((v >> (FRAC_BITS - 8)) & 0xFF) as u32;
        let (x0, x1) = (clamp_index(xi, tex.width), clamp_index(xi + 1, tex.width));
        let (y0, y1) = (clamp_index(yi, tex.height), clamp_index(yi + 1, tex.height));
        let row0 = y0 * tex.width;
        let row1 = y1 * tex.width;
        let (i00, i01) = ((row0 + x0) * C, (row0 + x1) * C);
        let (i10, i11) = ((row1 + x0) * C, (row1 + x1) * C);
        let w00 = (256 - fx) * (256 - fy);
        let w01 = fx * (256 - fy);
        let w10 = (256 - fx) * fy;
        let w11 = fx * fy;
        let d = tex.data;
        let mut px = [0u8; C];
        for c in 0..C {
            let s = d[i00 + c] as u32 * w00
                + d[i01 + c] as u32 * w01
                + d[i10 + c] as u32 * w10
                + d[i11 + c] as u32 * w11;
            px[c] = ((s + (1 << 15)) >> 16) as u8;
        }
        px
    }

    #[inline(always)]
    fn in_bounds(tex: &ImageRef, u: i64, v: i64) -> bool {
        let (x, y) = (u >> FRAC_BITS, v >> FRAC_BITS);
        x >= 0 && y >= 0 && x + 1 < tex.width as i64 && y + 1 < tex.height as i64
    }

    #[inline(always)]
    unsafe fn sample_unchecked<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C] {
        let fx = ((u >> (FRAC_BITS - 8)) & 0xFF) as u32;
        let fy = ((v >> (FRAC_BITS - 8)) & 0xFF) as u32;
        let stride = tex.width * C;
        let p00 = tex.data.as_ptr().add(((v >> FRAC_BITS) as usize) * stride + ((u >> FRAC_BITS) as usize) * C);
        let (p01, p10) = (p00.add(C), p00.add(stride));
        let p11 = p10.add(C);
        // Horizontal then vertical interpolation, 8-bit weights, one rounding at the end.
        let mut px = [0u8; C];
        for c in 0..C {
            let top = *p00.add(c) as u32 * (256 - fx) + *p01.add(c) as u32 * fx;
            let bottom = *p10.add(c) as u32 * (256 - fx) + *p11.add(c) as u32 * fx;
            px[c] = ((top * (256 - fy) + bottom * fy + (1 << 15)) >> 16) as u8;
        }
        px
    }
}
