//! The energies of one curve (docs/method.md §1) and of the knot pairs that couple curves, each
//! returned with its gradient with respect to the knot coordinates.
//!
//! For a curve with knots K_0..K_m, rest knots R_0..R_m, starting knots S_0..S_m and chord Δ:
//!
//! ```text
//! E1 = m·α/Δ²        Σ_{k=1..m}   |(K_k − K_{k−1}) − (R_k − R_{k−1})|²          (eq. 12)
//! E2 = m·β/(n·Δ²)    Σ_{k=1..m−1} |(2K_k − K_{k−1} − K_{k+1}) − (same of R)|²    (eq. 13)
//! Et = τ/((m+1)·Δ²)  Σ_{k=0..m}   |K_k − S_k|²                                  (eq. 14)
//! Ec = ρ/(p+1)       Σ_{i=0..p}   H(x_i)                                        (eq. 15)
//! Ev = γ/(p+1)       Σ_{i=0..p}   (L(x_i) − L'(x_i))²                           (eq. 16)
//! E  = E1 + E2 + Et − Ec − Ev
//! ```
//!
//! With all rest knots equal (zero rest edges) E1 and E2 are the paper's own terms. The image
//! sums are means over the p+1 = m·n+1 curve points so that ρ and γ do not depend on n.
//! H is, for the `Directional` operator, the derivative along the curve's unit normal
//! (the segment direction turned +90°, i.e. "down" for a curve running image-left to image-right)
//! weighted per channel: `H = wL·(n·∇L) + wC·(n·∇C)`; the signs of wL, wC give the polarity of the
//! edge. For `Magnitude`, `H = wL·|∇L| + wC·|∇C|`. The normal is held fixed while differentiating.

use super::field::{Field, CX, CY, FIELD_CHANNELS, L, LPREV, LX, LY};

/// The image operator H of a curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operator {
    /// Signed derivative along the curve normal (matched to the edge's polarity).
    Directional,
    /// Gradient magnitude (polarity-blind; the paper's Figure 3 problem).
    Magnitude,
}

/// Weights of one curve. `luma`, `chroma`: signed channel weights of H.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveParams {
    pub alpha: f64,
    pub beta: f64,
    pub tau: f64,
    pub rho: f64,
    pub gamma: f64,
    pub luma: f64,
    pub chroma: f64,
    pub operator: Operator,
}

/// How a pair of knots (a, b) is coupled. The gap is g = down · (K_b − K_a) in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairKind {
    /// E = w·max(0, target − g)²: b stays at least `target` below a (repulsion).
    MinGap,
    /// E = w·(g − target)²: the gap is held (brow thickness constancy).
    Keep,
}

/// A coupling between knots `a` and `b` of the shared knot array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSpec {
    pub a: usize,
    pub b: usize,
    pub kind: PairKind,
    pub weight: f64,
}

type P2 = [f64; 2];

#[inline]
fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline]
fn add_to(g: &mut P2, v: P2, s: f64) {
    g[0] += s * v[0];
    g[1] += s * v[1];
}

/// Internal energies E1 + E2 + Et of one curve; adds their gradient to `grad` (indexed like
/// `knots`, through `idx`). `chord2` is Δ², `n` the points per segment.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn internal(
    idx: &[usize],
    knots: &[P2],
    rest: &[P2],
    start: &[P2],
    p: &CurveParams,
    n: usize,
    chord2: f64,
    grad: &mut [P2],
) -> f64 {
    let m = idx.len() - 1;
    let c1 = m as f64 * p.alpha / chord2;
    let c2 = m as f64 * p.beta / (n as f64 * chord2);
    let ct = p.tau / ((m + 1) as f64 * chord2);
    let mut e = 0.0;
    for k in 1..=m {
        let (i, j) = (idx[k - 1], idx[k]);
        let d = sub(sub(knots[j], knots[i]), sub(rest[j], rest[i]));
        e += c1 * (d[0] * d[0] + d[1] * d[1]);
        add_to(&mut grad[j], d, 2.0 * c1);
        add_to(&mut grad[i], d, -2.0 * c1);
    }
    for k in 1..m {
        let (h, i, j) = (idx[k - 1], idx[k], idx[k + 1]);
        let bend = |q: &[P2]| {
            [
                2.0 * q[i][0] - q[h][0] - q[j][0],
                2.0 * q[i][1] - q[h][1] - q[j][1],
            ]
        };
        let d = sub(bend(knots), bend(rest));
        e += c2 * (d[0] * d[0] + d[1] * d[1]);
        add_to(&mut grad[i], d, 4.0 * c2);
        add_to(&mut grad[h], d, -2.0 * c2);
        add_to(&mut grad[j], d, -2.0 * c2);
    }
    for &i in idx {
        let d = sub(knots[i], start[i]);
        e += ct * (d[0] * d[0] + d[1] * d[1]);
        add_to(&mut grad[i], d, 2.0 * ct);
    }
    e
}

/// Image energies −(Ec + Ev) of one curve; adds their gradient to `grad`. Returns
/// (energy, mean H over the curve points).
#[inline(always)]
pub(crate) fn image(
    idx: &[usize],
    knots: &[P2],
    field: &Field<'_>,
    p: &CurveParams,
    n: usize,
    fallback_normal: P2,
    grad: &mut [P2],
) -> (f64, f64) {
    let m = idx.len() - 1;
    let count = (m * n + 1) as f64;
    let (wc, wv) = (p.rho / count, p.gamma / count);
    let (mut e, mut sum_h) = (0.0, 0.0);
    for seg in 0..m {
        let (a, b) = (idx[seg], idx[seg + 1]);
        let dir = sub(knots[b], knots[a]);
        let len = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
        let normal = if len > 1e-9 {
            [-dir[1] / len, dir[0] / len]
        } else {
            fallback_normal
        };
        let last = if seg + 1 == m { n } else { n - 1 };
        for s in 0..=last {
            let t = s as f64 / n as f64;
            let x = knots[a][0] + t * dir[0];
            let y = knots[a][1] + t * dir[1];
            let (h, gh, v, gv) = point_terms(field, x, y, normal, p);
            sum_h += h;
            e -= wc * h + wv * v;
            let g = [-(wc * gh[0] + wv * gv[0]), -(wc * gh[1] + wv * gv[1])];
            add_to(&mut grad[a], g, 1.0 - t);
            add_to(&mut grad[b], g, t);
        }
    }
    (e, sum_h / count)
}

/// H and (L − L')² at one point with their (x, y) gradients.
#[inline(always)]
fn point_terms(field: &Field<'_>, x: f64, y: f64, nrm: P2, p: &CurveParams) -> (f64, P2, f64, P2) {
    // The derivative channels come first; the lumas only feed the temporal term.
    let s = if p.gamma == 0.0 {
        field.sample::<{ CY + 1 }>(x, y)
    } else {
        field.sample::<FIELD_CHANNELS>(x, y)
    };
    let (v, dx, dy) = (&s.v, &s.dx, &s.dy);
    let f = |a: f32| a as f64;
    let (h, gh) = match p.operator {
        Operator::Directional => {
            let along = |cx: usize, cy: usize, d: &[f32; 6]| nrm[0] * f(d[cx]) + nrm[1] * f(d[cy]);
            (
                p.luma * along(LX, LY, v) + p.chroma * along(CX, CY, v),
                [
                    p.luma * along(LX, LY, dx) + p.chroma * along(CX, CY, dx),
                    p.luma * along(LX, LY, dy) + p.chroma * along(CX, CY, dy),
                ],
            )
        }
        Operator::Magnitude => {
            let mut h = 0.0;
            let mut g = [0.0; 2];
            for (w, cx, cy) in [(p.luma, LX, LY), (p.chroma, CX, CY)] {
                let mag = f(v[cx]).hypot(f(v[cy]));
                h += w * mag;
                if mag > 1e-9 {
                    g[0] += w * (f(v[cx]) * f(dx[cx]) + f(v[cy]) * f(dx[cy])) / mag;
                    g[1] += w * (f(v[cx]) * f(dy[cx]) + f(v[cy]) * f(dy[cy])) / mag;
                }
            }
            (h, g)
        }
    };
    if p.gamma == 0.0 {
        return (h, gh, 0.0, [0.0; 2]);
    }
    let d = f(v[L]) - f(v[LPREV]);
    let gv = [
        2.0 * d * (f(dx[L]) - f(dx[LPREV])),
        2.0 * d * (f(dy[L]) - f(dy[LPREV])),
    ];
    (h, gh, d * d, gv)
}

/// Energy of one pair with target gap `target` (pixels); adds its gradient to `grad`.
#[inline(always)]
pub(crate) fn pair(spec: &PairSpec, target: f64, knots: &[P2], down: P2, grad: &mut [P2]) -> f64 {
    let d = sub(knots[spec.b], knots[spec.a]);
    let gap = down[0] * d[0] + down[1] * d[1];
    let r = match spec.kind {
        PairKind::MinGap => (target - gap).max(0.0),
        PairKind::Keep => target - gap,
    };
    add_to(&mut grad[spec.b], down, -2.0 * spec.weight * r);
    add_to(&mut grad[spec.a], down, 2.0 * spec.weight * r);
    spec.weight * r * r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(alpha: f64, beta: f64) -> CurveParams {
        CurveParams {
            alpha,
            beta,
            tau: 0.0,
            rho: 0.0,
            gamma: 0.0,
            luma: 0.0,
            chroma: 0.0,
            operator: Operator::Directional,
        }
    }

    /// Evenly spaced collinear knots: E1 = α ("equal to 1 only for rectilinear curves") and E2 = 0.
    #[test]
    fn straight_evenly_spaced_knots_give_e1_alpha_and_e2_zero() {
        for m in [1usize, 3, 7, 10] {
            let knots: Vec<P2> = (0..=m)
                .map(|k| [5.0 + 4.0 * k as f64, 2.0 + 3.0 * k as f64])
                .collect();
            let idx: Vec<usize> = (0..=m).collect();
            let rest = vec![[0.0; 2]; m + 1];
            let chord2 = (4.0 * m as f64).powi(2) + (3.0 * m as f64).powi(2);
            let mut g = vec![[0.0; 2]; m + 1];
            let e1 = internal(
                &idx,
                &knots,
                &rest,
                &knots,
                &params(7.5, 0.0),
                3,
                chord2,
                &mut g,
            );
            assert!((e1 - 7.5).abs() < 1e-9, "m={m}: E1={e1}");
            let mut g = vec![[0.0; 2]; m + 1];
            let e2 = internal(
                &idx,
                &knots,
                &rest,
                &knots,
                &params(0.0, 9.0),
                3,
                chord2,
                &mut g,
            );
            assert!(e2.abs() < 1e-12, "m={m}: E2={e2}");
            assert!(g.iter().all(|v| v[0].abs() < 1e-12 && v[1].abs() < 1e-12));
        }
    }

    /// The weights of eq. 13 and 14 as written: E2 = m·β/(n·Δ²)·Σ|bend|², Et = τ/((m+1)·Δ²)·Σ|K − S|².
    #[test]
    fn bending_and_temporal_energies_have_the_papers_weights() {
        let knots: Vec<P2> = vec![[0.0, 0.0], [2.0, 1.0], [4.0, 0.0]];
        let start: Vec<P2> = knots.iter().map(|k| [k[0] + 0.5, k[1]]).collect();
        let (idx, rest) = (vec![0, 1, 2], vec![[0.0; 2]; 3]);
        let mut g = vec![[0.0; 2]; 3];
        // m = 2, n = 4, Δ² = 16, |bend of K_1|² = |(0, 2)|² = 4: E2 = 2·8/(4·16)·4 = 1.
        let e2 = internal(
            &idx,
            &knots,
            &rest,
            &knots,
            &params(0.0, 8.0),
            4,
            16.0,
            &mut g,
        );
        assert!((e2 - 1.0).abs() < 1e-12, "E2={e2}");
        // Σ|K − S|² = 3·0.25: Et = 64/(3·16)·0.75 = 1.
        let p = CurveParams {
            tau: 64.0,
            ..params(0.0, 0.0)
        };
        let et = internal(&idx, &knots, &rest, &start, &p, 4, 16.0, &mut g);
        assert!((et - 1.0).abs() < 1e-12, "Et={et}");
    }

    /// The analytic gradient of the internal energies matches finite differences.
    #[test]
    fn internal_gradient_matches_finite_differences() {
        let knots: Vec<P2> = vec![[0.0, 0.0], [3.0, 1.5], [7.0, -0.5], [9.5, 2.0], [14.0, 0.0]];
        let rest: Vec<P2> = vec![[0.0, 1.0], [4.0, 1.0], [7.0, 0.0], [10.0, 1.0], [13.0, 0.0]];
        let start: Vec<P2> = knots.iter().map(|k| [k[0] + 0.7, k[1] - 0.3]).collect();
        let idx: Vec<usize> = (0..5).collect();
        let p = CurveParams {
            tau: 2.0,
            ..params(3.0, 5.0)
        };
        let mut g = vec![[0.0; 2]; 5];
        internal(&idx, &knots, &rest, &start, &p, 3, 150.0, &mut g);
        for k in 0..5 {
            for c in 0..2 {
                let mut plus = knots.clone();
                let mut minus = knots.clone();
                plus[k][c] += 1e-5;
                minus[k][c] -= 1e-5;
                let mut scratch = vec![[0.0; 2]; 5];
                let ep = internal(&idx, &plus, &rest, &start, &p, 3, 150.0, &mut scratch);
                let em = internal(&idx, &minus, &rest, &start, &p, 3, 150.0, &mut scratch);
                let fd = (ep - em) / 2e-5;
                assert!(
                    (fd - g[k][c]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "knot {k} coord {c}: {fd} vs {}",
                    g[k][c]
                );
            }
        }
    }

    /// A 16x16 field whose channels are bilinear in (x, y), which bilinear sampling reproduces
    /// exactly: the image terms can be computed here by hand at any point.
    fn planes() -> (Vec<f32>, impl Fn(f64, f64) -> [f64; FIELD_CHANNELS]) {
        let at = |x: f64, y: f64| {
            [
                1.0 + 0.1 * x + 0.02 * y,
                0.5 - 0.03 * x + 0.05 * y,
                0.2 + 0.04 * y,
                -0.3 + 0.02 * x,
                0.3 * x + 0.2 * y + 0.01 * x * y,
                0.25 * x - 0.1 * y,
            ]
        };
        let mut d = vec![0.0f32; 16 * 16 * FIELD_CHANNELS];
        for y in 0..16 {
            for x in 0..16 {
                let v = at(x as f64, y as f64);
                for c in 0..FIELD_CHANNELS {
                    d[(y * 16 + x) * FIELD_CHANNELS + c] = v[c] as f32;
                }
            }
        }
        (d, at)
    }

    /// −(Ec + Ev) and the mean H are the means over the m·n+1 curve points of eq. 15 and 16,
    /// with the normal of each segment turned +90° from its direction.
    #[test]
    fn image_energy_is_minus_the_weighted_means_of_h_and_the_temporal_term() {
        let (data, at) = planes();
        let field = Field::new(&data, 16, 16, [0.0, 0.0]).unwrap();
        let knots: Vec<P2> = vec![[2.3, 3.1], [6.7, 4.2], [9.1, 8.6], [12.4, 9.3]];
        let idx: Vec<usize> = (0..4).collect();
        let n = 3;
        // gamma = 0 samples only the derivative channels (the temporal term is off).
        for (operator, luma, chroma, gamma) in [
            (Operator::Directional, 1.5, -0.7, 3.0),
            (Operator::Magnitude, 1.5, 0.7, 3.0),
            (Operator::Directional, 1.5, -0.7, 0.0),
        ] {
            let p = CurveParams {
                rho: 2.0,
                gamma,
                luma,
                chroma,
                operator,
                ..params(0.0, 0.0)
            };
            let (mut sum_h, mut sum_v, mut count) = (0.0, 0.0, 0.0);
            for seg in 0..3 {
                let (a, b) = (knots[seg], knots[seg + 1]);
                let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                let nrm = [-(b[1] - a[1]) / len, (b[0] - a[0]) / len];
                let points = if seg == 2 { n + 1 } else { n };
                for s in 0..points {
                    let t = s as f64 / n as f64;
                    let v = at(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                    sum_h += match operator {
                        Operator::Directional => {
                            luma * (nrm[0] * v[LX] + nrm[1] * v[LY])
                                + chroma * (nrm[0] * v[CX] + nrm[1] * v[CY])
                        }
                        Operator::Magnitude => {
                            luma * v[LX].hypot(v[LY]) + chroma * v[CX].hypot(v[CY])
                        }
                    };
                    sum_v += (v[L] - v[LPREV]).powi(2);
                    count += 1.0;
                }
            }
            assert_eq!(count, 10.0);
            let mut g = vec![[0.0; 2]; 4];
            let (e, mean_h) = image(&idx, &knots, &field, &p, n, [0.0, 1.0], &mut g);
            let want = -(2.0 * sum_h + gamma * sum_v) / count;
            assert!(
                (e - want).abs() < 1e-4 * (1.0 + want.abs()),
                "{operator:?}: E={e} vs {want}"
            );
            assert!(
                (mean_h - sum_h / count).abs() < 1e-5,
                "{operator:?}: mean H={mean_h}"
            );
        }
    }

    /// With the gradient-magnitude operator (no normal to hold fixed) the analytic gradient of the
    /// image energies matches finite differences.
    #[test]
    fn image_gradient_matches_finite_differences() {
        let (data, _) = planes();
        let field = Field::new(&data, 16, 16, [0.0, 0.0]).unwrap();
        let knots: Vec<P2> = vec![[2.3, 3.1], [6.7, 4.2], [9.1, 8.6], [12.4, 9.3]];
        let idx: Vec<usize> = (0..4).collect();
        let p = CurveParams {
            rho: 2.0,
            gamma: 3.0,
            luma: 1.5,
            chroma: 0.7,
            operator: Operator::Magnitude,
            ..params(0.0, 0.0)
        };
        let mut g = vec![[0.0; 2]; 4];
        image(&idx, &knots, &field, &p, 3, [0.0, 1.0], &mut g);
        for k in 0..4 {
            for c in 0..2 {
                let mut plus = knots.clone();
                let mut minus = knots.clone();
                plus[k][c] += 1e-3;
                minus[k][c] -= 1e-3;
                let mut scratch = vec![[0.0; 2]; 4];
                let ep = image(&idx, &plus, &field, &p, 3, [0.0, 1.0], &mut scratch).0;
                let em = image(&idx, &minus, &field, &p, 3, [0.0, 1.0], &mut scratch).0;
                let fd = (ep - em) / 2e-3;
                assert!(
                    (fd - g[k][c]).abs() < 1e-3 * (1.0 + fd.abs()),
                    "knot {k} coord {c}: {fd} vs {}",
                    g[k][c]
                );
            }
        }
    }

    /// At one point, with the normal held fixed, the gradients of H (either operator) and of
    /// (L − L')² match finite differences.
    #[test]
    fn point_gradients_match_finite_differences() {
        let (data, _) = planes();
        let field = Field::new(&data, 16, 16, [0.0, 0.0]).unwrap();
        let nrm = [0.6, -0.8];
        for operator in [Operator::Directional, Operator::Magnitude] {
            let p = CurveParams {
                gamma: 1.0,
                luma: 1.5,
                chroma: -0.7,
                operator,
                ..params(0.0, 0.0)
            };
            let (x, y) = (7.3, 5.6);
            let (_, gh, _, gv) = point_terms(&field, x, y, nrm, &p);
            for c in 0..2 {
                let e = 1e-3;
                let (dx, dy) = if c == 0 { (e, 0.0) } else { (0.0, e) };
                let (hp, _, vp, _) = point_terms(&field, x + dx, y + dy, nrm, &p);
                let (hm, _, vm, _) = point_terms(&field, x - dx, y - dy, nrm, &p);
                let (fh, fv) = ((hp - hm) / (2.0 * e), (vp - vm) / (2.0 * e));
                assert!(
                    (fh - gh[c]).abs() < 1e-3 * (1.0 + fh.abs()),
                    "{operator:?} H {c}: {fh} vs {}",
                    gh[c]
                );
                assert!(
                    (fv - gv[c]).abs() < 1e-3 * (1.0 + fv.abs()),
                    "{operator:?} V {c}: {fv} vs {}",
                    gv[c]
                );
            }
        }
    }

    /// Keep holds the gap g = down·(K_b − K_a) at its target from either side: E = w·(target − g)².
    #[test]
    fn keep_holds_the_gap_along_down() {
        let spec = PairSpec {
            a: 0,
            b: 1,
            kind: PairKind::Keep,
            weight: 2.0,
        };
        let down = [0.6, 0.8];
        // g = 0.6·1 + 0.8·5 = 4.6, target 3: r = −1.6, E = 2·2.56, dE/dK_b = −2·w·r·down.
        let mut g = vec![[0.0; 2]; 2];
        let e = pair(&spec, 3.0, &[[0.0, 0.0], [1.0, 5.0]], down, &mut g);
        assert!((e - 5.12).abs() < 1e-12, "E={e}");
        let want = [6.4 * 0.6, 6.4 * 0.8];
        for c in 0..2 {
            assert!((g[1][c] - want[c]).abs() < 1e-12 && (g[0][c] + want[c]).abs() < 1e-12);
        }
    }

    #[test]
    fn min_gap_pushes_apart_only_when_too_close() {
        let spec = PairSpec {
            a: 0,
            b: 1,
            kind: PairKind::MinGap,
            weight: 2.0,
        };
        let mut g = vec![[0.0; 2]; 2];
        let e = pair(&spec, 3.0, &[[0.0, 0.0], [0.0, 1.0]], [0.0, 1.0], &mut g);
        assert_eq!(e, 8.0);
        assert!(
            g[1][1] < 0.0 && g[0][1] > 0.0,
            "descent moves b down and a up"
        );
        let mut g = vec![[0.0; 2]; 2];
        assert_eq!(
            pair(&spec, 3.0, &[[0.0, 0.0], [0.0, 4.0]], [0.0, 1.0], &mut g),
            0.0
        );
        assert_eq!(g, vec![[0.0; 2]; 2]);
    }
}
