//! A wide search for lip edges along a knot's normal, on a lip-colour score: where the optical
//! flow cannot follow a mouth knot (a mouth opening wide in a few frames), the tracker starts it
//! at the lip edge found here instead of where the head motion alone would put it.
//!
//! The score of a colour (R, G, B) is `w_r·r + w_g·g − bias`, with the chromaticities
//! r = R / (R + G + B + 1) and g = G / (R + G + B + 1): positive on lips, negative on skin, teeth
//! and the dark mouth opening (the caller fits the weights; see `facemime.track.lips`). Along a
//! probe's normal, the samples 1 px apart within ±`reach` px (bilinear in RGB, clamped at the
//! image border) are scored, smoothed by a Gaussian of `sigma` px (ends replicated) and
//! differentiated (central differences, per px). A transition is a local maximum of
//! sign · derivative above `min_step`, placed between samples by a parabola; the search returns
//! the one nearest to the probe's expected offset. Coordinates are pixels (x right, y down, origin at the centre of the
//! top-left pixel).

use crate::error::Result;
use crate::invalid;
use crate::raster::ImageRef;

/// The lip-colour score's weights on (r, g) and its bias.
#[derive(Clone, Copy, Debug)]
pub struct LipColour {
    pub weights: [f64; 2],
    pub bias: f64,
}

/// One search: from `at` along the unit `normal`, for a transition whose score rises
/// (`sign` = +1) or falls (−1) along the normal, nearest to the offset `expect` (px).
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    pub at: [f64; 2],
    pub normal: [f64; 2],
    pub sign: f64,
    pub expect: f64,
}

/// Search range ±`reach` px, smoothing σ `sigma` px (0: none), smallest step `min_step`
/// (score units per px).
#[derive(Clone, Copy, Debug)]
pub struct SearchSettings {
    pub reach: f64,
    pub sigma: f64,
    pub min_step: f64,
}

/// Largest search reach (px) accepted.
pub const MAX_REACH: f64 = 256.0;

/// The offset (px along the normal) of each probe's transition, NaN where none was found.
/// `image` is (H, W, 3) RGB.
pub fn find_edges(
    image: &ImageRef,
    colour: &LipColour,
    probes: &[Probe],
    s: &SearchSettings,
) -> Result<Vec<f64>> {
    if image.channels != 3 {
        return invalid!("the image must be RGB, got {} channels", image.channels);
    }
    if !(s.reach.is_finite() && (1.0..=MAX_REACH).contains(&s.reach)) {
        return invalid!("reach must be 1 to {MAX_REACH} px, got {}", s.reach);
    }
    if !((0.0..=s.reach).contains(&s.sigma) && s.min_step.is_finite()) {
        return invalid!(
            "sigma must be 0 to the reach and min_step finite, got {} and {}",
            s.sigma,
            s.min_step
        );
    }
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !finite(&[colour.weights[0], colour.weights[1], colour.bias]) {
        return invalid!("the lip colour must be finite, got {colour:?}");
    }
    if let Some(p) = probes
        .iter()
        .find(|p| !finite(&[p.at[0], p.at[1], p.normal[0], p.normal[1], p.sign, p.expect]))
    {
        return invalid!("probes must be finite, got {p:?}");
    }
    let n = s.reach.floor() as usize;
    let kernel = gaussian(s.sigma);
    let mut profile = vec![0.0; 2 * n + 1];
    let mut smooth = vec![0.0; 2 * n + 1];
    Ok(probes
        .iter()
        .map(|p| {
            for (k, v) in profile.iter_mut().enumerate() {
                let t = k as f64 - n as f64;
                let rgb = bilinear(image, p.at[0] + t * p.normal[0], p.at[1] + t * p.normal[1]);
                *v = score(colour, rgb);
            }
            convolve(&profile, &kernel, &mut smooth);
            nearest_step(&smooth, p.sign, p.expect + n as f64, s.min_step)
                .map_or(f64::NAN, |k| k - n as f64)
        })
        .collect())
}

/// The score averaged over the 3×3 pixels nearest each of `points` (the pixel the point rounds
/// to, ties to even, and its eight neighbours, clamped to the image). `image` is (H, W, 3) RGB.
pub fn scores_near(image: &ImageRef, colour: &LipColour, points: &[[f64; 2]]) -> Result<Vec<f64>> {
    if image.channels != 3 {
        return invalid!("the image must be RGB, got {} channels", image.channels);
    }
    if let Some(p) = points
        .iter()
        .find(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return invalid!("points must be finite, got {p:?}");
    }
    let clamp = |v: f64, size: usize| v.clamp(0.0, (size - 1) as f64) as usize;
    Ok(points
        .iter()
        .map(|p| {
            let (x, y) = (p[0].round_ties_even(), p[1].round_ties_even());
            let mut total = 0.0;
            for dy in [-1.0, 0.0, 1.0] {
                for dx in [-1.0, 0.0, 1.0] {
                    let (px, py) = (clamp(x + dx, image.width), clamp(y + dy, image.height));
                    let at = (py * image.width + px) * 3;
                    let rgb = std::array::from_fn(|c| image.data[at + c] as f64);
                    total += score(colour, rgb);
                }
            }
            total / 9.0
        })
        .collect())
}

/// The score of every pixel of the box `[x0, y0, x1, y1)` (exclusive ends, inside the image),
/// row by row. `image` is (H, W, 3) RGB.
pub fn score_map(image: &ImageRef, colour: &LipColour, bounds: [usize; 4]) -> Result<Vec<f32>> {
    if image.channels != 3 {
        return invalid!("the image must be RGB, got {} channels", image.channels);
    }
    let [x0, y0, x1, y1] = bounds;
    if x0 > x1 || y0 > y1 || x1 > image.width || y1 > image.height {
        return invalid!(
            "box {bounds:?} is not inside the {}x{} image",
            image.width,
            image.height
        );
    }
    let mut out = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        let row = &image.data[(y * image.width + x0) * 3..(y * image.width + x1) * 3];
        out.extend(
            row.chunks_exact(3)
                .map(|p| score(colour, [p[0] as f64, p[1] as f64, p[2] as f64]) as f32),
        );
    }
    Ok(out)
}

/// For each of `points` (px) and its unit normal, the signed distance t (px) along the normal
/// to the nearest crossing of the polyline `curve`: point + t·normal lies on it; NaN where the
/// normal's line misses every segment (or the curve has fewer than two points).
pub fn normal_gaps(points: &[[f64; 2]], normals: &[[f64; 2]], curve: &[[f64; 2]]) -> Vec<f64> {
    points
        .iter()
        .zip(normals)
        .map(|(p, n)| {
            let mut best = f64::INFINITY;
            for seg in curve.windows(2) {
                let (a, e) = (seg[0], [seg[1][0] - seg[0][0], seg[1][1] - seg[0][1]]);
                let (rx, ry) = (a[0] - p[0], a[1] - p[1]);
                // p + t·n = a + s·e by Cramer's rule: t = num_t / det, s = num_s / det, and
                // 0 ≤ s ≤ 1 without dividing: num_s and det of one sign, |num_s| ≤ |det|.
                let det = n[1] * e[0] - n[0] * e[1];
                let num_t = ry * e[0] - rx * e[1];
                let num_s = n[0] * ry - n[1] * rx;
                if num_s * det >= 0.0 && num_s.abs() <= det.abs() && det != 0.0 {
                    let t = num_t / det;
                    if t.abs() < best.abs() {
                        best = t;
                    }
                }
            }
            if best.is_finite() {
                best
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// The score of an RGB colour.
fn score(c: &LipColour, [r, g, b]: [f64; 3]) -> f64 {
    let sum = r + g + b + 1.0;
    c.weights[0] * r / sum + c.weights[1] * g / sum - c.bias
}

/// The RGB colour at (x, y), bilinear between pixel centres, clamped to the image.
fn bilinear(img: &ImageRef, x: f64, y: f64) -> [f64; 3] {
    let x = x.clamp(0.0, (img.width - 1) as f64);
    let y = y.clamp(0.0, (img.height - 1) as f64);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(img.width - 1), (y0 + 1).min(img.height - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let px = |xx: usize, yy: usize, c: usize| img.data[(yy * img.width + xx) * 3 + c] as f64;
    std::array::from_fn(|c| {
        let top = px(x0, y0, c) * (1.0 - fx) + px(x1, y0, c) * fx;
        let bottom = px(x0, y1, c) * (1.0 - fx) + px(x1, y1, c) * fx;
        top * (1.0 - fy) + bottom * fy
    })
}

/// Normalised Gaussian taps of radius ⌈3σ⌉ (the single tap 1 for σ = 0).
fn gaussian(sigma: f64) -> Vec<f64> {
    if sigma <= 0.0 {
        return vec![1.0];
    }
    let r = (3.0 * sigma).ceil() as isize;
    let taps: Vec<f64> = (-r..=r)
        .map(|k| (-0.5 * (k as f64 / sigma).powi(2)).exp())
        .collect();
    let total: f64 = taps.iter().sum();
    taps.iter().map(|t| t / total).collect()
}

/// `out` = `v` convolved with the odd-length `kernel`, the ends of `v` replicated.
fn convolve(v: &[f64], kernel: &[f64], out: &mut [f64]) {
    let r = (kernel.len() / 2) as isize;
    let last = v.len() as isize - 1;
    for (i, o) in out.iter_mut().enumerate() {
        *o = kernel
            .iter()
            .enumerate()
            .map(|(k, w)| w * v[(i as isize + k as isize - r).clamp(0, last) as usize])
            .sum();
    }
}

/// The position (an index into `v`, refined between samples by a parabola through the peak and
/// its neighbours) of the local maximum of sign · (central difference of `v`) above `min_step`
/// nearest to index `expect`, if any.
fn nearest_step(v: &[f64], sign: f64, expect: f64, min_step: f64) -> Option<f64> {
    let d: Vec<f64> = v.windows(3).map(|w| sign * (w[2] - w[0]) / 2.0).collect();
    (1..d.len().saturating_sub(1))
        .filter(|&j| d[j] >= d[j - 1] && d[j] > d[j + 1] && d[j] > min_step)
        .map(|j| {
            let curve = d[j - 1] - 2.0 * d[j] + d[j + 1];
            let shift = if curve < 0.0 {
                0.5 * (d[j - 1] - d[j + 1]) / curve
            } else {
                0.0
            };
            (j + 1) as f64 + shift
        })
        .min_by(|a, b| (a - expect).abs().total_cmp(&(b - expect).abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 40×40 image: skin above row `edge`, lip colour from it down.
    fn two_tone(edge: usize) -> Vec<u8> {
        let mut img = vec![0u8; 40 * 40 * 3];
        for (i, px) in img.chunks_mut(3).enumerate() {
            px.copy_from_slice(if i / 40 >= edge {
                &[175, 70, 75]
            } else {
                &[205, 160, 140]
            });
        }
        img
    }

    /// Lip minus skin in r, scaled: positive on the lip colour above.
    const COLOUR: LipColour = LipColour {
        weights: [10.0, 0.0],
        bias: 4.0,
    };
    const SETTINGS: SearchSettings = SearchSettings {
        reach: 12.0,
        sigma: 1.0,
        min_step: 0.05,
    };

    fn probe(y: f64, sign: f64, expect: f64) -> Probe {
        Probe {
            at: [20.0, y],
            normal: [0.0, 1.0],
            sign,
            expect,
        }
    }

    #[test]
    fn finds_the_colour_edge_with_the_right_polarity_only() {
        let data = two_tone(25);
        let img = ImageRef::new(&data, 40, 40, 3).unwrap();
        // The edge lies between rows 24 and 25: at +4.5 px from y = 20.
        let found = find_edges(
            &img,
            &COLOUR,
            &[probe(20.0, 1.0, 0.0), probe(20.0, -1.0, 0.0)],
            &SETTINGS,
        )
        .unwrap();
        assert!((found[0] - 4.5).abs() <= 0.1, "{found:?}");
        assert!(found[1].is_nan(), "a falling edge was found: {found:?}");
    }

    #[test]
    fn picks_the_transition_nearest_to_the_expected_offset() {
        // Two rising edges along the probe: skin-lip at row 14 and again at row 30.
        let mut data = two_tone(14);
        let skin = two_tone(40);
        data[22 * 120..30 * 120].copy_from_slice(&skin[22 * 120..30 * 120]);
        let img = ImageRef::new(&data, 40, 40, 3).unwrap();
        let at =
            |expect| find_edges(&img, &COLOUR, &[probe(22.0, 1.0, expect)], &SETTINGS).unwrap()[0];
        assert!((at(-8.0) + 8.5).abs() <= 0.1, "{}", at(-8.0));
        assert!((at(6.0) - 7.5).abs() <= 0.1, "{}", at(6.0));
    }

    #[test]
    fn scores_near_average_the_nine_nearest_pixels() {
        let img = two_tone(20);
        let image = ImageRef::new(&img, 40, 40, 3).unwrap();
        let skin = score(&COLOUR, [205.0, 160.0, 140.0]);
        let lip = score(&COLOUR, [175.0, 70.0, 75.0]);
        // Rows 18..=20 around (10, 19.4): two of skin, one of lip; a corner clamps to skin.
        let got = scores_near(&image, &COLOUR, &[[10.0, 19.4], [5.0, 30.0], [-3.0, -2.0]]).unwrap();
        let expected = [(2.0 * skin + lip) / 3.0, lip, skin];
        for (g, e) in got.iter().zip(expected) {
            assert!((g - e).abs() < 1e-12, "{got:?} vs {expected:?}");
        }
        // 19.5 rounds to 20 (ties to even): rows 19..=21, one of skin, two of lip.
        let tie = scores_near(&image, &COLOUR, &[[10.0, 19.5]]).unwrap()[0];
        assert!((tie - (skin + 2.0 * lip) / 3.0).abs() < 1e-12);
        assert!(scores_near(&image, &COLOUR, &[[f64::NAN, 1.0]]).is_err());
    }

    #[test]
    fn the_score_map_scores_each_pixel_of_the_box() {
        let img = two_tone(20);
        let image = ImageRef::new(&img, 40, 40, 3).unwrap();
        let map = score_map(&image, &COLOUR, [5, 18, 9, 22]).unwrap();
        assert_eq!(map.len(), 16);
        let skin = score(&COLOUR, [205.0, 160.0, 140.0]) as f32;
        let lip = score(&COLOUR, [175.0, 70.0, 75.0]) as f32;
        assert_eq!(&map[..8], &[skin; 8]);
        assert_eq!(&map[8..], &[lip; 8]);
        assert!(score_map(&image, &COLOUR, [5, 18, 41, 22]).is_err());
    }

    #[test]
    fn normal_gaps_reach_the_nearest_crossing_or_nan() {
        // A V-shaped curve, and points looking down (+y) and up onto it.
        let curve = [[0.0, 0.0], [10.0, 10.0], [20.0, 0.0]];
        let points = [[5.0, 8.0], [15.0, 0.0], [30.0, 0.0], [10.0, 10.0]];
        let down = [[0.0, 1.0]; 4];
        let gaps = normal_gaps(&points, &down, &curve);
        assert_eq!(gaps[0], -3.0); // up to (5, 5)
        assert_eq!(gaps[1], 5.0); // down to (15, 5)
        assert!(gaps[2].is_nan()); // beyond the curve's ends
        assert_eq!(gaps[3], 0.0); // on the curve's vertex
        assert!(normal_gaps(&points[..1], &down[..1], &curve[..1])[0].is_nan());
    }

    #[test]
    fn rejects_a_grey_image_and_a_bad_reach() {
        let data = two_tone(25);
        let img = ImageRef::new(&data, 40, 40, 3).unwrap();
        let bad = SearchSettings {
            reach: 0.5,
            ..SETTINGS
        };
        assert!(find_edges(&img, &COLOUR, &[], &bad).is_err());
        let grey = vec![9u8; 40 * 40];
        let img = ImageRef::new(&grey, 40, 40, 1).unwrap();
        assert!(find_edges(&img, &COLOUR, &[], &SETTINGS).is_err());
    }
}
