//! Grey levels of RGB frames, as OpenCV's `cvtColor(RGB2GRAY)` gives them for 8-bit images.

use crate::raster::ImageRef;

/// The grey levels of the box [x0, x1)×[y0, y1) (pixels, inside the frame) of a grey (copied)
/// or RGB `frame` into `out`, row-major, x1 − x0 per row.
pub(crate) fn grey_box(frame: &ImageRef, [x0, y0, x1, y1]: [usize; 4], out: &mut Vec<u8>) {
    let (w, c) = (x1 - x0, frame.channels);
    out.resize(w * (y1 - y0), 0);
    for (y, row) in out.chunks_exact_mut(w).enumerate() {
        let src = &frame.data[((y0 + y) * frame.width + x0) * c..][..w * c];
        if c == 1 {
            row.copy_from_slice(src);
        } else {
            rgb_to_gray(src, row);
        }
    }
}

/// RGB triples `rgb` to grey levels `out`: OpenCV's `RGB2GRAY` for 8-bit images,
/// (9798·R + 19235·G + 3735·B + 2^14) >> 15 (equal to OpenCV 4.14's on every RGB triple).
pub(crate) fn rgb_to_gray(rgb: &[u8], out: &mut [u8]) {
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present.
        done = unsafe { rgb_to_gray_avx2(rgb, out) };
    }
    for (o, p) in out[done..].iter_mut().zip(rgb[3 * done..].chunks_exact(3)) {
        let v = p[0] as u32 * 9798 + p[1] as u32 * 19235 + p[2] as u32 * 3735 + (1 << 14);
        *o = (v >> 15) as u8;
    }
}

/// How far ahead of the pixels it converts [`rgb_to_gray_avx2`] asks for the frame's bytes: on
/// a frame not in the cache, 2 KiB made it 1.6 times as fast, 4 KiB as much.
#[cfg(target_arch = "x86_64")]
const READ_AHEAD: usize = 2048;

/// [`rgb_to_gray`] sixteen pixels at a time, as far as whole loads reach; returns the number
/// of pixels done.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rgb_to_gray_avx2(rgb: &[u8], out: &mut [u8]) -> usize {
    use std::arch::x86_64::*;
    let n = out.len().min(rgb.len() / 3);
    // Per 128-bit lane, four pixels from its 16 bytes' first 12: the (R, G) pairs as 16-bit
    // values and B as 32-bit ones (-1: a zero byte).
    let z = -1;
    #[rustfmt::skip]
    let pairs = _mm256_setr_epi8(
        0, z, 1, z, 3, z, 4, z, 6, z, 7, z, 9, z, 10, z,
        0, z, 1, z, 3, z, 4, z, 6, z, 7, z, 9, z, 10, z,
    );
    #[rustfmt::skip]
    let blues = _mm256_setr_epi8(
        2, z, z, z, 5, z, z, z, 8, z, z, z, 11, z, z, z,
        2, z, z, z, 5, z, z, z, 8, z, z, z, 11, z, z, z,
    );
    let (w_rg, w_b) = (
        _mm256_set1_epi32((19235 << 16) | 9798),
        _mm256_set1_epi32(3735),
    );
    let half = _mm256_set1_epi32(1 << 14);
    // The grey levels of the pixels from byte `at` (lane 0) and from byte `at` + 24 (lane 1).
    let grey = |p: *const u8| {
        let v = _mm256_loadu2_m128i(p.add(24) as *const __m128i, p as *const __m128i);
        let sum = _mm256_add_epi32(
            _mm256_madd_epi16(_mm256_shuffle_epi8(v, pairs), w_rg),
            _mm256_madd_epi16(_mm256_shuffle_epi8(v, blues), w_b),
        );
        _mm256_srli_epi32(_mm256_add_epi32(sum, half), 15)
    };
    let mut i = 0;
    // Pixels i..i + 16 read bytes 3i..3i + 52.
    while 3 * i + 52 <= 3 * n {
        let p = rgb.as_ptr().add(3 * i);
        // A frame is seldom in the cache (decoded a while ago): ask for what comes next
        // early. A prefetch never faults, wherever it points.
        _mm_prefetch(p.wrapping_add(READ_AHEAD) as *const i8, _MM_HINT_T0);
        // Lanes: pixels 0-3 and 8-11, then 4-7 and 12-15; packed, 0-7 and 8-15.
        let words = _mm256_packus_epi32(grey(p), grey(p.add(12)));
        let bytes = _mm256_packus_epi16(words, words);
        let both = _mm256_permute4x64_epi64(bytes, 0b1000);
        _mm_storeu_si128(
            out.as_mut_ptr().add(i) as *mut __m128i,
            _mm256_castsi256_si128(both),
        );
        i += 16;
    }
    i
}
