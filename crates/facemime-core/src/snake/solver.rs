//! The paper's sign-descent solver (eq. 17): from the starting knots, every knot coordinate c
//! takes Q steps `c ← c − δ_q·sign(∂E/∂c)`, δ_q = δ0·σ^q, stopping early when the energy
//! changes by less than `tol`. No coordinate moves more than δ0/(1−σ) pixels in a frame.
//!
//! The early stop is per feature: the curves and pairs that share knots (the mouth's four
//! curves; one brow's two) form a group with its own energy, and a group stops on its own
//! change. So each feature is solved exactly as it would be alone, and one feature still
//! converging does not keep another moving (nor its stop end another's).

use super::energy::{self, CurveParams, PairSpec};
use super::field::Field;
use crate::error::Result;
use crate::invalid;

type P2 = [f64; 2];
/// Per knot, whether it stays where it starts (see [`Problem::solve_some`]).
type Held<'a> = Option<&'a [bool]>;

/// Solver settings shared by all curves of a problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Points per segment n (≥ 1).
    pub points_per_segment: usize,
    /// First step δ0 in pixels (> 0).
    pub delta0: f64,
    /// Step ratio σ in (0, 1).
    pub sigma: f64,
    /// At most Q iterations (1..=1000).
    pub iterations: usize,
    /// A group of coupled curves stops when its |ΔE| < tol between iterations (energy units,
    /// ≥ 0).
    pub tol: f64,
}

/// Curves over one shared knot array, their couplings and the solver settings; built once,
/// solved every frame.
#[derive(Clone, Debug)]
pub struct Problem {
    curves: Vec<(Vec<usize>, CurveParams)>,
    pairs: Vec<PairSpec>,
    n_knots: usize,
    settings: Settings,
    /// Group (connected by curves and pairs) of each knot, curve and pair; number of groups.
    knot_group: Vec<usize>,
    curve_group: Vec<usize>,
    pair_group: Vec<usize>,
    n_groups: usize,
}

/// One frame's input. Slices are indexed like the shared knot array.
#[derive(Clone, Copy)]
pub struct FrameInput<'a> {
    /// Image field of this frame (see [`Field`]).
    pub field: Field<'a>,
    /// Starting knots (the previous frame's, moved by the head motion); also the Et anchor.
    pub start: &'a [P2],
    /// Rest knots the internal energies measure shape against (all equal: the paper's E1, E2).
    pub rest: &'a [P2],
    /// Unit "down" vector of the head in the image, for pair gaps and zero-length normals.
    pub down: P2,
    /// Target gap of each pair, pixels.
    pub pair_targets: &'a [f64],
    /// Image (width, height): knots are kept within [0, width−1] × [0, height−1].
    pub bounds: [f64; 2],
}

/// The solved knots with the iterations run, the final total energy and each curve's mean H.
#[derive(Clone, Debug)]
pub struct Solution {
    pub knots: Vec<P2>,
    pub iterations: usize,
    pub energy: f64,
    pub response: Vec<f64>,
}

impl Problem {
    /// Validates and builds a problem over `n_knots` shared knots.
    pub fn new(
        curves: Vec<(Vec<usize>, CurveParams)>,
        pairs: Vec<PairSpec>,
        n_knots: usize,
        settings: Settings,
    ) -> Result<Self> {
        if curves.is_empty() {
            return invalid!("a snake problem needs at least one curve");
        }
        for (c, (idx, p)) in curves.iter().enumerate() {
            if idx.len() < 2 {
                return invalid!("curve {c} must have at least 2 knots, got {}", idx.len());
            }
            if let Some(&bad) = idx.iter().find(|&&i| i >= n_knots) {
                return invalid!("curve {c} knot index {bad} is out of range for {n_knots} knots");
            }
            let w = [p.alpha, p.beta, p.tau, p.rho, p.gamma, p.luma, p.chroma];
            if !w.iter().all(|v| v.is_finite())
                || [p.alpha, p.beta, p.tau, p.rho, p.gamma]
                    .iter()
                    .any(|&v| v < 0.0)
            {
                return invalid!(
                    "curve {c} weights must be finite and alpha, beta, tau, rho, gamma >= 0"
                );
            }
        }
        for (k, q) in pairs.iter().enumerate() {
            if q.a >= n_knots || q.b >= n_knots || q.a == q.b {
                return invalid!(
                    "pair {k} must join two different knots below {n_knots}, got ({}, {})",
                    q.a,
                    q.b
                );
            }
            if !(q.weight.is_finite() && q.weight >= 0.0) {
                return invalid!("pair {k} weight must be finite and >= 0, got {}", q.weight);
            }
        }
        let s = &settings;
        if s.points_per_segment == 0 || s.points_per_segment > 64 {
            return invalid!(
                "points per segment must be in 1..=64, got {}",
                s.points_per_segment
            );
        }
        if !(s.delta0.is_finite() && s.delta0 > 0.0) {
            return invalid!(
                "delta0 must be a positive number of pixels, got {}",
                s.delta0
            );
        }
        if !(s.sigma > 0.0 && s.sigma < 1.0) {
            return invalid!("sigma must be in (0, 1), got {}", s.sigma);
        }
        if s.iterations == 0 || s.iterations > 1000 {
            return invalid!("iterations must be in 1..=1000, got {}", s.iterations);
        }
        if !(s.tol.is_finite() && s.tol >= 0.0) {
            return invalid!("tol must be finite and >= 0, got {}", s.tol);
        }
        let knot_group = groups(&curves, &pairs, n_knots);
        let n_groups = knot_group.iter().max().map_or(0, |g| g + 1);
        Ok(Problem {
            curve_group: curves.iter().map(|(idx, _)| knot_group[idx[0]]).collect(),
            pair_group: pairs.iter().map(|q| knot_group[q.a]).collect(),
            curves,
            pairs,
            n_knots,
            settings,
            knot_group,
            n_groups,
        })
    }

    pub fn n_knots(&self) -> usize {
        self.n_knots
    }

    /// Whether a curve that weighs the colour channel has one of `knots`.
    pub(crate) fn reads_colour(&self, knots: &[usize]) -> bool {
        self.curves
            .iter()
            .any(|(idx, p)| p.chroma != 0.0 && idx.iter().any(|i| knots.contains(i)))
    }

    pub fn n_curves(&self) -> usize {
        self.curves.len()
    }

    pub fn n_pairs(&self) -> usize {
        self.pairs.len()
    }

    /// Runs the solver on one frame.
    pub fn solve(&self, input: &FrameInput<'_>) -> Result<Solution> {
        self.solve_some(input, &vec![true; self.curves.len()], None)
    }

    /// Runs the solver on one frame for the features (groups of coupled curves) of the curves
    /// flagged in `curves` only: the other features' knots stay at the start, their curves are
    /// not evaluated and their response is NaN. Each solved feature gets exactly the knots,
    /// iterations and response it gets from [`Problem::solve`]; the energy is the solved
    /// features'. The knots flagged in `held`, if given (one flag per knot), stay at the start
    /// too: their curves still read the image and pull on the others through the couplings.
    pub fn solve_some(
        &self,
        input: &FrameInput<'_>,
        curves: &[bool],
        held: Held,
    ) -> Result<Solution> {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::has_avx2_fma() {
            // SAFETY: AVX2 and FMA are present.
            return unsafe { self.solve_avx2(input, curves, held) };
        }
        self.solve_body(input, curves, held)
    }

    /// [`Problem::solve_some`] compiled for AVX2 and FMA: the same operations (Rust never fuses
    /// a product and a sum on its own), in fewer instructions.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn solve_avx2(
        &self,
        input: &FrameInput,
        curves: &[bool],
        held: Held,
    ) -> Result<Solution> {
        self.solve_body(input, curves, held)
    }

    /// [`Problem::solve_some`]'s work.
    #[inline(always)]
    fn solve_body(&self, input: &FrameInput, curves: &[bool], held: Held) -> Result<Solution> {
        if curves.len() != self.curves.len() {
            return invalid!(
                "the curve mask must have {} values, got {}",
                self.curves.len(),
                curves.len()
            );
        }
        if let Some(h) = held.filter(|h| h.len() != self.n_knots) {
            return invalid!(
                "the held-knot mask must have {} values, got {}",
                self.n_knots,
                h.len()
            );
        }
        let mut moving = vec![false; self.n_groups];
        for (&on, &g) in curves.iter().zip(&self.curve_group) {
            moving[g] |= on;
        }
        let active = moving.clone();
        let mut ws = self.workspace(input)?;
        let mut knots = input.start.to_vec();
        let [xmax, ymax] = [input.bounds[0] - 1.0, input.bounds[1] - 1.0];
        let mut energy = self.evaluate(&knots, input, &active, &mut ws);
        let s = &self.settings;
        let mut step = s.delta0;
        let mut iterations = 0;
        let mut before = ws.group_energy.clone();
        while iterations < s.iterations && moving.contains(&true) {
            for (i, ((k, g), &group)) in knots
                .iter_mut()
                .zip(&ws.grad)
                .zip(&self.knot_group)
                .enumerate()
            {
                if moving[group] && !held.is_some_and(|h| h[i]) {
                    k[0] = (k[0] - step * sign(g[0])).clamp(0.0, xmax);
                    k[1] = (k[1] - step * sign(g[1])).clamp(0.0, ymax);
                }
            }
            step *= s.sigma;
            iterations += 1;
            energy = self.evaluate(&knots, input, &active, &mut ws);
            for ((go, e), e0) in moving.iter_mut().zip(&ws.group_energy).zip(&before) {
                if (e - e0).abs() < s.tol {
                    *go = false;
                }
            }
            before.copy_from_slice(&ws.group_energy);
        }
        Ok(Solution {
            knots,
            iterations,
            energy,
            response: ws.response,
        })
    }

    /// Total energy and each curve's mean H at the starting knots, without moving them.
    pub fn evaluate_start(&self, input: &FrameInput<'_>) -> Result<(f64, Vec<f64>)> {
        let mut ws = self.workspace(input)?;
        let e = self.evaluate(input.start, input, &vec![true; self.n_groups], &mut ws);
        Ok((e, ws.response))
    }

    /// Checks a frame's input and allocates the buffers one solve needs (once per frame).
    fn workspace(&self, input: &FrameInput<'_>) -> Result<Workspace> {
        self.check(input)?;
        Ok(Workspace {
            chords: self
                .curves
                .iter()
                .map(|(idx, _)| chord2(idx, input.rest, input.start))
                .collect(),
            grad: vec![[0.0; 2]; self.n_knots],
            response: vec![0.0; self.curves.len()],
            group_energy: vec![0.0; self.n_groups],
        })
    }

    /// Total energy at `knots` of the `active` groups; writes its gradient and each of their
    /// curves' mean H into `ws` (NaN for the other curves).
    #[inline(always)]
    fn evaluate(
        &self,
        knots: &[P2],
        input: &FrameInput<'_>,
        active: &[bool],
        ws: &mut Workspace,
    ) -> f64 {
        ws.grad.iter_mut().for_each(|g| *g = [0.0; 2]);
        ws.group_energy.iter_mut().for_each(|e| *e = 0.0);
        let n = self.settings.points_per_segment;
        for (c, (idx, p)) in self.curves.iter().enumerate() {
            if !active[self.curve_group[c]] {
                ws.response[c] = f64::NAN;
                continue;
            }
            let ei = energy::internal(
                idx,
                knots,
                input.rest,
                input.start,
                p,
                n,
                ws.chords[c],
                &mut ws.grad,
            );
            let (ex, h) = energy::image(idx, knots, &input.field, p, n, input.down, &mut ws.grad);
            ws.group_energy[self.curve_group[c]] += ei + ex;
            ws.response[c] = h;
        }
        for ((q, &target), &group) in self
            .pairs
            .iter()
            .zip(input.pair_targets)
            .zip(&self.pair_group)
            .filter(|&(_, &group)| active[group])
        {
            ws.group_energy[group] += energy::pair(q, target, knots, input.down, &mut ws.grad);
        }
        ws.group_energy.iter().sum()
    }

    fn check(&self, input: &FrameInput<'_>) -> Result<()> {
        let k = self.n_knots;
        if input.start.len() != k || input.rest.len() != k {
            return invalid!(
                "start and rest must have {k} knots, got {} and {}",
                input.start.len(),
                input.rest.len()
            );
        }
        if input.pair_targets.len() != self.pairs.len() {
            return invalid!(
                "pair targets must have {} values, got {}",
                self.pairs.len(),
                input.pair_targets.len()
            );
        }
        let finite = |pts: &[P2]| pts.iter().all(|p| p[0].is_finite() && p[1].is_finite());
        if !finite(input.start)
            || !finite(input.rest)
            || !input.pair_targets.iter().all(|t| t.is_finite())
        {
            return invalid!("knots, rest knots and pair targets must be finite");
        }
        let [dx, dy] = input.down;
        let unit_error = ((dx * dx + dy * dy).sqrt() - 1.0).abs();
        if unit_error.is_nan() || unit_error >= 1e-6 {
            return invalid!("down must be a unit vector, got ({dx}, {dy})");
        }
        let [w, h] = input.bounds;
        if !(w >= 1.0 && h >= 1.0 && w.is_finite() && h.is_finite()) {
            return invalid!("image bounds must be at least 1x1, got {w}x{h}");
        }
        Ok(())
    }
}

/// Per-solve buffers: each curve's Δ², the energy gradient per knot, each curve's mean H,
/// each group's energy.
struct Workspace {
    chords: Vec<f64>,
    grad: Vec<P2>,
    response: Vec<f64>,
    group_energy: Vec<f64>,
}

/// Group of each knot: knots joined by a curve or a pair share a group; groups are numbered
/// 0.. in order of their first knot.
fn groups(curves: &[(Vec<usize>, CurveParams)], pairs: &[PairSpec], n_knots: usize) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..n_knots).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    let links = curves
        .iter()
        .flat_map(|(idx, _)| idx.windows(2).map(|w| (w[0], w[1])))
        .chain(pairs.iter().map(|q| (q.a, q.b)));
    for (a, b) in links {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra.max(rb)] = ra.min(rb);
    }
    let mut number = vec![usize::MAX; n_knots];
    let mut next = 0;
    (0..n_knots)
        .map(|k| {
            let r = root(&mut parent, k);
            if number[r] == usize::MAX {
                number[r] = next;
                next += 1;
            }
            number[r]
        })
        .collect()
}

fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Δ² of a curve: its rest chord, or its starting chord when the rest knots coincide; at least 1.
fn chord2(idx: &[usize], rest: &[P2], start: &[P2]) -> f64 {
    let d2 = |q: &[P2]| {
        let (a, b) = (q[idx[0]], q[idx[idx.len() - 1]]);
        (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)
    };
    let r = d2(rest);
    (if r > 1.0 { r } else { d2(start) }).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::super::energy::{Operator, PairKind};
    use super::super::field::{FIELD_CHANNELS, L, LX, LY};
    use super::*;
    use proptest::prelude::*;

    const W: usize = 64;
    const H: usize = 48;

    /// Field of a smoothed dark horizontal band (rows ≈ y0..y0+thick) on a bright background.
    fn band_field(y0: f64, thick: f64) -> Vec<f32> {
        let mut d = vec![0.0f32; W * H * FIELD_CHANNELS];
        let lum = |y: f64| {
            let s = |t: f64| 1.0 / (1.0 + (-t / 1.2).exp());
            200.0 - 120.0 * (s(y - y0) - s(y - y0 - thick))
        };
        for y in 0..H {
            for x in 0..W {
                let i = (y * W + x) * FIELD_CHANNELS;
                d[i + L] = lum(y as f64) as f32;
                d[i + LX] = 0.0;
                d[i + LY] = ((lum(y as f64 + 0.5) - lum(y as f64 - 0.5)) as f32).clamp(-1e3, 1e3);
            }
        }
        d
    }

    fn curve_params(luma: f64) -> CurveParams {
        CurveParams {
            alpha: 1.0,
            beta: 1.0,
            tau: 0.1,
            rho: 1.0,
            gamma: 0.0,
            luma,
            chroma: 0.0,
            operator: Operator::Directional,
        }
    }

    fn settings() -> Settings {
        Settings {
            points_per_segment: 3,
            delta0: 2.0,
            sigma: 0.75,
            iterations: 15,
            tol: 0.0,
        }
    }

    /// A frame without pairs whose rest knots are its start, the head upright.
    fn plain_input<'a>(field: Field<'a>, start: &'a [P2]) -> FrameInput<'a> {
        FrameInput {
            field,
            start,
            rest: start,
            down: [0.0, 1.0],
            pair_targets: &[],
            bounds: [W as f64, H as f64],
        }
    }

    fn line(y: f64, x0: f64, count: usize) -> Vec<P2> {
        (0..count).map(|k| [x0 + 5.0 * k as f64, y]).collect()
    }

    #[test]
    fn a_curve_moves_onto_the_edge_of_its_polarity() {
        // Upper edge of the band at y ≈ 20: bright above, dark below, so luma weight −1.
        let data = band_field(20.0, 8.0);
        let field = Field::new(&data, W, H, [0.0, 0.0]).unwrap();
        let idx: Vec<usize> = (0..8).collect();
        let upper = Problem::new(
            vec![(idx.clone(), curve_params(-1.0))],
            vec![],
            8,
            settings(),
        )
        .unwrap();
        let lower = Problem::new(vec![(idx, curve_params(1.0))], vec![], 8, settings()).unwrap();
        let start = line(23.5, 10.0, 8);
        let input = plain_input(field, &start);
        let up = upper.solve(&input).unwrap();
        assert!(
            up.knots.iter().all(|k| (k[1] - 19.5).abs() < 0.6),
            "{:?}",
            up.knots
        );
        let low = lower.solve(&input).unwrap();
        assert!(
            low.knots.iter().all(|k| (k[1] - 27.5).abs() < 0.6),
            "{:?}",
            low.knots
        );
        assert!(up.response[0] > 10.0);
    }

    #[test]
    fn min_gap_keeps_two_curves_from_merging() {
        // Both curves are drawn to the same edge; the pair keeps the lower one 4 px below.
        let data = band_field(20.0, 8.0);
        let field = Field::new(&data, W, H, [0.0, 0.0]).unwrap();
        let p = curve_params(-1.0);
        let curves = vec![((0..5).collect(), p), ((5..10).collect(), p)];
        let pairs: Vec<PairSpec> = (0..5)
            .map(|k| PairSpec {
                a: k,
                b: k + 5,
                kind: PairKind::MinGap,
                weight: 50.0,
            })
            .collect();
        let problem = Problem::new(curves, pairs, 10, settings()).unwrap();
        let mut start = line(19.0, 10.0, 5);
        start.extend(line(24.0, 10.0, 5));
        let input = FrameInput {
            field,
            start: &start,
            rest: &start,
            down: [0.0, 1.0],
            pair_targets: &[4.0; 5],
            bounds: [W as f64, H as f64],
        };
        let sol = problem.solve(&input).unwrap();
        for k in 0..5 {
            assert!(
                sol.knots[k + 5][1] - sol.knots[k][1] > 3.0,
                "{:?}",
                sol.knots
            );
        }
    }

    #[test]
    fn a_feature_stops_on_its_own_energy_as_if_solved_alone() {
        // Curve A starts next to the band's upper edge and settles in a few iterations; curve B
        // (another feature: no shared knot, no pair) starts 4.5 px below the lower edge and keeps
        // moving. A's early stop must not wait for B.
        let data = band_field(20.0, 8.0);
        let p = curve_params(-1.0);
        let s = Settings {
            tol: 0.5,
            ..settings()
        };
        let mut start = line(20.5, 10.0, 5);
        start.extend(line(32.0, 10.0, 5));
        let solve = |curves: Vec<(Vec<usize>, CurveParams)>, n: usize| {
            let field = Field::new(&data, W, H, [0.0, 0.0]).unwrap();
            let input = plain_input(field, &start[..n]);
            Problem::new(curves, vec![], n, s)
                .unwrap()
                .solve(&input)
                .unwrap()
        };
        let alone = solve(vec![((0..5).collect(), p)], 5);
        let joint = solve(
            vec![
                ((0..5).collect(), p),
                ((5..10).collect(), curve_params(1.0)),
            ],
            10,
        );
        assert!(
            alone.iterations < joint.iterations,
            "{} vs {}",
            alone.iterations,
            joint.iterations
        );
        assert_eq!(&joint.knots[..5], &alone.knots[..]);
        assert!(
            (joint.knots[7][1] - 9.0).abs() > 3.0,
            "B moved towards its edge"
        );
    }

    #[test]
    fn solving_some_features_leaves_the_others_and_matches_the_joint_solve() {
        // Two features near the band's two edges; solving only the second one must give its
        // joint-solve knots and response exactly and leave the first at its start.
        let data = band_field(20.0, 8.0);
        let field = Field::new(&data, W, H, [0.0, 0.0]).unwrap();
        let curves = vec![
            ((0..5).collect(), curve_params(-1.0)),
            ((5..10).collect(), curve_params(1.0)),
        ];
        let problem = Problem::new(curves, vec![], 10, settings()).unwrap();
        let mut start = line(22.0, 10.0, 5);
        start.extend(line(30.0, 10.0, 5));
        let input = plain_input(field, &start);
        let joint = problem.solve(&input).unwrap();
        let some = problem.solve_some(&input, &[false, true], None).unwrap();
        assert_eq!(&some.knots[..5], &start[..5]);
        assert_eq!(&some.knots[5..], &joint.knots[5..]);
        assert_ne!(&joint.knots[5..], &start[5..]);
        assert!(some.response[0].is_nan());
        assert_eq!(some.response[1], joint.response[1]);
        assert_eq!(some.iterations, joint.iterations);
        assert!(problem.solve_some(&input, &[true], None).is_err());
        assert!(problem
            .solve_some(&input, &[true, true], Some(&[false]))
            .is_err());
        // Held knots stay at the start; the others of their curve still move.
        let mut held = [true; 10];
        held[6..].fill(false);
        let some = problem
            .solve_some(&input, &[true, true], Some(&held))
            .unwrap();
        assert_eq!(&some.knots[..6], &start[..6]);
        assert!(some.knots[6..].iter().zip(&start[6..]).all(|(k, s)| k != s));
    }

    #[test]
    fn bad_problems_and_inputs_are_refused() {
        let p = curve_params(1.0);
        assert!(Problem::new(vec![(vec![0], p)], vec![], 1, settings()).is_err());
        assert!(Problem::new(vec![(vec![0, 3], p)], vec![], 3, settings()).is_err());
        assert!(Problem::new(
            vec![(vec![0, 1], p)],
            vec![],
            2,
            Settings {
                sigma: 1.0,
                ..settings()
            }
        )
        .is_err());
        let problem = Problem::new(vec![(vec![0, 1], p)], vec![], 2, settings()).unwrap();
        let data = band_field(20.0, 8.0);
        let field = Field::new(&data, W, H, [0.0, 0.0]).unwrap();
        let start = [[0.0, f64::NAN], [1.0, 1.0]];
        let input = FrameInput {
            field,
            start: &start,
            rest: &start,
            down: [0.0, 1.0],
            pair_targets: &[],
            bounds: [64.0, 48.0],
        };
        assert!(problem.solve(&input).is_err());
    }

    proptest! {
        /// Whatever the image, no coordinate moves more than δ0/(1−σ) in a frame and no knot
        /// leaves the image.
        #[test]
        fn moves_are_bounded_and_knots_stay_in_the_image(
            seed in proptest::collection::vec(-50.0f32..50.0, W * H * FIELD_CHANNELS / 64),
            x0 in -10.0f64..70.0, y0 in -10.0f64..60.0,
            delta0 in 0.1f64..6.0, sigma in 0.05f64..0.95, iterations in 1usize..40,
        ) {
            let data: Vec<f32> = (0..W * H * FIELD_CHANNELS).map(|i| seed[i % seed.len()] * ((i % 7) as f32 - 3.0)).collect();
            let field = Field::new(&data, W, H, [3.0, -2.0]).unwrap();
            let s = Settings { points_per_segment: 3, delta0, sigma, iterations, tol: 0.0 };
            let p = curve_params(1.0);
            let problem = Problem::new(vec![((0..6).collect(), p)], vec![], 6, s).unwrap();
            let start: Vec<P2> = (0..6).map(|k| [(x0 + 4.0 * k as f64).clamp(0.0, 63.0), y0.clamp(0.0, 47.0)]).collect();
            let input = plain_input(field, &start);
            let sol = problem.solve(&input).unwrap();
            let bound = delta0 / (1.0 - sigma) + 1e-9;
            for (k, s0) in sol.knots.iter().zip(&start) {
                prop_assert!((k[0] - s0[0]).abs() <= bound && (k[1] - s0[1]).abs() <= bound);
                prop_assert!(k[0] >= 0.0 && k[0] <= 63.0 && k[1] >= 0.0 && k[1] <= 47.0);
            }
        }
    }
}
