//! Texture lookups. Texture coordinates are texel pixels in 16.16 fixed point with texel centres
//! on integers (the image convention of the crate); lookups outside the texture clamp to its edge.

use super::image::ImageRef;

/// Fractional bits of the fixed-point texture coordinates.
pub const FRAC_BITS: u32 = 16;
/// 1.0 in fixed point.
pub const ONE: i64 = 1 << FRAC_BITS;

/// Reads one texel value (C channels) at a fixed-point texture position.
pub trait Sampler {
    fn sample<const C: usize>(tex: &ImageRef, u: i64, v: i64) -> [u8; C];
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
}
