//! A tracker frame's steps around its solver passes ([`solve_frame`](super::solve_frame)), on
//! the tracker's fixed knot layout: where the knots start ([`FramePlan::begin`]), the rest shape
//! and gap targets they are solved against ([`FramePlan::settle`]), and each feature's
//! confidence and shape check afterwards ([`FramePlan::assess`]). One call each, so that a frame
//! crosses from Python to the core a few times rather than once per small step.
//!
//! Pixels: x right, y down, origin at the centre of the top-left pixel; transforms are 2×3
//! matrices mapping one frame's pixels to another's.

use super::frame::{centre_group, chords_within, start_knots};
use super::rest::affine_rest;
use crate::error::Result;
use crate::invalid;
use crate::motion::{scale_and_turn, transformed};

type P2 = [f64; 2];

/// The tracker's fixed layout and first-frame values.
pub struct FramePlan {
    /// The first frame's knots (the rest shape before the head moves), and its downward unit
    /// vector of the mouth.
    pub knots0: Vec<P2>,
    pub down0: P2,
    /// The knot pairs' target gaps on the first frame (they scale with the head), and each
    /// curve's first-frame edge response.
    pub targets0: Vec<f64>,
    pub response0: Vec<f64>,
    /// The largest knot coordinates: the last pixel's centre, (width − 1, height − 1).
    pub bounds: P2,
    /// The mouth's knots, and the fraction of them the flow must follow for their start to be
    /// trusted.
    pub mouth: Vec<usize>,
    pub mouth_patch: f64,
    /// The knot groups whose rest shape follows part (`mouth_affine`) of their affine change.
    pub affine_groups: Vec<Vec<usize>>,
    pub mouth_affine: f64,
    /// The inner and outer mouth's knots, and the fraction of the inner's sideways drift taken
    /// out each frame.
    pub inner: Vec<usize>,
    pub outer: Vec<usize>,
    pub centring: f64,
    /// Per feature: its upper curve's end knots, the least fraction of its rest chord they may
    /// shrink to, and its (upper, lower) curves.
    pub chord_ends: Vec<[usize; 2]>,
    pub least_chord: Vec<f64>,
    pub feature_curves: Vec<[usize; 2]>,
}

/// Where a frame's knots start, by [`FramePlan::begin`].
pub struct Begun {
    /// The starting knots, and with a flow which of them it followed.
    pub start: Vec<P2>,
    pub followed: Option<Vec<bool>>,
    /// Whether the flow followed fewer of the mouth's knots than the plan's fraction.
    pub mouth_unfollowed: bool,
    /// The head's scale since the first frame and the mouth's down vector turned with it.
    pub scale: f64,
    pub down: P2,
}

/// A frame's solver inputs besides the start, by [`FramePlan::settle`].
pub struct Settled {
    /// The first frame's knots carried by the head's motion, the rest shape, the gap targets.
    pub carried: Vec<P2>,
    pub rest: Vec<P2>,
    pub targets: Vec<f64>,
}

/// A frame's outcome per curve and feature, by [`FramePlan::assess`].
pub struct Assessed {
    /// Each curve's edge response over its first frame's, in 0..1; each feature's mean of its
    /// two curves'; whether each feature's chord is sound.
    pub ratio: Vec<f64>,
    pub confidence: Vec<f64>,
    pub shape_ok: Vec<bool>,
}

impl FramePlan {
    /// Checks that every index lies among the knots and curves and the per-feature lists
    /// agree.
    pub fn check(&self) -> Result<()> {
        let (k, c) = (self.knots0.len(), self.response0.len());
        let knots = self
            .mouth
            .iter()
            .chain(self.affine_groups.iter().flatten())
            .chain(&self.inner)
            .chain(&self.outer)
            .chain(self.chord_ends.iter().flatten());
        if let Some(i) = knots.copied().find(|&i| i >= k) {
            return invalid!("knot index {i} is past the {k} knots");
        }
        if let Some(i) = self
            .feature_curves
            .iter()
            .flatten()
            .copied()
            .find(|&i| i >= c)
        {
            return invalid!("curve index {i} is past the {c} curves");
        }
        let f = self.feature_curves.len();
        if self.chord_ends.len() != f || self.least_chord.len() != f {
            return invalid!(
                "{f} features but {} chord ends and {} least chords",
                self.chord_ends.len(),
                self.least_chord.len()
            );
        }
        if !self.bounds.iter().all(|b| b.is_finite() && *b >= 0.0) {
            return invalid!(
                "the bounds must be finite and not negative, got {:?}",
                self.bounds
            );
        }
        if self.inner.is_empty() || self.outer.is_empty() {
            return invalid!("the inner and outer mouth need at least one knot each");
        }
        Ok(())
    }

    /// The frame's starting knots: where the optical `flow` put them (NaN where it failed),
    /// else where the head's `step` carries the previous frame's `knots`; `total` is the
    /// head's motion since the first frame.
    pub fn begin(
        &self,
        step: &[[f64; 3]; 2],
        total: &[[f64; 3]; 2],
        knots: &[P2],
        flow: Option<&[P2]>,
    ) -> Begun {
        let (scale, down) = scale_and_turn(total, self.down0);
        let (start, followed) = match flow {
            None => (transformed(step, knots), None),
            Some(flow) => {
                let (start, followed) = start_knots(step, knots, flow);
                (start, Some(followed))
            }
        };
        let mouth_unfollowed = followed.as_ref().is_some_and(|f| {
            let count = self.mouth.iter().filter(|&&i| f[i]).count();
            (count as f64) < self.mouth_patch * self.mouth.len() as f64
        });
        Begun {
            start,
            followed,
            mouth_unfollowed,
            scale,
            down,
        }
    }

    /// Clips `start` (in place) to the frame, and gives the knots it is solved against: the
    /// first frame's carried by `total`, the rest shape (the mouth's groups following part of
    /// their affine change to `start`) and the gap targets at the head's `scale`.
    pub fn settle(&self, start: &mut [P2], total: &[[f64; 3]; 2], scale: f64) -> Settled {
        for p in start.iter_mut() {
            for (v, hi) in p.iter_mut().zip(self.bounds) {
                // numpy's minimum(maximum(v, 0), hi): NaN stays NaN.
                *v = v.clamp(0.0, hi);
            }
        }
        let carried = transformed(total, &self.knots0);
        let rest = self.rest(&carried, start);
        let targets = self.targets0.iter().map(|t| t * scale).collect();
        Settled {
            carried,
            rest,
            targets,
        }
    }

    /// The rest shape: `carried` (the first frame's knots moved by the head) with each of the
    /// plan's affine groups moved its fraction of the way to its affine least-squares fit to
    /// `start`.
    pub fn rest(&self, carried: &[P2], start: &[P2]) -> Vec<P2> {
        let groups: Vec<&[usize]> = self.affine_groups.iter().map(Vec::as_slice).collect();
        affine_rest(carried, start, &groups, self.mouth_affine)
    }

    /// The inner mouth slid (in place in `knots`) by the plan's fraction of its drift from
    /// where it sat in the outer mouth in `rest`, along the mouth line (`down` turned).
    pub fn centre(&self, knots: &mut [P2], rest: &[P2], down: P2) {
        let along = [down[1], -down[0]];
        centre_group(knots, rest, &self.inner, &self.outer, along, self.centring);
    }

    /// Per feature, whether its upper curve's chord in `knots` is within its least fraction to
    /// 2 times its chord in `rest`.
    pub fn shapes(&self, knots: &[P2], rest: &[P2]) -> Vec<bool> {
        chords_within(knots, rest, &self.chord_ends, &self.least_chord)
    }

    /// Each curve's edge `response` over its first frame's, clipped to 0..1, and each
    /// feature's mean of its two curves'.
    pub fn confidences(&self, response: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let ratio: Vec<f64> = response
            .iter()
            .zip(&self.response0)
            // numpy's minimum(maximum(v, 0), 1): NaN stays NaN.
            .map(|(r, r0)| (r / r0).clamp(0.0, 1.0))
            .collect();
        let confidence = self
            .feature_curves
            .iter()
            .map(|&[u, l]| (ratio[u] + ratio[l]) / 2.0)
            .collect();
        (ratio, confidence)
    }

    /// After the solver: the inner mouth slid back in `knots` ([`FramePlan::centre`]), the
    /// confidences of `response` and the shape checks of `knots` against `carried`
    /// ([`FramePlan::shapes`]).
    pub fn assess(
        &self,
        knots: &mut [P2],
        rest: &[P2],
        down: P2,
        response: &[f64],
        carried: &[P2],
    ) -> Assessed {
        self.centre(knots, rest, down);
        let (ratio, confidence) = self.confidences(response);
        let shape_ok = self.shapes(knots, carried);
        Assessed {
            ratio,
            confidence,
            shape_ok,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two features over 6 knots: a "mouth" (knots 0..4, inner 2..4, outer 0..2) and a "brow"
    /// (4..6); curves 0, 1 the mouth's, 2, 3 the brow's.
    fn plan() -> FramePlan {
        FramePlan {
            knots0: vec![
                [10.0, 50.0],
                [30.0, 50.0],
                [15.0, 51.0],
                [25.0, 51.0],
                [10.0, 10.0],
                [30.0, 10.0],
            ],
            down0: [0.0, 1.0],
            targets0: vec![2.0, 4.0],
            response0: vec![10.0, 20.0, 5.0, 5.0],
            bounds: [63.0, 63.0],
            mouth: vec![0, 1, 2, 3],
            mouth_patch: 0.5,
            affine_groups: vec![vec![0, 1], vec![2, 3]],
            mouth_affine: 0.0,
            inner: vec![2, 3],
            outer: vec![0, 1],
            centring: 0.5,
            chord_ends: vec![[0, 1], [4, 5]],
            least_chord: vec![0.5, 0.5],
            feature_curves: vec![[0, 1], [2, 3]],
        }
    }

    #[test]
    fn the_start_comes_from_the_flow_where_it_followed_and_counts_the_mouth() {
        let p = plan();
        let shift = [[1.0, 0.0, 2.0], [0.0, 1.0, -1.0]];
        let mut flow = vec![[f64::NAN; 2]; 6];
        flow[0] = [11.0, 49.5];
        let begun = p.begin(&shift, &shift, &p.knots0, Some(&flow));
        assert_eq!(begun.start[0], [11.0, 49.5]);
        assert_eq!(begun.start[1], [32.0, 49.0]);
        assert_eq!(
            begun.followed.as_deref(),
            Some(&[true, false, false, false, false, false][..])
        );
        assert!(
            begun.mouth_unfollowed,
            "1 of 4 mouth knots followed, under half"
        );
        assert_eq!((begun.scale, begun.down), (1.0, [0.0, 1.0]));
        let alone = p.begin(&shift, &shift, &p.knots0, None);
        assert!(alone.followed.is_none() && !alone.mouth_unfollowed);
        assert_eq!(alone.start[5], [32.0, 9.0]);
    }

    #[test]
    fn settling_clips_the_start_and_scales_the_targets() {
        let p = plan();
        let mut start = p.knots0.clone();
        start[0] = [-3.0, 70.0];
        let total = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let settled = p.settle(&mut start, &total, 2.0);
        assert_eq!(start[0], [0.0, 63.0]);
        assert_eq!(settled.carried[5], [60.0, 20.0]);
        assert_eq!(
            settled.rest, settled.carried,
            "mouth_affine 0: the rest is carried"
        );
        assert_eq!(settled.targets, [4.0, 8.0]);
    }

    #[test]
    fn the_assessment_centres_the_inner_mouth_and_checks_confidence_and_chords() {
        let p = plan();
        let mut knots = p.knots0.clone();
        knots[2][0] += 4.0;
        knots[3][0] += 4.0;
        knots[5] = [70.0, 10.0]; // the brow's chord grew threefold
        let a = p.assess(
            &mut knots,
            &p.knots0,
            [0.0, 1.0],
            &[5.0, 30.0, -1.0, 2.5],
            &p.knots0,
        );
        assert_eq!(
            [knots[2][0], knots[3][0]],
            [17.0, 27.0],
            "half the 4 px drift taken out"
        );
        assert_eq!(a.ratio, [0.5, 1.0, 0.0, 0.5]);
        assert_eq!(a.confidence, [0.75, 0.25]);
        assert_eq!(a.shape_ok, [true, false]);
    }

    #[test]
    fn indices_past_the_knots_or_curves_are_refused() {
        assert!(plan().check().is_ok());
        let mut p = plan();
        p.mouth.push(6);
        assert!(p.check().is_err());
        let mut p = plan();
        p.feature_curves[1] = [2, 4];
        assert!(p.check().is_err());
        let mut p = plan();
        p.least_chord.pop();
        assert!(p.check().is_err());
    }
}
