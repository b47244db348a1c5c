"""Pyramidal Lucas-Kanade optical flow between consecutive frames (the algorithm of OpenCV's
``calcOpticalFlowPyrLK``: same window, derivatives, stopping rules and texture test), with each
frame's pyramid built once in the Rust core and kept for the next frame, where OpenCV builds
two per call. Points are (x, y) pixels of the whole frame, pixel centres on integers.
"""

from __future__ import annotations

import numpy as np

from facemime import _core

WINDOW = 21  # px: side of the square window matched around each point
LEVELS = 5  # pyramid levels above the frame at most (fewer on small crops)
ITERATIONS = 20  # per level at most
EPSILON = 0.03  # px (of the level): stop once a step is shorter
#: Refuse a point whose window's smaller gradient-matrix eigenvalue over the window area is
#: below this ((grey levels / px)²); OpenCV's default ``minEigThreshold`` of 1e-4.
MIN_EIGEN = 1e-4 * 1024


def as_points(points: object) -> np.ndarray:
    """``points`` as the core takes (x, y) points: a C-contiguous (N, 2) float64 array."""
    return np.ascontiguousarray(points, np.float64).reshape(-1, 2)


class FrameFlow:
    """Feed gray frames with :meth:`push`; :meth:`track` follows points from the previous frame
    into the current one, or back."""

    def __init__(self) -> None:
        self._frames = _core.FlowFrames(LEVELS, WINDOW)

    def push(self, gray: np.ndarray, crop: tuple[int, int, int, int]) -> None:
        """The next (H, W) uint8 frame; only ``crop`` = (x0, y0, x1, y1) px, exclusive ends,
        is used: points outside it are not followed."""
        self._frames.push(np.ascontiguousarray(gray, np.uint8), tuple(int(v) for v in crop))

    def track(self, points: np.ndarray, backward: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Positions in the current frame of (N, 2) points of the previous one (the reverse
        with ``backward``): ((N, 2) float64, NaN where lost; (N,) bool, followed)."""
        return self._frames.track(as_points(points), backward, ITERATIONS, EPSILON, MIN_EIGEN)

    def follow(self, points: np.ndarray, extra: np.ndarray, extra_levels: int, limit: float, min_points: int,
               rounds: int) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, np.ndarray]:
        """The head's step from the previous frame to the current one (``facemime_core::motion::
        follow_rigid``): the rigid ``points`` (N, 2) followed forwards and back, those that came
        back within ``limit`` px fitted by a robust similarity (:func:`facemime.track.motion.
        robust_similarity`, ``rounds`` rounds at most) when at least ``min_points`` did and fit
        it; the ``extra`` points (M, 2) followed and checked alike, from where that similarity
        carries them through ``extra_levels`` pyramid levels at most when there is one (those
        that then fail the check, like the rigid points). Returns (the 2×3 similarity,
        or None; the (K,) indices of the rigid points that fit it and their (K, 2) positions now;
        the extra points' (M, 2) positions now, NaN where the flow or its check failed)."""
        return self._frames.follow(as_points(points), as_points(extra), int(extra_levels), float(limit),
                                   int(min_points), int(rounds), ITERATIONS, EPSILON, MIN_EIGEN)
