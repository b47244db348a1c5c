//! Border handling shared by the image filters.

/// Index into 0..n mirrored about the end pixels (OpenCV's BORDER_REFLECT_101: …2 1 | 0 1 2 …
/// n−1 | n−2 …), for any `i`.
pub(crate) fn reflect101(mut i: isize, n: usize) -> usize {
    let last = n as isize - 1;
    if last <= 0 {
        return 0;
    }
    while i < 0 || i > last {
        i = if i < 0 { -i } else { 2 * last - i };
    }
    i as usize
}

#[cfg(test)]
mod tests {
    use super::reflect101;

    #[test]
    fn mirrors_about_the_end_pixels_without_repeating_them() {
        let got: Vec<usize> = (-4..8).map(|i| reflect101(i, 4)).collect();
        assert_eq!(got, [2, 3, 2, 1, 0, 1, 2, 3, 2, 1, 0, 1]);
        assert_eq!(reflect101(-3, 1), 0);
    }
}
