"""The lips' colour and the tracker's wide search for lip edges.

The optical flow cannot follow a lip that moves far in a few frames (a mouth opening wide): its
forward-backward check fails, and the snakes, which reach only δ0/(1−σ) px per pass, stay near
the closed mouth. Such a knot is moved instead along its curve's normal to the nearest lip edge
of that curve's polarity on a lip-colour score (``facemime._core.find_lip_edges``).

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

#: Side of the square that grows the outer mouth into the skin ring, as a fraction of the mouth width.
SKIN_RING = 0.3
#: The search is off when lip and skin colours are closer than this: the distance of their
#: mean chromaticities (the six shared videos: 0.026 to 0.062), and that distance over their
#: pooled spread along the discriminant (1.3 to 2.0).
MIN_CHROMA = 0.01
MIN_SEPARATION = 0.5
SIGMA = 1.5  # px: smoothing of the score along the normal
#: The outer curves' edges are searched outermost first: above (−1) or below (+1) along the normal.
OUTERMOST = {"mouth_outer_upper": -1.0, "mouth_outer_lower": +1.0}
MOUTH = ("mouth_outer_upper", "mouth_outer_lower", "mouth_inner_upper", "mouth_inner_lower")


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
    """Moves mouth knots the flow could not follow onto the lip edges.

    ``frame``, ``contours``: the first frame and its given contours (fit the colour);
    ``index``: contour name -> its knots' indices in the tracker's knot array; ``edges``: the
    first frame's knots as settled on the image edges; ``reach``: search range, ± this fraction
    of the first frame's mouth width; ``min_step``: smallest edge (score units per px).
    ``active`` is False when the colours did not separate: :meth:`move` then does nothing.
    """

    def __init__(self, frame: np.ndarray, contours: Mapping[str, np.ndarray], index: Mapping[str, np.ndarray],
                 edges: np.ndarray, reach: float, min_step: float):
        self._colour = lip_colour(frame, contours)
        corners = np.asarray(contours["mouth_outer_upper"], np.float64)[[0, -1]]
        self._reach = reach * float(np.linalg.norm(corners[1] - corners[0]))
        self._min_step = min_step
        self._index = {n: index[n] for n in MOUTH}
        self.active = self._colour is not None and self._reach >= 1.0
        # Where each knot sat from its lip edge on the first frame (the snakes settle on the
        # luma edge, which may lie a little off the colour edge): kept in later frames.
        self._offset0 = {n: np.zeros(len(i)) for n, i in self._index.items()}
        if self.active:
            for name, idx in self._index.items():
                found, _ = self._search(frame, edges, name, np.ones(len(idx) - 2, bool), 1.0)
                self._offset0[name] = np.nan_to_num(found)

    def _search(self, frame: np.ndarray, knots: np.ndarray, name: str, which: np.ndarray,
                scale: float) -> tuple[np.ndarray, np.ndarray]:
        """The offsets (px along the downward normals) of the lip edges from the knots of curve
        ``name`` selected by ``which`` (a mask over the curve's interior knots; NaN for the
        others and where none was found), and the curve's (N, 2) unit normals."""
        pts = knots[self._index[name]]
        along = np.gradient(pts, axis=0)
        along /= np.maximum(np.linalg.norm(along, axis=1, keepdims=True), 1e-9)
        normal = np.stack([-along[:, 1], along[:, 0]], axis=1)  # curves run left to right: down
        pick = np.flatnonzero(which) + 1
        out = np.full(len(pts), np.nan)
        reach = max(self._reach * scale, SIGMA)  # the core takes σ ≤ reach, and a head may shrink
        # Outside the outer lips lies skin only: their edge is the outermost lip-skin transition
        # (the transitions nearer the mouth are those of the teeth and the opening).
        expect = OUTERMOST[name] * reach if name in OUTERMOST else self._offset0[name][pick] * scale
        out[pick] = _core.find_lip_edges(
            frame, self._colour, np.ascontiguousarray(pts[pick]), np.ascontiguousarray(normal[pick]),
            np.full(len(pick), POLARITY[name][1]), np.broadcast_to(expect, len(pick)).astype(np.float64),
            reach, SIGMA, self._min_step)
        return out, normal

    def move(self, frame: np.ndarray, knots: np.ndarray, unfollowed: np.ndarray, scale: float) -> None:
        """Move the interior mouth knots flagged in ``unfollowed`` (a mask over ``knots``, (K, 2)
        px) to the lip edge found near them in ``frame``, head scale ``scale`` (in place)."""
        if not self.active:
            return
        for name, idx in self._index.items():
            which = unfollowed[idx[1:-1]]
            if not which.any():
                continue
            found, normal = self._search(frame, knots, name, which, scale)
            hit = np.flatnonzero(np.isfinite(found))
            shift = found[hit] - self._offset0[name][hit] * scale
            knots[idx[hit]] += shift[:, None] * normal[hit]
