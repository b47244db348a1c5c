//! The tracker's placement of mouth knots on lip edges found by [`crate::lip_search`]: each
//! frame, the knots the optical flow could not follow, the outer knots left inside their lips
//! and the inner knots left far inside the mouth start at a lip edge (see
//! `facemime.track.lips` for why each is searched for).
//!
//! The mouth is four curves of knots in one knot array, in the order of [`Curve`]; the curves
//! run image-left to image-right and share their end knots, which never move here. Each knot's
//! normal is its curve's central difference (one-sided at the ends) turned to point down.
//! Distances are pixels of the frame, scaled by the head's scale relative to the first frame
//! where they were measured there.

use crate::error::Result;
use crate::invalid;
use crate::lip_search::{find_edges, normal_gaps, scores_near, LipColour, Probe, SearchSettings};
use crate::median::median;
use crate::raster::ImageRef;

/// Smoothing (px) of the lip score along a normal.
pub const SIGMA: f64 = 1.5;
/// An inner knot farther from its outer lip than this many first-frame lip thicknesses (at
/// least 1 px each) is searched for again.
pub const THICKER: f64 = 1.8;
/// An outer knot is searched for again when the lip score this many of its first-frame lip
/// thicknesses (at least 2 px) outside it exceeds [`LIP_OUTSIDE`] (skin standard deviations),
/// but only where, [`BEYOND`] times as far out, the score is below [`SKIN_BEYOND`].
pub const PROBE: f64 = 0.75;
pub const LIP_OUTSIDE: f64 = 1.0;
pub const BEYOND: f64 = 3.0;
pub const SKIN_BEYOND: f64 = 0.5;

/// The mouth's curves, in the order [`LipPlacer::new`] takes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Curve {
    OuterUpper = 0,
    OuterLower = 1,
    InnerUpper = 2,
    InnerLower = 3,
}

const CURVES: [Curve; 4] = [
    Curve::OuterUpper,
    Curve::OuterLower,
    Curve::InnerUpper,
    Curve::InnerLower,
];

impl Curve {
    /// Where the outer curves' edges are searched first: above (−1) or below (+1) along the
    /// normal, outermost first (outside the outer lips lies skin only; the transitions nearer
    /// the mouth are the teeth's and the opening's).
    fn outermost(self) -> Option<f64> {
        match self {
            Curve::OuterUpper => Some(-1.0),
            Curve::OuterLower => Some(1.0),
            _ => None,
        }
    }

    /// The outer curve on the same lip as an inner one, and the reverse.
    fn partner(self) -> Curve {
        match self {
            Curve::OuterUpper => Curve::InnerUpper,
            Curve::OuterLower => Curve::InnerLower,
            Curve::InnerUpper => Curve::OuterUpper,
            Curve::InnerLower => Curve::OuterLower,
        }
    }
}

/// Downward unit normals of a curve running image-left to image-right (at least 2 points).
fn normals(pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let (a, b) = match i {
                0 => (pts[0], pts[1]),
                _ if i == n - 1 => (pts[n - 2], pts[n - 1]),
                _ => (pts[i - 1], pts[i + 1]),
            };
            let d = [b[0] - a[0], b[1] - a[1]];
            let len = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-9);
            [-(d[1] / len), d[0] / len]
        })
        .collect()
}

/// The [`median`] of the finite `values`; None when there are none.
fn finite_median(values: impl Iterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| median(&mut v))
}

/// One search of [`LipPlacer::search`]: which interior knots, a shorter range (px) than the
/// usual one, the offsets to search nearest to (one per selected knot), and the offset (px,
/// first-frame scale) each moved knot keeps from its edge (default: its own first-frame one).
#[derive(Default)]
struct Search<'a> {
    within: Option<f64>,
    expect: Option<&'a [f64]>,
    offset: Option<f64>,
}

/// Moves mouth knots onto the lip edges of one face; built on its first frame.
pub struct LipPlacer {
    colour: LipColour,
    reach: f64,
    min_step: f64,
    index: [Vec<usize>; 4],
    signs: [f64; 4],
    /// Per curve and knot: where it sat from its lip edge on the first frame, px (0 where no
    /// edge was found and at the ends).
    offset0: [Vec<f64>; 4],
    /// Per inner curve's interior knot: its signed distance along its normal to its outer lip
    /// on the first frame, px (NaN where the normal misses it); empty for the outer curves.
    thickness0: [Vec<f64>; 4],
    /// Per outer curve's interior knot: its lip's thickness along its normal to the inner curve
    /// on the first frame, px (the lip's median where the normal misses it); empty for the
    /// inner curves.
    lip0: [Vec<f64>; 4],
}

impl LipPlacer {
    /// `image`: the first frame, (H, W, 3) RGB; `colour`: its lip score; `reach`: the search
    /// range, ± px at the first frame's scale (at least 1); `min_step`: the smallest edge
    /// (score units per px); `index`: each curve's knot indices (at least 2, in [`Curve`]
    /// order) into `edges`, the first frame's knots as settled on the image edges; `signs`:
    /// per curve, +1 where the lip score rises along the downward normal at its edge, −1 where
    /// it falls.
    pub fn new(
        image: &ImageRef,
        colour: LipColour,
        reach: f64,
        min_step: f64,
        index: [Vec<usize>; 4],
        signs: [f64; 4],
        edges: &[[f64; 2]],
    ) -> Result<Self> {
        if !(reach.is_finite() && reach >= 1.0) {
            return invalid!("reach must be at least 1 px, got {reach}");
        }
        if let Some(i) = index.iter().position(|idx| idx.len() < 2) {
            return invalid!("each mouth curve needs at least 2 knots; curve {i} has fewer");
        }
        if let Some(&k) = index.iter().flatten().find(|&&k| k >= edges.len()) {
            return invalid!("knot index {k} is past the {} knots", edges.len());
        }
        let empty = || std::array::from_fn(|_| Vec::new());
        let mut placer = Self {
            colour,
            reach,
            min_step,
            offset0: std::array::from_fn(|c| vec![0.0; index[c].len()]),
            index,
            signs,
            thickness0: empty(),
            lip0: empty(),
        };
        for curve in CURVES {
            let all = vec![true; placer.index[curve as usize].len() - 2];
            let (found, _) = placer.search(image, edges, curve, &all, 1.0, &Search::default())?;
            placer.offset0[curve as usize] = found
                .iter()
                .map(|v| if v.is_finite() { *v } else { 0.0 })
                .collect();
        }
        for curve in [Curve::InnerUpper, Curve::InnerLower] {
            placer.thickness0[curve as usize] = placer.gaps(edges, curve);
        }
        for curve in [Curve::OuterUpper, Curve::OuterLower] {
            let gap: Vec<f64> = placer.gaps(edges, curve).iter().map(|g| g.abs()).collect();
            let fill = finite_median(gap.iter().copied()).unwrap_or(0.0);
            placer.lip0[curve as usize] = gap
                .iter()
                .map(|&g| if g.is_finite() { g } else { fill })
                .collect();
        }
        Ok(placer)
    }

    fn points(&self, knots: &[[f64; 2]], curve: Curve) -> Vec<[f64; 2]> {
        self.index[curve as usize]
            .iter()
            .map(|&k| knots[k])
            .collect()
    }

    /// The signed distances (px) of the interior knots of `curve` along their normals to its
    /// partner curve (NaN where they miss it).
    fn gaps(&self, knots: &[[f64; 2]], curve: Curve) -> Vec<f64> {
        let pts = self.points(knots, curve);
        let n = pts.len();
        normal_gaps(
            &pts[1..n - 1],
            &normals(&pts)[1..n - 1],
            &self.points(knots, curve.partner()),
        )
    }

    /// The offsets (px along the downward normals) of the lip edges from the knots of `curve`
    /// selected by `which` (a mask over its interior knots; NaN for the others and where none
    /// was found), and the curve's normals. The expected offsets, unless given, are the
    /// outermost for an outer curve, else each knot's first-frame offset.
    fn search(
        &self,
        image: &ImageRef,
        knots: &[[f64; 2]],
        curve: Curve,
        which: &[bool],
        scale: f64,
        how: &Search,
    ) -> Result<(Vec<f64>, Vec<[f64; 2]>)> {
        let c = curve as usize;
        let pts = self.points(knots, curve);
        let normal = normals(&pts);
        let pick: Vec<usize> = (1..pts.len() - 1).filter(|&k| which[k - 1]).collect();
        let usual = self.reach * scale;
        let reach = how.within.map_or(usual, |w| w.min(usual)).max(SIGMA);
        let probes: Vec<Probe> = pick
            .iter()
            .enumerate()
            .map(|(j, &k)| Probe {
                at: pts[k],
                normal: normal[k],
                sign: self.signs[c],
                expect: match (how.expect, curve.outermost()) {
                    (Some(e), _) => e[j],
                    (None, Some(side)) => side * reach,
                    (None, None) => self.offset0[c][k] * scale,
                },
            })
            .collect();
        let settings = SearchSettings {
            reach,
            sigma: SIGMA,
            min_step: self.min_step,
        };
        let found = find_edges(image, &self.colour, &probes, &settings)?;
        let mut out = vec![f64::NAN; pts.len()];
        for (&k, v) in pick.iter().zip(found) {
            out[k] = v;
        }
        Ok((out, normal))
    }

    /// Moves the interior knots of `curve` selected by `which` to the lip edges
    /// [`Self::search`] finds for them, each keeping its offset from its edge (in place).
    fn place_curve(
        &self,
        image: &ImageRef,
        knots: &mut [[f64; 2]],
        curve: Curve,
        which: &[bool],
        scale: f64,
        how: &Search,
    ) -> Result<()> {
        let c = curve as usize;
        let (found, normal) = self.search(image, knots, curve, which, scale, how)?;
        for (k, f) in found.iter().enumerate().filter(|(_, f)| f.is_finite()) {
            let shift = f - how.offset.unwrap_or(self.offset0[c][k]) * scale;
            let at = &mut knots[self.index[c][k]];
            *at = [at[0] + shift * normal[k][0], at[1] + shift * normal[k][1]];
        }
        Ok(())
    }

    /// Moves, in `image` (the frame, (H, W, 3) RGB) at head scale `scale`: the interior mouth
    /// knots flagged in `unfollowed` (a mask over `knots`), then the outer knots inside their
    /// lips (lip colour outside them, then skin), then the inner knots too far inside the
    /// mouth, to the lip edges found near them (in place).
    pub fn place(
        &self,
        image: &ImageRef,
        knots: &mut [[f64; 2]],
        unfollowed: &[bool],
        scale: f64,
    ) -> Result<()> {
        if unfollowed.len() != knots.len() {
            return invalid!(
                "the mask has {} entries for {} knots",
                unfollowed.len(),
                knots.len()
            );
        }
        if let Some(&k) = self.index.iter().flatten().find(|&&k| k >= knots.len()) {
            return invalid!("knot index {k} is past the {} knots", knots.len());
        }
        if !(scale.is_finite() && scale > 0.0) {
            return invalid!("the head scale must be positive, got {scale}");
        }
        for curve in CURVES {
            let idx = &self.index[curve as usize];
            let which: Vec<bool> = idx[1..idx.len() - 1]
                .iter()
                .map(|&k| unfollowed[k])
                .collect();
            if which.contains(&true) {
                self.place_curve(image, knots, curve, &which, scale, &Search::default())?;
            }
        }
        self.pull_out(image, knots, scale)?;
        for curve in [Curve::InnerUpper, Curve::InnerLower] {
            self.thin(image, knots, curve, scale)?;
        }
        Ok(())
    }

    /// Moves the outer knots whose lip colour continues outside them, then skin, to the
    /// outermost lip edge (in place; both curves probed before either moves).
    fn pull_out(&self, image: &ImageRef, knots: &mut [[f64; 2]], scale: f64) -> Result<()> {
        let outer = [Curve::OuterUpper, Curve::OuterLower];
        let mut near: [Vec<f64>; 2] = Default::default();
        let mut probes = Vec::new();
        for (j, curve) in outer.into_iter().enumerate() {
            let pts = self.points(knots, curve);
            let normal = normals(&pts);
            let side = curve.outermost().expect("an outer curve");
            near[j] = self.lip0[curve as usize]
                .iter()
                .map(|l| (PROBE * l * scale).max(2.0))
                .collect();
            let steps: Vec<[f64; 2]> = near[j]
                .iter()
                .zip(&normal[1..])
                .map(|(d, n)| [side * d * n[0], side * d * n[1]])
                .collect();
            let interior = &pts[1..pts.len() - 1];
            probes.extend(
                interior
                    .iter()
                    .zip(&steps)
                    .map(|(p, s)| [p[0] + s[0], p[1] + s[1]]),
            );
            probes.extend(
                interior
                    .iter()
                    .zip(&steps)
                    .map(|(p, s)| [p[0] + BEYOND * s[0], p[1] + BEYOND * s[1]]),
            );
        }
        let scores = scores_near(image, &self.colour, &probes)?;
        let mut at = 0;
        for (j, curve) in outer.into_iter().enumerate() {
            let m = near[j].len();
            let (near_score, far_score) = (&scores[at..at + m], &scores[at + m..at + 2 * m]);
            at += 2 * m;
            let inside: Vec<bool> = near_score
                .iter()
                .zip(far_score)
                .map(|(&a, &b)| a > LIP_OUTSIDE && b < SKIN_BEYOND)
                .collect();
            let farthest = near[j]
                .iter()
                .zip(&inside)
                .filter(|(_, &i)| i)
                .map(|(&d, _)| d)
                .fold(f64::NEG_INFINITY, f64::max);
            if farthest.is_finite() {
                let how = Search {
                    within: Some(BEYOND * farthest),
                    ..Search::default()
                };
                self.place_curve(image, knots, curve, &inside, scale, &how)?;
            }
        }
        Ok(())
    }

    /// Moves the interior knots of inner `curve` that lie farther from their outer lip than
    /// [`THICKER`] first-frame lip thicknesses to the lip edge found nearest one thickness
    /// inside the outer lip, keeping the curve's median first-frame offset from its edge (in
    /// place).
    fn thin(
        &self,
        image: &ImageRef,
        knots: &mut [[f64; 2]],
        curve: Curve,
        scale: f64,
    ) -> Result<()> {
        let c = curve as usize;
        let gap = self.gaps(knots, curve);
        let thickness: Vec<f64> = self.thickness0[c].iter().map(|t| t * scale).collect();
        // NaN gaps and thicknesses are never far.
        let far: Vec<bool> = gap
            .iter()
            .zip(&thickness)
            .map(|(g, t)| !t.is_nan() && g.abs() > THICKER * t.abs().max(1.0))
            .collect();
        if !far.contains(&true) {
            return Ok(());
        }
        let reach = (self.reach * scale).max(SIGMA);
        let expect: Vec<f64> = gap
            .iter()
            .zip(&thickness)
            .zip(&far)
            .filter(|(_, &f)| f)
            .map(|((g, t), _)| (g - t).clamp(-reach, reach))
            .collect();
        let offsets = &self.offset0[c];
        let how = Search {
            expect: Some(&expect),
            offset: finite_median(offsets[1..offsets.len() - 1].iter().copied()),
            ..Search::default()
        };
        self.place_curve(image, knots, curve, &far, scale, &how)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_point_down_for_a_curve_running_right() {
        let n = normals(&[[0.0, 0.0], [1.0, 0.0], [2.0, 1.0]]);
        assert_eq!(n[0], [-0.0, 1.0]);
        // The middle knot's direction is the central difference (2, 1).
        let s = 5.0f64.sqrt();
        assert!((n[1][0] + 1.0 / s).abs() < 1e-12 && (n[1][1] - 2.0 / s).abs() < 1e-12);
        assert!(n[2][1] > 0.0);
    }

    #[test]
    fn the_median_skips_non_finite_values() {
        assert_eq!(
            finite_median([3.0, f64::NAN, 1.0, 2.0].into_iter()),
            Some(2.0)
        );
        assert_eq!(finite_median([4.0, 1.0].into_iter()), Some(2.5));
        assert_eq!(finite_median([f64::NAN].into_iter()), None);
    }
}
