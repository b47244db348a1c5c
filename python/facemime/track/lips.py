"""The lips' colour and the tracker's wide search for lip edges.

The optical flow cannot follow a lip that moves far in a few frames (a mouth opening wide): its
forward-backward check fails, and the snakes, which reach only δ0/(1−σ) px per pass, stay near
the closed mouth. Such a knot is moved instead along its curve's normal to the nearest lip edge
of that curve's polarity on a lip-colour score.

A lip can also be left behind while the flow follows it. As the mouth opens on teeth, an outer
lip's knots can stay on the lip's inner edge (the teeth's edge has the same luma polarity as the
skin-lip edge): the lip colour then continues outside them, and they are moved to the outermost
lip-skin transition. The inner lips' knots can stay on the teeth near where the lips met: the
lip is then much thicker than it was, and an inner knot farther from its outer lip than 1.8
first-frame lip thicknesses is moved to the lip edge found nearest one such thickness inside the
outer lip.

The searches and moves run in the core (``facemime._core.LipPlacer``); this module fits the
colour and holds the tuned settings' record.

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
from facemime.types.contours import POLARITY
from facemime.types.similarity import as_points

#: Side of the square that grows the outer mouth into the skin ring, as a fraction of the mouth width.
SKIN_RING = 0.3
#: The search is off when lip and skin colours are closer than this: the distance of their
#: mean chromaticities (the six shared videos: 0.026 to 0.062), and that distance over their
#: pooled spread along the discriminant (1.3 to 2.0). The demo's rendered astronaut, smiling
#: on her first frame, has 0.010 and 0.65: on so weak a score the searches moved her lips onto
#: noise (mouth NME 0.015 without them, 0.08 with).
MIN_CHROMA = 0.02
MIN_SEPARATION = 1.0
#: The outer curves' edges are searched outermost first (outside the outer lips lies skin only;
#: the transitions nearer the mouth are those of the teeth and the opening). An inner knot
#: farther from its outer lip than ``THICKER`` = 1.8 first-frame lip thicknesses is searched for
#: again. An outer knot is searched for again when the lip score ``PROBE`` = 0.75 of its
#: first-frame lip thicknesses (at least 2 px) outside it exceeds ``LIP_OUTSIDE`` = 1 skin
#: standard deviation: it lies inside its lip; but only where, ``BEYOND`` = 3 times as far out,
#: the score is below ``SKIN_BEYOND`` = 0.5: skin follows. Measured on the six videos: gates of
#: 0.75 to 1.5 at probes of 0.6 to 1.5 thicknesses track alike; a gate of 0.5 took a shadow
#: under vr_2's lower lip; without the skin beyond, vr_2's reddish skin around the mouth could
#: pull its outer lips outwards frame after frame. These constants, and the score's smoothing of
#: 1.5 px along the normal, live in the core (``facemime_core::lip_placement``), which does the
#: searches and moves the knots.
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
    """The lip score of ``frame`` from its mouth contours.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB array, the first frame.
    contours
        Contour name -> (N, 2) float array, (x, y) pixels; the four mouth contours are read.

    Returns
    -------
    tuple of (w_r, w_g, bias) or None
        The score ``w_r·r + w_g·g − bias`` of a pixel's chromaticities, in skin standard
        deviations; None when fewer than 10 lip or skin pixels, or the colours closer than
        :data:`MIN_CHROMA` or separated by less than :data:`MIN_SEPARATION`.
    """
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

    ``active`` is False when the colours did not separate (or the reach is under 1 px):
    :meth:`move` then does nothing; ``colour`` is the lip score (w_r, w_g, bias) of
    :func:`lip_colour` when the colours separated, else None.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB array, the first frame (fits the colour with ``contours``).
    contours
        Contour name -> (N, 2) float array, (x, y) pixels: the first frame's given contours.
    index
        Contour name -> its knots' indices in the tracker's knot array (the four mouth contours
        are read).
    edges
        (K, 2) float array, (x, y) pixels: the first frame's knots as settled on the image edges
        (each knot keeps, in later frames, the offset from its lip edge it had there: the snakes
        settle on the luma edge, which may lie a little off the colour edge).
    reach
        Search range along a knot's normal: ± this fraction of the first frame's mouth width
        (between the outer upper lip's corners).
    min_step
        Smallest edge the search takes, score units (skin standard deviations) per pixel.
    """

    def __init__(
        self,
        frame: np.ndarray,
        contours: Mapping[str, np.ndarray],
        index: Mapping[str, np.ndarray],
        edges: np.ndarray,
        reach: float,
        min_step: float,
    ):
        self.colour = lip_colour(frame, contours)
        corners = np.asarray(contours["mouth_outer_upper"], np.float64)[[0, -1]]
        reach_px = reach * float(np.linalg.norm(corners[1] - corners[0]))
        self.active = self.colour is not None and reach_px >= 1.0
        if self.active and self.colour is not None:
            self._placer = _core.LipPlacer(
                np.ascontiguousarray(frame),
                self.colour,
                reach_px,
                min_step,
                [list(map(int, index[n])) for n in MOUTH],
                [POLARITY[n][1] for n in MOUTH],
                as_points(edges),
            )

    def move(self, frame: np.ndarray, knots: np.ndarray, unfollowed: np.ndarray, scale: float) -> None:
        """Move mouth knots onto the lip edges found near them in ``frame``, in place.

        First the interior (not corner) mouth knots flagged in ``unfollowed``, then the outer
        knots inside their lips (lip colour outside them, then skin), then the inner knots too
        far inside the mouth. Does nothing when the search is not ``active``.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB array, the current frame.
        knots
            C-contiguous (K, 2) float64 array: the tracker's knots, (x, y) pixels, moved in
            place.
        unfollowed
            (K,) bool array over ``knots``: the knots the optical flow could not follow.
        scale
            The head's scale relative to the first frame (positive; 1 = unchanged).
        """
        if self.active:
            self._placer.place(np.ascontiguousarray(frame), knots, np.ascontiguousarray(unfollowed, bool), float(scale))
