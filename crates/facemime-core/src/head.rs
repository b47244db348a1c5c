//! The head followed from frame to frame: textured points in the face's rigid zones (nose,
//! forehead), tracked by the Lucas-Kanade flow forwards and back and fitted by a robust
//! similarity ([`follow_rigid`]). The zones are quadrilaterals placed each frame by the
//! similarity that carries the first frame's brows onto the brows tracked in the previous one,
//! then moved by the head's step; points that leave them are dropped. [`HeadFollower::advance`]
//! says when too few are left; [`HeadFollower::corners`] finds corners in the frame's grey
//! levels (in a mask of the zones the caller draws) and [`HeadFollower::detected`] takes them.
//!
//! Points are (x, y) pixels of the whole frame, pixel centres on integers; transforms are 2×3
//! matrices mapping one frame's pixels to another's. Rigid points are kept in single precision,
//! as the corner detector gives them.

use crate::corners::{good_features, CornerSettings};
use crate::error::Result;
use crate::extent::extent;
use crate::flow::{LkParams, Pyramid};
use crate::invalid;
use crate::motion::{apply, follow_rigid, inside_quads, robust_similarity};
use crate::raster::ImageRef;

/// A convex quadrilateral, corners in order (pixels).
pub type Quad = [[f64; 2]; 4];

/// Rounds of the robust similarity that places the zones by the brows, and its inlier limit
/// (pixels).
const PLACE_ROUNDS: usize = 10;
const PLACE_LIMIT: f64 = 1.0;
/// Pixels added to the crop's pad beyond the coarsest level's half window.
const CROP_MARGIN: usize = 8;

/// How the head is followed.
#[derive(Clone, Copy, Debug)]
pub struct FollowSettings {
    /// Side of the Lucas-Kanade window (odd, pixels).
    pub window: usize,
    /// Pyramid levels above the frame at most.
    pub max_level: usize,
    /// Levels above the frame at most for the flows that start where the head's step carries
    /// the points: the extra points' both ways, the rigid points' way back (see [`follow_rigid`]).
    pub guided_levels: usize,
    /// Forward-backward and fit tolerance (pixels).
    pub limit: f64,
    /// Fewest points for a similarity; also the fewest that are ever wanted.
    pub min_points: usize,
    /// Rounds of the step's robust fit at most.
    pub rounds: usize,
    pub lk: LkParams,
}

/// One frame's measurement by [`HeadFollower::follow`].
#[derive(Clone, Debug, PartialEq)]
pub struct Followed {
    /// The head's similarity from the previous frame to this one; None when too few rigid
    /// points were left or passed the forward-backward check and fit it.
    pub similarity: Option<[[f64; 3]; 2]>,
    /// Per extra point: its position in this frame, None where the flow or its check failed.
    pub extra: Vec<Option<[f64; 2]>>,
}

/// The head's rigid points, their identities and the pyramids of the last two frames.
pub struct HeadFollower {
    settings: FollowSettings,
    prev: Pyramid,
    cur: Pyramid,
    brows0: Vec<[f64; 2]>,
    zones0: Vec<Quad>,
    zones: Vec<Quad>,
    points: Vec<[f32; 2]>,
    ids: Vec<i64>,
    followed: (Vec<[f32; 2]>, Vec<i64>),
    next_id: i64,
    /// Fewer points than this call for new ones; set by the first frame's corners.
    wanted: Option<usize>,
}

fn widen(p: &[f32; 2]) -> [f64; 2] {
    [p[0] as f64, p[1] as f64]
}

impl HeadFollower {
    /// Starts on the first frame, a grey or RGB image: `brows0` are its brow points (later
    /// frames' brows are matched to them point by point), `zones0` its rigid zones. The
    /// first frame's corners in them ([`HeadFollower::corners`]) are then given to
    /// [`HeadFollower::detected`].
    pub fn new(
        frame: &ImageRef,
        brows0: Vec<[f64; 2]>,
        zones0: Vec<Quad>,
        settings: FollowSettings,
    ) -> Result<Self> {
        if brows0.is_empty() {
            return invalid!("the head needs brow points to place its zones");
        }
        let mut head = Self {
            settings,
            prev: Pyramid::new(settings.window)?,
            cur: Pyramid::new(settings.window)?,
            brows0,
            zones: zones0.clone(),
            zones0,
            points: Vec::new(),
            ids: Vec::new(),
            followed: (Vec::new(), Vec::new()),
            next_id: 0,
            wanted: None,
        };
        head.push(frame, &[])?;
        Ok(head)
    }

    /// The rigid zones now (after [`HeadFollower::advance`]: in the current frame).
    pub fn zones(&self) -> &[Quad] {
        &self.zones
    }

    /// The rigid points followed into the current frame and their identities.
    pub fn points(&self) -> (&[[f32; 2]], &[i64]) {
        (&self.points, &self.ids)
    }

    /// The points followed from the previous frame, before any new ones were found.
    pub fn followed(&self) -> (&[[f32; 2]], &[i64]) {
        (&self.followed.0, &self.followed.1)
    }

    /// Replaces the rigid points by new ones, with new identities (0, 1, ... for the first
    /// frame's, which are also its followed points; from then on, fewer than half as many as
    /// those, or than `min_points`, call for new ones).
    pub fn detected(&mut self, points: Vec<[f32; 2]>) {
        self.ids = (self.next_id..).take(points.len()).collect();
        self.next_id += points.len() as i64;
        self.points = points;
        if self.wanted.is_none() {
            self.wanted = Some(self.settings.min_points.max(self.points.len() / 2));
            self.followed = (self.points.clone(), self.ids.clone());
        }
    }

    /// The corners of the current frame (frame pixels) in `area` = [x0, y0, x1, y1) (frame
    /// pixels, exclusive ends) where `mask` (row-major over the area; nonzero: allowed) allows
    /// them, as [`good_features`] finds them on the frame's grey levels. Only the part of the
    /// area that the frame's pyramid covers is searched: all of it, unless the zones moved
    /// further in one step than the pyramid's margin around them (the coarsest level's window).
    pub fn corners(
        &self,
        area: [usize; 4],
        mask: &[u8],
        settings: &CornerSettings,
    ) -> Result<Vec<[f32; 2]>> {
        let [x0, y0, x1, y1] = area;
        let (w, h) = (x1.saturating_sub(x0), y1.saturating_sub(y0));
        if mask.len() != w * h {
            return invalid!("the mask has {} pixels, not the area's {w}×{h}", mask.len());
        }
        let (grey, [cx0, cy0, cx1, cy1]) = self.cur.grey_levels();
        let [ix0, iy0, ix1, iy1] = [x0.max(cx0), y0.max(cy0), x1.min(cx1), y1.min(cy1)];
        if ix0 >= ix1 || iy0 >= iy1 {
            return Ok(Vec::new());
        }
        let inside: Vec<u8>;
        let mask = if [ix0, iy0, ix1, iy1] == area {
            mask
        } else {
            inside = (iy0..iy1)
                .flat_map(|y| &mask[(y - y0) * w + ix0 - x0..][..ix1 - ix0])
                .copied()
                .collect();
            &inside
        };
        let local = [ix0 - cx0, iy0 - cy0, ix1 - cx0, iy1 - cy0];
        let found = good_features(grey, cx1 - cx0, cy1 - cy0, local, mask, settings)?;
        let shift = [cx0 as f32, cy0 as f32];
        Ok(found
            .into_iter()
            .map(|p| [p[0] + shift[0], p[1] + shift[1]])
            .collect())
    }

    /// Drops every rigid point (the step was measured some other way).
    pub fn drop_points(&mut self) {
        self.points.clear();
        self.ids.clear();
    }

    /// The next `frame` (grey or RGB, the first frame's size): the zones placed by the previous
    /// frame's `brows` (as many as the first frame's), the frame's pyramid built, the rigid
    /// points followed into it and fitted, and the `extra` points (pixels of the previous
    /// frame) followed alike. With a similarity the rigid points that fit it are kept at their
    /// new positions; without one, they stay.
    pub fn follow(
        &mut self,
        frame: &ImageRef,
        brows: &[[f64; 2]],
        extra: &[[f64; 2]],
    ) -> Result<Followed> {
        if brows.len() != self.brows0.len() {
            return invalid!(
                "{} brow points for the first frame's {}",
                brows.len(),
                self.brows0.len()
            );
        }
        let (place, _) = robust_similarity(&self.brows0, brows, PLACE_LIMIT, PLACE_ROUNDS);
        self.zones = self.moved_zones(&self.zones0, &place);
        self.push(frame, extra)?;
        let s = &self.settings;
        let none = || vec![None; extra.len()];
        if self.points.len() < s.min_points {
            return Ok(Followed {
                similarity: None,
                extra: none(),
            });
        }
        let points: Vec<[f64; 2]> = self.points.iter().map(widen).collect();
        let step = follow_rigid(
            &mut self.prev,
            &mut self.cur,
            &points,
            extra,
            s.guided_levels,
            &s.lk,
            s.limit,
            s.min_points,
            s.rounds,
        )?;
        if step.similarity.is_some() {
            self.ids = step.kept.iter().map(|&i| self.ids[i]).collect();
            self.points = step
                .moved
                .iter()
                .map(|p| [p[0] as f32, p[1] as f32])
                .collect();
        }
        Ok(Followed {
            similarity: step.similarity,
            extra: step.extra,
        })
    }

    /// Ends the frame once the head's `step` from the previous one is known: the zones move by
    /// it and the points outside them are dropped. Returns whether new points are wanted.
    pub fn advance(&mut self, step: &[[f64; 3]; 2]) -> bool {
        self.zones = self.moved_zones(&self.zones, step);
        if !self.points.is_empty() {
            let pts: Vec<[f64; 2]> = self.points.iter().map(widen).collect();
            let inside = inside_quads(&pts, &self.zones);
            let mut k = inside.iter();
            self.points
                .retain(|_| *k.next().expect("one flag per point"));
            let mut k = inside.iter();
            self.ids.retain(|_| *k.next().expect("one flag per point"));
        }
        self.followed = (self.points.clone(), self.ids.clone());
        self.wanted.is_none_or(|w| self.points.len() < w)
    }

    fn moved_zones(&self, zones: &[Quad], m: &[[f64; 3]; 2]) -> Vec<Quad> {
        zones
            .iter()
            .map(|z| std::array::from_fn(|k| apply(m, z[k])))
            .collect()
    }

    /// Builds the frame's pyramid on the part of it the flow uses: the zones, rigid points and
    /// `extra` points with room for the coarsest level's window, its corner on a multiple of
    /// that level's scale so that consecutive frames' levels sample the same grid.
    fn push(&mut self, frame: &ImageRef, extra: &[[f64; 2]]) -> Result<()> {
        let s = &self.settings;
        let grid = 1i64 << s.max_level;
        let pad = grid * s.window as i64 / 2 + CROP_MARGIN as i64;
        let corners = self.zones.iter().flatten().copied();
        let (lo, hi) = extent(
            corners
                .chain(self.points.iter().map(widen))
                .chain(extra.iter().copied()),
        );
        let start = |v: f64| ((v.floor() as i64 - pad).div_euclid(grid) * grid).max(0) as usize;
        let end = |v: f64, size: usize| (v.ceil() as i64 + pad).clamp(0, size as i64) as usize;
        let crop = [
            start(lo[0]),
            start(lo[1]),
            end(hi[0], frame.width),
            end(hi[1], frame.height),
        ];
        std::mem::swap(&mut self.prev, &mut self.cur);
        self.cur.rebuild(frame, crop, s.max_level)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flow::tests::{gray, texture, PARAMS};

    const SETTINGS: FollowSettings = FollowSettings {
        window: 21,
        max_level: 3,
        guided_levels: 2,
        limit: 1.0,
        min_points: 6,
        rounds: 10,
        lk: PARAMS,
    };

    fn grid_points() -> Vec<[f32; 2]> {
        (0..16)
            .map(|k| [70.0 + 12.0 * (k % 4) as f32, 60.0 + 12.0 * (k / 4) as f32])
            .collect()
    }

    fn brows() -> Vec<[f64; 2]> {
        vec![[60.0, 40.0], [90.0, 36.0], [120.0, 40.0]]
    }

    #[test]
    fn follows_the_head_keeps_identities_and_drops_points_that_leave_the_zones() {
        let (w, h) = (192, 160);
        let zone: Quad = [[60.0, 50.0], [120.0, 50.0], [120.0, 110.0], [60.0, 110.0]];
        let first = texture(w, h, 0.0, 0.0);
        let mut head =
            HeadFollower::new(&gray(&first, w, h), brows(), vec![zone], SETTINGS).unwrap();
        head.detected(grid_points());
        assert_eq!(head.points().1, (0..16).collect::<Vec<i64>>());
        assert_eq!(
            head.followed().1.len(),
            16,
            "the first frame's points are its followed"
        );
        // The image moves 2 px right: the brows with it, so the zone does too.
        let next = texture(w, h, 2.0, 0.0);
        let moved: Vec<[f64; 2]> = brows().iter().map(|p| [p[0] + 2.0, p[1]]).collect();
        let got = head
            .follow(&gray(&next, w, h), &moved, &[[95.0, 75.0], [f64::NAN, 1.0]])
            .unwrap();
        let m = got.similarity.expect("a similarity");
        assert!(
            (m[0][2] - 2.0).abs() < 0.05 && m[1][2].abs() < 0.05,
            "{m:?}"
        );
        let e = got.extra[0].expect("followed");
        assert!((e[0] - 97.0).abs() < 0.05 && (e[1] - 75.0).abs() < 0.05);
        assert_eq!(got.extra[1], None);
        assert!(!head.advance(&m));
        // Every point is still inside the zone (moved by the brows, then by the step).
        assert_eq!(head.followed().1.len(), 16);
        assert!((head.zones()[0][0][0] - 64.0).abs() < 0.1);
        // Brows that put the zone 40 px left leave only its left column's points... too few.
        let far: Vec<[f64; 2]> = moved.iter().map(|p| [p[0] - 40.0, p[1]]).collect();
        let again = head.follow(&gray(&next, w, h), &far, &[]).unwrap();
        let step = again.similarity.expect("a similarity");
        assert!(
            head.advance(&step),
            "too few points left: new ones are wanted"
        );
        let (pts, ids) = head.points();
        assert!(pts.iter().all(|p| p[0] < 86.0), "{pts:?}");
        assert!(ids.iter().all(|&i| i % 4 == 0), "{ids:?}");
        head.detected(grid_points());
        assert_eq!(head.points().1[0], 16, "new points get new identities");
    }

    #[test]
    fn corners_are_those_of_the_frames_grey_levels_where_its_pyramid_reaches() {
        let (w, h) = (400, 320);
        let zone: Quad = [
            [200.0, 150.0],
            [260.0, 150.0],
            [260.0, 210.0],
            [200.0, 210.0],
        ];
        let img = texture(w, h, 0.0, 0.0);
        let head = HeadFollower::new(&gray(&img, w, h), brows(), vec![zone], SETTINGS).unwrap();
        let s = CornerSettings {
            max_corners: 30,
            quality: 0.01,
            min_distance: 5.0,
            block: 5,
        };
        // Inside the pyramid's crop: the corners of the whole image's grey levels.
        let area = [190, 140, 270, 220];
        let mask: Vec<u8> = (0..80 * 80)
            .map(|i| if i % 80 < 70 { 255 } else { 0 })
            .collect();
        let want = good_features(&img, w, h, area, &mask, &s).unwrap();
        assert!(want.len() > 5, "{want:?}");
        assert_eq!(head.corners(area, &mask, &s).unwrap(), want);
        // Reaching left of the crop (the zone's left, 200, less 8·21/2 + 8, down to a multiple
        // of 8: 104): the part inside it.
        let wide = [90, 140, 170, 220];
        let inside: Vec<u8> = mask.chunks(80).flat_map(|r| &r[14..]).copied().collect();
        let want = good_features(&img, w, h, [104, 140, 170, 220], &inside, &s).unwrap();
        assert!(!want.is_empty());
        assert_eq!(head.corners(wide, &mask, &s).unwrap(), want);
        assert!(head.corners(area, &mask[1..], &s).is_err());
    }

    #[test]
    fn too_few_points_give_no_similarity_and_wrong_brows_are_refused() {
        let (w, h) = (192, 160);
        let zone: Quad = [[60.0, 50.0], [120.0, 50.0], [120.0, 110.0], [60.0, 110.0]];
        let img = texture(w, h, 0.0, 0.0);
        let few = grid_points()[..4].to_vec();
        let mut head = HeadFollower::new(&gray(&img, w, h), brows(), vec![zone], SETTINGS).unwrap();
        head.detected(few);
        let got = head
            .follow(&gray(&img, w, h), &brows(), &[[90.0, 80.0]])
            .unwrap();
        assert_eq!(got.similarity, None);
        assert_eq!(got.extra, [None]);
        assert!(head.follow(&gray(&img, w, h), &brows()[..2], &[]).is_err());
        assert!(HeadFollower::new(&gray(&img, w, h), vec![], vec![zone], SETTINGS).is_err());
    }
}
