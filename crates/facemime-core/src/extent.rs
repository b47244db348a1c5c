//! Bounding boxes of point sets (pixels).

/// The smallest and largest x and y of `points`: ([min x, min y], [max x, max y]); NaN
/// coordinates are skipped, and no points give infinities (min above max).
pub fn extent(points: impl IntoIterator<Item = [f64; 2]>) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// The integer box [x0, y0, x1, y1) around `points`, from the floor of their smallest to the
/// ceiling of their largest coordinates, grown by `margin` pixels and clipped to the
/// `width`×`height` image (x0 and y0 to 0 and up, x1 and y1 to the size and down: a box
/// wholly outside the image comes out empty, x1 ≤ x0 or y1 ≤ y0).
pub fn grown_box(
    points: impl IntoIterator<Item = [f64; 2]>,
    margin: i64,
    width: usize,
    height: usize,
) -> [i64; 4] {
    let (lo, hi) = extent(points);
    [
        (lo[0].floor() as i64 - margin).max(0),
        (lo[1].floor() as i64 - margin).max(0),
        (hi[0].ceil() as i64 + margin).min(width as i64),
        (hi[1].ceil() as i64 + margin).min(height as i64),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_grow_by_the_margin_and_stay_inside_the_image() {
        let pts = [[10.5, 20.2], [30.0, f64::NAN], [40.1, 5.0]];
        assert_eq!(extent(pts), ([10.5, 5.0], [40.1, 20.2]));
        assert_eq!(grown_box(pts, 3, 100, 100), [7, 2, 44, 24]);
        assert_eq!(grown_box(pts, 8, 42, 100), [2, 0, 42, 29]);
        let outside = [[150.0, 10.0], [160.0, 20.0]];
        let [x0, _, x1, _] = grown_box(outside, 2, 100, 100);
        assert!(x1 <= x0);
    }
}
