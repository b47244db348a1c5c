"""The lips' colour and the tracker's wide search for lip edges.

The optical flow cannot follow a lip that moves far in a few frames (a mouth opening wide): its
forward-backward check fails, and the snakes, which reach only δ0/(1−σ) px per pass, stay near
the closed mouth. Such a knot is moved instead along its curve's normal to the nearest lip edge
of that curve's polarity on a lip-colour score (``facemime._core.find_lip_edges``).

A lip can also be left behind while the flow follows it. As the mouth opens on teeth, an outer
lip's knots can stay on the lip's inner edge (the teeth's edge has the same luma polarity as the
skin-lip edge): the lip colour then continues outside them, and they are moved to the outermost
lip-skin transition. The inner lips' knots can stay on the teeth near where the lips met: the
lip is then much thicker than it was, and an inner knot farther from its outer lip than
:data:`THICKER` first-frame lip thicknesses is moved to the lip edge found nearest one such
thickness inside the outer lip.

The score is a linear discriminant (Fisher's) of the chromaticities r = R/(R+G+B+1),
g = G/(R+G+B+1), fitted on the first frame between the lip pixels (between the outer and inner
mouth contours) and the skin around the mouth (:data:`SKIN_RING`): positive on lips, negative on
skin, teeth and the dark opening, in units of the skin's standard deviation. Coordinates are
(x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

from collections.abc import Mapping

import cv2
import numpy as np

from facemime import _core
from facemime.track.contours import POLARITY
from facemime.track.flow import as_points

#: Side of the square that grows the outer mouth into the skin ring, as a fraction of the mouth width.
SKIN_RING = 0.3
#: The search is off when lip and skin colours are closer than this: the distance of their
#: mean chromaticities (the six shared videos: 0.026 to 0.062), and that distance over their
#: pooled spread along the discriminant (1.3 to 2.0). The demo's rendered astronaut, smiling
#: on her first frame, has 0.010 and 0.65: on so weak a score the searches moved her lips onto
#: noise (mouth NME 0.015 without them, 0.08 with).
MIN_CHROMA = 0.02
MIN_SEPARATION = 1.0
SIGMA = 1.5  # px: smoothing of the score along the normal
#: The outer curves' edges are searched outermost first: above (−1) or below (+1) along the normal.
OUTERMOST = {"mouth_outer_upper": -1.0, "mouth_outer_lower": +1.0}
MOUTH = ("mouth_outer_upper", "mouth_outer_lower", "mouth_inner_upper", "mouth_inner_lower")
#: Each inner lip curve and the outer one on the same lip.
LIP_PAIRS = {"mouth_inner_upper": "mouth_outer_upper", "mouth_inner_lower": "mouth_outer_lower"}
#: An inner knot farther from its outer lip than this many first-frame lip thicknesses is
#: searched for again.
THICKER = 1.8
#: An outer knot is searched for again when the lip score this many of its first-frame lip
#: thicknesses (at least 2 px) outside it exceeds :data:`LIP_OUTSIDE` (skin standard
#: deviations): it lies inside its lip; but only where, :data:`BEYOND` times as far out, the
#: score is below :data:`SKIN_BEYOND`: skin follows. Measured on the six videos: gates of 0.75
#: to 1.5 at probes of 0.6 to 1.5 thicknesses track alike; a gate of 0.5 took a shadow under
#: vr_2's lower lip; without the skin beyond, vr_2's reddish skin around the mouth could pull
#: its outer lips outwards frame after frame.
PROBE = 0.75
LIP_OUTSIDE = 1.0
BEYOND = 3.0
SKIN_BEYOND = 0.5


def _normals(pts: np.ndarray) -> np.ndarray:
    """(N, 2) unit normals of a curve running image-left to image-right: pointing down."""
    along = np.empty_like(pts)  # central differences, one-sided at the ends (np.gradient's, unhalved)
    along[1:-1] = pts[2:] - pts[:-2]
    along[0], along[-1] = pts[1] - pts[0], pts[-1] - pts[-2]
    along /= np.maximum(np.sqrt((along * along).sum(axis=1, keepdims=True)), 1e-9)
    return np.stack([-along[:, 1], along[:, 0]], axis=1)


def normal_gaps(pts: np.ndarray, normals: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """For each of ``pts`` (N, 2) px, the signed distance t (px) along its unit normal to the
    nearest crossing of the polyline ``curve`` (M, 2): pts + t·normal lies on it; NaN where
    the normal's line misses the polyline (``facemime._core.normal_gaps``)."""
    return _core.normal_gaps(as_points(pts), as_points(normals), as_points(curve))


def _polygon_mask(shape: tuple[int, int], upper: np.ndarray, lower: np.ndarray) -> np.ndarray:
    mask = np.zeros(shape, np.uint8)
    cv2.fillPoly(mask, [np.round(np.concatenate([upper, lower[::-1]])).astype(np.int32)], 1)
    return mask


def _chromaticity(pixels: np.ndarray) -> np.ndarray:
    """(N, 3) RGB -> (N, 2) float64 (r, g)."""
    p = pixels.astype(np.float64)
    return p[:, :2] / (p.sum(axis=1, keepdims=True) + 1.0)


def lip_colour(frame: np.ndarray, contours: Mapping[str, np.ndarray]) -> tuple[float, float, float] | None:
    """The lip score (w_r, w_g, bias) of ``frame`` (H, W, 3) uint8 RGB from its mouth contours,
    or None when lips and skin cannot be told apart by colour."""
    shape = frame.shape[:2]
    outer = _polygon_mask(shape, contours["mouth_outer_upper"], contours["mouth_outer_lower"])
    inner = _polygon_mask(shape, contours["mouth_inner_upper"], contours["mouth_inner_lower"])
    corners = contours["mouth_outer_upper"][[0, -1]]
    side = max(int(SKIN_RING * np.linalg.norm(corners[1] - corners[0])), 3)
    ring = cv2.dilate(outer, np.ones((side, side), np.uint8))
    lip, skin = frame[(outer == 1) & (inner == 0)], frame[(ring == 1) & (outer == 0)]
    if len(lip) < 10 or len(skin) < 10:
        return None
    a, b = _chromaticity(lip), _chromaticity(skin)
    gap = a.mean(axis=0) - b.mean(axis=0)
    if not np.linalg.norm(gap) >= MIN_CHROMA:
        return None
    pooled = np.cov(a.T) + np.cov(b.T) + 1e-9 * np.eye(2)
    w = np.linalg.solve(pooled, gap)
    separation = float(w @ gap) / float(np.sqrt(w @ pooled @ w))
    spread = float((b @ w).std())
    if not separation >= MIN_SEPARATION or spread <= 0.0:
        return None
    w /= spread
    bias = 0.5 * (np.median(a @ w) + np.median(b @ w))
    return float(w[0]), float(w[1]), float(bias)


class LipSearch:
    """Moves mouth knots the flow could not follow, or left inside the lips, onto the lip edges.

    ``frame``, ``contours``: the first frame and its given contours (fit the colour);
    ``index``: contour name -> its knots' indices in the tracker's knot array; ``edges``: the
    first frame's knots as settled on the image edges; ``reach``: search range, ± this fraction
    of the first frame's mouth width; ``min_step``: smallest edge (score units per px).
    ``active`` is False when the colours did not separate: :meth:`move` then does nothing;
    ``colour`` is the lip score (w_r, w_g, bias) when it is True.
    """

    def __init__(self, frame: np.ndarray, contours: Mapping[str, np.ndarray], index: Mapping[str, np.ndarray],
                 edges: np.ndarray, reach: float, min_step: float):
        self.colour = lip_colour(frame, contours)
        corners = np.asarray(contours["mouth_outer_upper"], np.float64)[[0, -1]]
        self._reach = reach * float(np.linalg.norm(corners[1] - corners[0]))
        self._min_step = min_step
        self._index = {n: index[n] for n in MOUTH}
        self.active = self.colour is not None and self._reach >= 1.0
        # Where each knot sat from its lip edge on the first frame (the snakes settle on the
        # luma edge, which may lie a little off the colour edge): kept in later frames.
        self._offset0 = {n: np.zeros(len(i)) for n, i in self._index.items()}
        if self.active:
            for name, idx in self._index.items():
                found, _ = self._search(frame, edges, name, np.ones(len(idx) - 2, bool), 1.0)
                self._offset0[name] = np.nan_to_num(found)
        # Each inner knot's signed distance (px) to its outer lip along its normal on the first
        # frame.
        self._thickness0 = {n: self._gaps(edges, n, outer) for n, outer in LIP_PAIRS.items()}
        # Each outer knot's lip thickness (px along its normal to the inner curve; where the
        # normal misses it, the lip's median).
        self._lip0 = {}
        for inner, outer in LIP_PAIRS.items():
            gap = np.abs(self._gaps(edges, outer, inner))
            median = float(np.nanmedian(gap)) if np.isfinite(gap).any() else 0.0
            self._lip0[outer] = np.where(np.isfinite(gap), gap, median)

    def _gaps(self, knots: np.ndarray, name: str, other: str) -> np.ndarray:
        """The signed distances (px) of the interior knots of curve ``name`` along their
        normals to curve ``other`` (NaN where they miss it)."""
        pts = knots[self._index[name]]
        return normal_gaps(pts[1:-1], _normals(pts)[1:-1], knots[self._index[other]])

    def _search(self, frame: np.ndarray, knots: np.ndarray, name: str, which: np.ndarray, scale: float,
                within: float | None = None, expect: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The offsets (px along the downward normals) of the lip edges from the knots of curve
        ``name`` selected by ``which`` (a mask over the curve's interior knots; NaN for the
        others and where none was found), and the curve's (N, 2) unit normals. ``within``: a
        search range (px) shorter than the usual one; ``expect``: the offsets to search nearest
        to, one per selected knot (default: the outermost for an outer curve, else the knot's
        first-frame offset)."""
        pts = knots[self._index[name]]
        normal = _normals(pts)
        pick = np.flatnonzero(which) + 1
        out = np.full(len(pts), np.nan)
        reach = self._reach * scale if within is None else min(within, self._reach * scale)
        reach = max(reach, SIGMA)  # the core takes σ ≤ reach, and a head may shrink
        # Outside the outer lips lies skin only: their edge is the outermost lip-skin transition
        # (the transitions nearer the mouth are those of the teeth and the opening).
        if expect is None:
            expect = OUTERMOST[name] * reach if name in OUTERMOST else self._offset0[name][pick] * scale
        out[pick] = _core.find_lip_edges(
            frame, self.colour, np.ascontiguousarray(pts[pick]), np.ascontiguousarray(normal[pick]),
            np.full(len(pick), POLARITY[name][1]), np.broadcast_to(expect, len(pick)).astype(np.float64),
            reach, SIGMA, self._min_step)
        return out, normal

    def _place(self, frame: np.ndarray, knots: np.ndarray, name: str, which: np.ndarray, scale: float,
               within: float | None = None, expect: np.ndarray | None = None, offset: float | None = None) -> None:
        """Move the interior knots of curve ``name`` selected by ``which`` to the lip edges
        :meth:`_search` finds for them, each keeping its first-frame offset from its edge (or
        ``offset`` px, scaled with the head; in place)."""
        found, normal = self._search(frame, knots, name, which, scale, within, expect)
        hit = np.flatnonzero(np.isfinite(found))
        shift = found[hit] - (self._offset0[name][hit] if offset is None else offset) * scale
        knots[self._index[name][hit]] += shift[:, None] * normal[hit]

    def move(self, frame: np.ndarray, knots: np.ndarray, unfollowed: np.ndarray, scale: float) -> None:
        """Move the interior mouth knots flagged in ``unfollowed`` (a mask over ``knots``, (K, 2)
        px), then the outer knots inside their lips (lip colour outside them, then skin), then
        the inner knots too far inside the mouth, to the lip edges found near them in ``frame``,
        head scale ``scale`` (in place)."""
        if not self.active:
            return
        for name, idx in self._index.items():
            which = unfollowed[idx[1:-1]]
            if which.any():
                self._place(frame, knots, name, which, scale)
        probes, near = [], {}  # per outer curve: the near and the far probes, scored in one call
        for name, side in OUTERMOST.items():
            pts = knots[self._index[name]][1:-1]
            near[name] = np.maximum(PROBE * self._lip0[name] * scale, 2.0)
            step = side * near[name][:, None] * _normals(knots[self._index[name]])[1:-1]
            probes += [pts + step, pts + BEYOND * step]
        scores = _core.lip_scores_near(frame, self.colour, np.concatenate(probes))
        ends = np.cumsum([0] + [len(q) for q in probes])
        for k, name in enumerate(OUTERMOST):
            near_score, far_score = (scores[ends[j]:ends[j + 1]] for j in (2 * k, 2 * k + 1))
            inside = (near_score > LIP_OUTSIDE) & (far_score < SKIN_BEYOND)
            if inside.any():  # the lip's edge lies between the two probes
                self._place(frame, knots, name, inside, scale, within=BEYOND * float(near[name][inside].max()))
        for name in LIP_PAIRS:
            self._thin(frame, knots, name, scale)

    def _thin(self, frame: np.ndarray, knots: np.ndarray, name: str, scale: float) -> None:
        """Move the interior knots of inner curve ``name`` that lie farther from their outer lip
        than :data:`THICKER` first-frame lip thicknesses (at least 1 px each) to the lip edge
        found nearest one thickness inside the outer lip, keeping the curve's median first-frame
        offset from its edge (in place)."""
        gap = self._gaps(knots, name, LIP_PAIRS[name])
        thickness = self._thickness0[name] * scale
        far = np.abs(gap) > THICKER * np.maximum(np.abs(thickness), 1.0)  # False where NaN
        if far.any():
            reach = max(self._reach * scale, SIGMA)
            self._place(frame, knots, name, far, scale, expect=np.clip(gap[far] - thickness[far], -reach, reach),
                        offset=float(np.median(self._offset0[name][1:-1])))
