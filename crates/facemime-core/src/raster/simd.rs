//! AVX2 bilinear texture lookup, 8 pixels at a time, bit-identical to the scalar
//! [`super::sampler::Bilinear`] (same 12-bit rounded weights, same rounding).

use std::arch::x86_64::*;

use super::image::ImageRef;
use super::sampler::FRAC_BITS;

/// Samples a whole span with AVX2 when the CPU has it and returns how many pixels it wrote:
/// all of them, or 0 when it cannot (no AVX2, unsupported channels, footprint too near the
/// texture's last row) and the caller must do the work.
///
/// # Safety
/// The bilinear footprint of the first and the last pixel of `out` must lie inside the texture
/// (`Bilinear::in_bounds`), and `out` must hold whole pixels of C bytes.
#[inline(always)]
pub unsafe fn bilinear_span_avx2<const C: usize>(
    tex: &ImageRef,
    u: i64,
    v: i64,
    du: i64,
    dv: i64,
    out: &mut [u8],
) -> usize {
    let n = out.len() / C;
    // Each 4-byte gather may read one byte past a 3-byte texel: keep the footprint off the
    // texture's last row so that byte always exists. Coordinates must fit in i32 lanes.
    let last_row = |vv: i64| (vv >> FRAC_BITS) + 2 < tex.height as i64;
    let fits = |a: i64| a.abs() < (1 << 30);
    let (u1, v1) = (u + du * (n as i64 - 1), v + dv * (n as i64 - 1));
    if !(C == 3 || C == 4)
        || n == 0
        || !last_row(v)
        || !last_row(v1)
        || !(fits(u) && fits(v) && fits(u1) && fits(v1))
    {
        return 0;
    }
    if !std::arch::is_x86_feature_detected!("avx2") {
        return 0;
    }
    span_avx2::<C>(tex, u as i32, v as i32, du as i32, dv as i32, out, n)
}

#[target_feature(enable = "avx2")]
unsafe fn span_avx2<const C: usize>(
    tex: &ImageRef,
    u: i32,
    v: i32,
    du: i32,
    dv: i32,
    out: &mut [u8],
    n: usize,
) -> usize {
    const WB: i32 = 12; // weight bits, as the scalar sampler
    let frac = _mm256_set1_epi32((1 << FRAC_BITS) - 1);
    let half = _mm256_set1_epi32(1 << (FRAC_BITS as i32 - WB - 1));
    let one = _mm256_set1_epi32(1 << WB);
    let round = _mm256_set1_epi32(1 << (2 * WB - 1));
    let stride = _mm256_set1_epi32((tex.width * C) as i32);
    // Byte c of every 32-bit lane to the lane's low 16 bits (`low`) or its high 16 bits
    // (`high`), the rest zero: with both, one lane holds a texel pair (t0 | t1 << 16) of
    // channel c, ready for a 16-bit multiply-add with the weight pair (1 - f | f << 16).
    let pick = |c: i8, at: i8| {
        let z = -128i8; // 0x80: a zero byte
        let lane = |k: i8| {
            let mut b = [z; 4];
            b[at as usize] = 4 * k + c;
            b
        };
        let [a, b, cc, d] = [lane(0), lane(1), lane(2), lane(3)];
        _mm256_setr_epi8(
            a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], cc[0], cc[1], cc[2], cc[3], d[0], d[1],
            d[2], d[3], a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3], cc[0], cc[1], cc[2], cc[3],
            d[0], d[1], d[2], d[3],
        )
    };
    let low: [__m256i; 4] = std::array::from_fn(|c| pick(c as i8, 0));
    let high: [__m256i; 4] = std::array::from_fn(|c| pick(c as i8, 2));
    let base = tex.data.as_ptr() as *const i32;
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let (du_v, dv_v) = (_mm256_set1_epi32(du), _mm256_set1_epi32(dv));
    // Positions of the chunk's eight pixels, stepped by eight pixels per chunk.
    let mut uu = _mm256_add_epi32(_mm256_set1_epi32(u), _mm256_mullo_epi32(lanes, du_v));
    let mut vv = _mm256_add_epi32(_mm256_set1_epi32(v), _mm256_mullo_epi32(lanes, dv_v));
    let (du8, dv8) = (_mm256_slli_epi32::<3>(du_v), _mm256_slli_epi32::<3>(dv_v));
    let mut done = 0;
    let mut buf = [0u32; 8];
    while done < n {
        let m = (n - done).min(8);
        let (mut cu, mut cv) = (uu, vv);
        if m < 8 {
            // Lanes past the span's end step back to its last pixel, so every gather stays
            // in bounds.
            let back = _mm256_sub_epi32(
                _mm256_min_epi32(lanes, _mm256_set1_epi32(m as i32 - 1)),
                lanes,
            );
            cu = _mm256_add_epi32(uu, _mm256_mullo_epi32(back, du_v));
            cv = _mm256_add_epi32(vv, _mm256_mullo_epi32(back, dv_v));
        }
        let fx = _mm256_srli_epi32::<{ FRAC_BITS as i32 - WB }>(_mm256_add_epi32(
            _mm256_and_si256(cu, frac),
            half,
        ));
        let fy = _mm256_srli_epi32::<{ FRAC_BITS as i32 - WB }>(_mm256_add_epi32(
            _mm256_and_si256(cv, frac),
            half,
        ));
        // Weight pairs (1 - fx | fx << 16) across; 1 - fy and fy down, as 32-bit lanes.
        let wx = _mm256_or_si256(_mm256_sub_epi32(one, fx), _mm256_slli_epi32::<16>(fx));
        let gy = _mm256_sub_epi32(one, fy);
        let x = _mm256_srai_epi32::<{ FRAC_BITS as i32 }>(cu);
        let y = _mm256_srai_epi32::<{ FRAC_BITS as i32 }>(cv);
        let xc = if C == 4 {
            _mm256_slli_epi32::<2>(x)
        } else {
            _mm256_add_epi32(_mm256_slli_epi32::<1>(x), x)
        };
        let o00 = _mm256_add_epi32(_mm256_mullo_epi32(y, stride), xc);
        let o01 = _mm256_add_epi32(o00, _mm256_set1_epi32(C as i32));
        let (o10, o11) = (_mm256_add_epi32(o00, stride), _mm256_add_epi32(o01, stride));
        let t00 = _mm256_i32gather_epi32::<1>(base, o00);
        let t01 = _mm256_i32gather_epi32::<1>(base, o01);
        let t10 = _mm256_i32gather_epi32::<1>(base, o10);
        let t11 = _mm256_i32gather_epi32::<1>(base, o11);
        let mut px = _mm256_setzero_si256();
        for c in 0..C.min(4) {
            let pair = |a: __m256i, b: __m256i| {
                _mm256_or_si256(
                    _mm256_shuffle_epi8(a, low[c]),
                    _mm256_shuffle_epi8(b, high[c]),
                )
            };
            // Across, exact in 32 bits (< 2^20); then down, the same sum as the scalar
            // sampler's four products (< 2^32).
            let top = _mm256_madd_epi16(pair(t00, t01), wx);
            let bottom = _mm256_madd_epi16(pair(t10, t11), wx);
            let s = _mm256_add_epi32(
                _mm256_add_epi32(_mm256_mullo_epi32(top, gy), _mm256_mullo_epi32(bottom, fy)),
                round,
            );
            px = _mm256_or_si256(
                px,
                _mm256_sll_epi32(
                    _mm256_srli_epi32::<{ 2 * WB }>(s),
                    _mm_cvtsi32_si128(8 * c as i32),
                ),
            );
        }
        _mm256_storeu_si256(buf.as_mut_ptr() as *mut __m256i, px);
        let dst = out.as_mut_ptr().add(done * C);
        for (k, p) in buf[..m].iter().enumerate() {
            if done + k + 1 < n {
                // 4-byte store; for C = 3 its last byte lands on the next pixel, rewritten next.
                std::ptr::write_unaligned(dst.add(k * C) as *mut u32, *p);
            } else {
                std::ptr::copy_nonoverlapping(p.to_le_bytes().as_ptr(), dst.add(k * C), C);
            }
        }
        done += m;
        uu = _mm256_add_epi32(uu, du8);
        vv = _mm256_add_epi32(vv, dv8);
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::sampler::{Bilinear, Sampler};
    use proptest::prelude::*;

    fn noise(w: usize, h: usize, c: usize, seed: u64) -> Vec<u8> {
        let mut s = seed | 1;
        (0..w * h * c)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 24) as u8
            })
            .collect()
    }

    fn check<const C: usize>(u: i64, v: i64, du: i64, dv: i64, n: usize, seed: u64) {
        let (w, h) = (37, 29);
        let data = noise(w, h, C, seed);
        let tex = ImageRef {
            data: &data,
            width: w,
            height: h,
            channels: C,
        };
        let last = n as i64 - 1;
        if !(Bilinear::in_bounds(&tex, u, v)
            && Bilinear::in_bounds(&tex, u + du * last, v + dv * last))
        {
            return;
        }
        // One guard pixel on each side catches a write outside the span.
        let mut out = vec![7u8; (n + 2) * C];
        let wrote =
            unsafe { bilinear_span_avx2::<C>(&tex, u, v, du, dv, &mut out[C..(n + 1) * C]) };
        if wrote == 0 {
            return;
        }
        assert_eq!(wrote, n);
        assert!(
            out[..C].iter().chain(&out[(n + 1) * C..]).all(|&b| b == 7),
            "wrote outside the span"
        );
        for k in 0..n {
            let want = Bilinear::sample::<C>(&tex, u + du * k as i64, v + dv * k as i64);
            assert_eq!(
                &out[(k + 1) * C..(k + 2) * C],
                &want[..],
                "pixel {k} of {n}"
            );
        }
    }

    proptest! {
        #[test]
        fn avx2_span_matches_scalar_lookups(
            u in 0i64..(36 << 16), v in 0i64..(27 << 16),
            du in -(3i64 << 16)..(3 << 16), dv in -(1i64 << 16)..(1 << 16),
            n in 1usize..40, seed in any::<u64>(),
        ) {
            check::<3>(u, v, du / 16, dv / 16, n, seed);
            check::<4>(u, v, du / 16, dv / 16, n, seed);
        }
    }
}
