//! SIMD bilinear texture lookups along spans: AVX-512 (BW), 16 pixels at a time, or AVX2, 8 at
//! a time; both bit-identical to the scalar [`super::sampler::Bilinear`] (the same truncated
//! 16-bit products, the same rounding).
//!
//! Both kernels gather each pixel's texel pair (a texel and its right neighbour: 8 bytes) from
//! the top and the bottom row, widen the channels to 8.8 fixed-point words, blend them with
//! `mulhi_epu16` and pack them back. A 128-bit lane holds the words of two pixels, so the
//! pixels are gathered in two groups (lanes 0, 1 and lanes 2, 3 of every four) that `packus`
//! interleaves back into order.

use std::arch::x86_64::*;

use super::image::ImageRef;
use super::sampler::{Bilinear, SpanStart, FRAC_BITS};

/// A byte shuffle index that writes zero.
const Z: u8 = 0x80;

/// Per 128-bit lane: the 16-bit fraction of 32-bit lane `a` repeated over the four channel
/// words of the first pixel, that of lane `a + 1` over the second's.
const fn spread(a: u8) -> [u8; 16] {
    let mut p = [0u8; 16];
    let mut i = 0;
    while i < 16 {
        p[i] = 4 * (a + (i / 8) as u8) + (i % 2) as u8;
        i += 1;
    }
    p
}

/// Per 128-bit lane (two 8-byte texel pairs): the C channels of the texel at byte `at` of each
/// pair as four 8.8 fixed-point words (the byte high, zero low).
const fn widen(at: u8) -> [u8; 16] {
    let mut p = [Z; 16];
    let mut k = 0;
    while k < 8 {
        p[2 * k + 1] = 8 * (k / 4) as u8 + at + (k % 4) as u8;
        k += 1;
    }
    p
}

/// Per 128-bit lane: the first three bytes of each 32-bit lane, side by side.
const PACK3: [u8; 16] = [0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, Z, Z, Z, Z];

/// Which kernel [`bilinear_spans`] may use.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kernel {
    /// The widest the CPU has.
    Best,
    /// AVX2 even where AVX-512 exists, so that tests check both.
    #[cfg(test)]
    Avx2,
}

/// Fills the spans with SIMD when the CPU can, as [`super::sampler::Sampler::fill_spans_unchecked`], and says
/// whether it did; false (nothing written) without AVX2, for other than 3 or 4 channels or for
/// texture rows over 32767 bytes. A span whose footprint touches the texture's last row is
/// drawn one pixel at a time, as each 8-byte gather may read two bytes past a texel pair.
///
/// # Safety
/// As [`super::sampler::Sampler::fill_spans_unchecked`].
#[inline(always)]
pub unsafe fn bilinear_spans<const C: usize>(
    tex: &ImageRef,
    du: i64,
    dv: i64,
    spans: &[SpanStart],
    data: &mut [u8],
    kernel: Kernel,
) -> bool {
    // Texel offsets are computed from 16-bit (x, y) and row lengths.
    if !(C == 3 || C == 4) || tex.width * C > i16::MAX as usize || tex.height > i16::MAX as usize {
        return false;
    }
    if kernel == Kernel::Best
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512bw")
    {
        spans_avx512::<C>(tex, du, dv, spans, data);
    } else if std::arch::is_x86_feature_detected!("avx2") {
        spans_avx2::<C>(tex, du, dv, spans, data);
    } else {
        return false;
    }
    true
}

/// A span's texture walk in i32 lanes (16.16 fixed point): first and last position, or None
/// when the span must be drawn by the scalar sampler (footprint on the texture's last row, or
/// positions beyond i32). Positions wrap in i32 like the casts: exact wherever they are used.
#[inline(always)]
fn walk(tex: &ImageRef, s: &SpanStart, du: i64, dv: i64) -> Option<[i32; 4]> {
    let last_row = |vv: i64| (vv >> FRAC_BITS) + 2 < tex.height as i64;
    let fits = |a: i64| a.abs() < (1 << 30);
    let (u1, v1) = (s.u + du * (s.len as i64 - 1), s.v + dv * (s.len as i64 - 1));
    let ok = last_row(s.v) && last_row(v1) && fits(s.u) && fits(s.v) && fits(u1) && fits(v1);
    ok.then_some([s.u as i32, s.v as i32, u1 as i32, v1 as i32])
}

#[target_feature(enable = "avx2")]
unsafe fn load_pattern_256(p: &[u8; 16]) -> __m256i {
    _mm256_broadcastsi128_si256(_mm_loadu_si128(p.as_ptr() as *const __m128i))
}

#[target_feature(enable = "avx2")]
unsafe fn spans_avx2<const C: usize>(
    tex: &ImageRef,
    du: i64,
    dv: i64,
    spans: &[SpanStart],
    data: &mut [u8],
) {
    let base = tex.data.as_ptr() as *const i64;
    let row_len = (tex.width * C) as i32;
    let all_ones = _mm256_set1_epi16(-1);
    let half = _mm256_set1_epi16(128);
    // (C, row length) as a pair of i16: `madd` with (x, y) gives the texel's byte offset.
    let to_offset = _mm256_set1_epi32((row_len << 16) | C as i32);
    let row = _mm_set1_epi32(row_len);
    let (spread_lo, spread_hi) = (load_pattern_256(&spread(0)), load_pattern_256(&spread(2)));
    let (widen_left, widen_right) = (
        load_pattern_256(&widen(0)),
        load_pattern_256(&widen(C as u8)),
    );
    let pack3 = load_pattern_256(&PACK3);
    let keep6 = _mm256_setr_epi32(0, 1, 2, 4, 5, 6, 7, 7);
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let (du_v, dv_v) = (_mm256_set1_epi32(du as i32), _mm256_set1_epi32(dv as i32));
    // Each lane's offset from the chunk's first pixel, and the step from chunk to chunk.
    let (lane_du, lane_dv) = (
        _mm256_mullo_epi32(lanes, du_v),
        _mm256_mullo_epi32(lanes, dv_v),
    );
    let (du8, dv8) = (_mm256_slli_epi32::<3>(du_v), _mm256_slli_epi32::<3>(dv_v));
    let mut buf = [0u32; 8];
    for s in spans {
        let Some([u, v, u1, v1]) = walk(tex, s, du, dv) else {
            Bilinear::fill_span_scalar::<C>(tex, s.u, s.v, du, dv, s.pixels::<C>(data));
            continue;
        };
        let (n, out) = (s.len, s.pixels::<C>(data));
        let (last_u, last_v) = (_mm256_set1_epi32(u1), _mm256_set1_epi32(v1));
        let mut uu = _mm256_add_epi32(_mm256_set1_epi32(u), lane_du);
        let mut vv = _mm256_add_epi32(_mm256_set1_epi32(v), lane_dv);
        let mut done = 0;
        while done < n {
            let m = (n - done).min(8);
            let (mut cu, mut cv) = (uu, vv);
            if m < 8 {
                // Lanes past the span's end take its last pixel, so every gather stays in bounds.
                let valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(m as i32), lanes);
                cu = _mm256_blendv_epi8(last_u, cu, valid);
                cv = _mm256_blendv_epi8(last_v, cv, valid);
            }
            // (x, y) = the integer parts as 16-bit pairs; the fractions are the low 16 bits.
            let xy = _mm256_blend_epi16::<0b1010_1010>(_mm256_srli_epi32::<16>(cu), cv);
            let o = _mm256_madd_epi16(xy, to_offset);
            // Pixels 0, 1, 4, 5 in one group, 2, 3, 6, 7 in the other.
            let o = _mm256_permute4x64_epi64::<0b11_01_10_00>(o);
            let (o_lo, o_hi) = (_mm256_castsi256_si128(o), _mm256_extracti128_si256::<1>(o));
            let gather = |at: __m128i| _mm256_i32gather_epi64::<1>(base, at);
            let group = |at: __m128i, pick: __m256i| {
                let (top, bottom) = (gather(at), gather(_mm_add_epi32(at, row)));
                let (fx, fy) = (_mm256_shuffle_epi8(cu, pick), _mm256_shuffle_epi8(cv, pick));
                let (gx, gy) = (
                    _mm256_xor_si256(fx, all_ones),
                    _mm256_xor_si256(fy, all_ones),
                );
                let lerp = |a: __m256i, b: __m256i, g: __m256i, f: __m256i| {
                    _mm256_add_epi16(_mm256_mulhi_epu16(a, g), _mm256_mulhi_epu16(b, f))
                };
                let across = |pair: __m256i| {
                    let left = _mm256_shuffle_epi8(pair, widen_left);
                    lerp(left, _mm256_shuffle_epi8(pair, widen_right), gx, fx)
                };
                let blended = lerp(across(top), across(bottom), gy, fy);
                _mm256_srli_epi16::<8>(_mm256_add_epi16(blended, half))
            };
            let px = _mm256_packus_epi16(group(o_lo, spread_lo), group(o_hi, spread_hi));
            let dst = out.as_mut_ptr().add(done * C);
            // The pixels packed to C bytes each, from the register's start.
            let packed = if C == 3 {
                _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(px, pack3), keep6)
            } else {
                px
            };
            if (n - done) * C >= 32 {
                // A whole register fits in the span (for C = 3 its last 8 bytes land on pixels
                // that the next chunk rewrites).
                _mm256_storeu_si256(dst as *mut __m256i, packed);
            } else {
                // The whole 32-bit words of the chunk's bytes, then the last one to three.
                let bytes = m * C;
                let words = _mm256_cmpgt_epi32(_mm256_set1_epi32((bytes / 4) as i32), lanes);
                _mm256_maskstore_epi32(dst as *mut i32, words, packed);
                _mm256_storeu_si256(buf.as_mut_ptr() as *mut __m256i, packed);
                let tail = bytes / 4 * 4;
                std::ptr::copy_nonoverlapping(
                    (buf.as_ptr() as *const u8).add(tail),
                    dst.add(tail),
                    bytes - tail,
                );
            }
            done += m;
            uu = _mm256_add_epi32(uu, du8);
            vv = _mm256_add_epi32(vv, dv8);
        }
    }
}

#[target_feature(enable = "avx512f,avx512bw")]
unsafe fn load_pattern_512(p: &[u8; 16]) -> __m512i {
    _mm512_broadcast_i32x4(_mm_loadu_si128(p.as_ptr() as *const __m128i))
}

#[target_feature(enable = "avx512f,avx512bw")]
unsafe fn spans_avx512<const C: usize>(
    tex: &ImageRef,
    du: i64,
    dv: i64,
    spans: &[SpanStart],
    data: &mut [u8],
) {
    let base = tex.data.as_ptr() as *const i64;
    let row_len = (tex.width * C) as i32;
    let all_ones = _mm512_set1_epi16(-1);
    let half = _mm512_set1_epi16(128);
    let to_offset = _mm512_set1_epi32((row_len << 16) | C as i32);
    let row = _mm256_set1_epi32(row_len);
    let (spread_lo, spread_hi) = (load_pattern_512(&spread(0)), load_pattern_512(&spread(2)));
    let (widen_left, widen_right) = (
        load_pattern_512(&widen(0)),
        load_pattern_512(&widen(C as u8)),
    );
    let pack3 = load_pattern_512(&PACK3);
    let keep12 = _mm512_setr_epi32(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 15, 15, 15, 15);
    let groups = _mm512_setr_epi64(0, 2, 4, 6, 1, 3, 5, 7);
    let lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    let (du_v, dv_v) = (_mm512_set1_epi32(du as i32), _mm512_set1_epi32(dv as i32));
    let (lane_du, lane_dv) = (
        _mm512_mullo_epi32(lanes, du_v),
        _mm512_mullo_epi32(lanes, dv_v),
    );
    let (du16, dv16) = (_mm512_slli_epi32::<4>(du_v), _mm512_slli_epi32::<4>(dv_v));
    for s in spans {
        let Some([u, v, u1, v1]) = walk(tex, s, du, dv) else {
            Bilinear::fill_span_scalar::<C>(tex, s.u, s.v, du, dv, s.pixels::<C>(data));
            continue;
        };
        let (n, out) = (s.len, s.pixels::<C>(data));
        let (last_u, last_v) = (_mm512_set1_epi32(u1), _mm512_set1_epi32(v1));
        let mut uu = _mm512_add_epi32(_mm512_set1_epi32(u), lane_du);
        let mut vv = _mm512_add_epi32(_mm512_set1_epi32(v), lane_dv);
        let mut done = 0;
        while done < n {
            let m = (n - done).min(16);
            let valid: __mmask16 = (u32::MAX >> (32 - m)) as u16;
            // Lanes past the span's end take its last pixel, so every gather stays in bounds.
            let cu = _mm512_mask_blend_epi32(valid, last_u, uu);
            let cv = _mm512_mask_blend_epi32(valid, last_v, vv);
            let xy = _mm512_mask_blend_epi16(0xAAAA_AAAA, _mm512_srli_epi32::<16>(cu), cv);
            let o = _mm512_permutexvar_epi64(groups, _mm512_madd_epi16(xy, to_offset));
            let (o_lo, o_hi) = (_mm512_castsi512_si256(o), _mm512_extracti64x4_epi64::<1>(o));
            let gather = |at: __m256i| _mm512_i32gather_epi64::<1>(at, base);
            let group = |at: __m256i, pick: __m512i| {
                let (top, bottom) = (gather(at), gather(_mm256_add_epi32(at, row)));
                let (fx, fy) = (_mm512_shuffle_epi8(cu, pick), _mm512_shuffle_epi8(cv, pick));
                let (gx, gy) = (
                    _mm512_xor_si512(fx, all_ones),
                    _mm512_xor_si512(fy, all_ones),
                );
                let lerp = |a: __m512i, b: __m512i, g: __m512i, f: __m512i| {
                    _mm512_add_epi16(_mm512_mulhi_epu16(a, g), _mm512_mulhi_epu16(b, f))
                };
                let across = |pair: __m512i| {
                    let left = _mm512_shuffle_epi8(pair, widen_left);
                    lerp(left, _mm512_shuffle_epi8(pair, widen_right), gx, fx)
                };
                let blended = lerp(across(top), across(bottom), gy, fy);
                _mm512_srli_epi16::<8>(_mm512_add_epi16(blended, half))
            };
            let px = _mm512_packus_epi16(group(o_lo, spread_lo), group(o_hi, spread_hi));
            let packed = if C == 3 {
                _mm512_permutexvar_epi32(keep12, _mm512_shuffle_epi8(px, pack3))
            } else {
                px
            };
            let bytes: __mmask64 = u64::MAX >> (64 - C * m);
            _mm512_mask_storeu_epi8(out.as_mut_ptr().add(done * C) as *mut i8, bytes, packed);
            done += m;
            uu = _mm512_add_epi32(uu, du16);
            vv = _mm512_add_epi32(vv, dv16);
        }
    }
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

    fn check<const C: usize>(
        kernel: Kernel,
        u: i64,
        v: i64,
        du: i64,
        dv: i64,
        n: usize,
        seed: u64,
    ) {
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
        // Two spans with the same walk, one guard pixel before, between and after them to
        // catch a write outside.
        let mut out = vec![7u8; (2 * n + 3) * C];
        let spans = [1, n + 2].map(|first| SpanStart {
            at: first * C,
            len: n,
            u,
            v,
        });
        if !unsafe { bilinear_spans::<C>(&tex, du, dv, &spans, &mut out, kernel) } {
            // No SIMD here: `this_cpu_runs_the_simd_spans` says so once.
            assert!(
                !std::arch::is_x86_feature_detected!("avx2"),
                "no SIMD spans though the CPU has AVX2"
            );
            return;
        }
        for guard in [0, n + 1, 2 * n + 2] {
            assert!(
                out[guard * C..(guard + 1) * C].iter().all(|&b| b == 7),
                "wrote outside the spans"
            );
        }
        for s in &spans {
            for k in 0..n {
                let want = Bilinear::sample::<C>(&tex, u + du * k as i64, v + dv * k as i64);
                let at = s.at + k * C;
                assert_eq!(&out[at..at + C], &want[..], "pixel {k} of {n}");
            }
        }
    }

    /// The proptest below checks only the kernels this CPU has: say which it could not check
    /// (or fail, with FACEMIME_REQUIRE_SIMD set).
    #[test]
    fn this_cpu_runs_the_simd_spans() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            crate::cpu::simd_missing("simd_spans_match_scalar_lookups", "AVX2");
        } else if !(std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512bw"))
        {
            crate::cpu::simd_missing(
                "simd_spans_match_scalar_lookups (its AVX-512 kernel)",
                "AVX-512 BW",
            );
        }
    }

    proptest! {
        /// Both kernels, spans of any length and direction; footprints on the texture's last
        /// rows (v >= 27 of 29) take the scalar fallback inside the same call.
        #[test]
        fn simd_spans_match_scalar_lookups(
            u in 0i64..(36 << 16), v in 0i64..(28 << 16),
            du in -(3i64 << 16)..(3 << 16), dv in -(1i64 << 16)..(1 << 16),
            n in 1usize..40, seed in any::<u64>(),
        ) {
            for kernel in [Kernel::Best, Kernel::Avx2] {
                check::<3>(kernel, u, v, du / 16, dv / 16, n, seed);
                check::<4>(kernel, u, v, du / 16, dv / 16, n, seed);
            }
        }
    }
}
