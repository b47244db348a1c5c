//! The mouth's rest shape in a frame: the first frame's knots carried by the head's motion,
//! each group (a mouth feature) moved part of the way to the affine map that best carries it
//! onto the knots' starting positions, so that a mouth narrowing into an "O" or opening wide is
//! not pulled back to its neutral shape. Points are pixels.

/// The mean of the points of `pts` at `idx` (not empty), summed in index order.
pub(crate) fn mean_of(pts: &[[f64; 2]], idx: &[usize]) -> [f64; 2] {
    let s = idx
        .iter()
        .fold([0.0, 0.0], |s, &i| [s[0] + pts[i][0], s[1] + pts[i][1]]);
    let n = idx.len() as f64;
    [s[0] / n, s[1] / n]
}

/// `carried` with each group of knot indices moved `amount` (0: not at all, 1: fully) of the
/// way to its affine least-squares fit to `start` (the same knots' starting positions): the
/// linear part from the centred points by the normal equations, or, where the group is
/// (nearly) collinear, from the pseudo-inverse of its rank-one scatter; the translation maps
/// the centroids onto each other. Indices must be inside both arrays (same length).
pub(crate) fn affine_rest(
    carried: &[[f64; 2]],
    start: &[[f64; 2]],
    groups: &[&[usize]],
    amount: f64,
) -> Vec<[f64; 2]> {
    assert_eq!(
        carried.len(),
        start.len(),
        "carried and start differ in length"
    );
    let mut rest = carried.to_vec();
    for idx in groups.iter().filter(|idx| !idx.is_empty()) {
        let (ca, cb) = (mean_of(carried, idx), mean_of(start, idx));
        // Scatter of the centred carried points (gram) and their cross-scatter with the
        // centred starts (cross[r][c] = Σ d_r e_c).
        let (mut gram, mut cross) = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        for &i in idx.iter() {
            let d = [carried[i][0] - ca[0], carried[i][1] - ca[1]];
            let e = [start[i][0] - cb[0], start[i][1] - cb[1]];
            for r in 0..2 {
                for c in 0..2 {
                    gram[r][c] += d[r] * d[c];
                    cross[r][c] += d[r] * e[c];
                }
            }
        }
        let trace = gram[0][0] + gram[1][1];
        let det = gram[0][0] * gram[1][1] - gram[0][1] * gram[1][0];
        let inverse = if det > 1e-9 * trace * trace {
            [
                [gram[1][1] / det, -gram[0][1] / det],
                [-gram[1][0] / det, gram[0][0] / det],
            ]
        } else if trace > 0.0 {
            let t2 = trace * trace;
            [
                [gram[0][0] / t2, gram[0][1] / t2],
                [gram[1][0] / t2, gram[1][1] / t2],
            ]
        } else {
            [[0.0; 2]; 2]
        };
        // The linear part L (points map as d ↦ d·L, row vectors) = inverse · cross.
        let linear: [[f64; 2]; 2] = std::array::from_fn(|r| {
            std::array::from_fn(|c| inverse[r][0] * cross[0][c] + inverse[r][1] * cross[1][c])
        });
        for &i in idx.iter() {
            let d = [carried[i][0] - ca[0], carried[i][1] - ca[1]];
            for c in 0..2 {
                let fit = d[0] * linear[0][c] + d[1] * linear[1][c] + cb[c];
                rest[i][c] += amount * (fit - carried[i][c]);
            }
        }
    }
    rest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_change_is_followed_by_the_amount() {
        let carried = [
            [0.0, 0.0],
            [10.0, 1.0],
            [20.0, 0.0],
            [10.0, -4.0],
            [30.0, 30.0],
        ];
        // The first four knots widened 1.5× and moved (3, 2); the last is in no group.
        let start: Vec<[f64; 2]> = carried
            .iter()
            .map(|p| [1.5 * p[0] + 3.0, p[1] + 2.0])
            .collect();
        let rest = affine_rest(&carried, &start, &[&[0, 1, 2, 3]], 0.5);
        for i in 0..4 {
            for c in 0..2 {
                let want = carried[i][c] + 0.5 * (start[i][c] - carried[i][c]);
                assert!((rest[i][c] - want).abs() < 1e-9, "{i} {c}: {rest:?}");
            }
        }
        assert_eq!(rest[4], carried[4]);
    }

    #[test]
    fn collinear_knots_get_the_least_squares_fit_along_their_line() {
        let carried = [[0.0, 5.0], [10.0, 5.0], [20.0, 5.0]];
        let start = [[0.0, 6.0], [20.0, 6.0], [40.0, 6.0]];
        let rest = affine_rest(&carried, &start, &[&[0, 1, 2]], 1.0);
        for (r, s) in rest.iter().zip(&start) {
            assert!(
                (r[0] - s[0]).abs() < 1e-9 && (r[1] - s[1]).abs() < 1e-9,
                "{rest:?}"
            );
        }
    }
}
