"""Pyramidal Lucas-Kanade optical flow between consecutive frames (the algorithm of OpenCV's
``calcOpticalFlowPyrLK``: same window, derivatives, stopping rules and texture test), with each
frame's pyramid built once in the Rust core and kept for the next frame, where OpenCV builds
two per call. Points are (x, y) pixels of the whole frame, pixel centres on integers.
"""

from __future__ import annotations

import numpy as np

from facemime import _core
from facemime.types.similarity import as_points

WINDOW = 21  # px: side of the square window matched around each point
LEVELS = 5  # pyramid levels above the frame at most (fewer on small crops)
ITERATIONS = 20  # per level at most
EPSILON = 0.03  # px (of the level): stop once a step is shorter
#: Refuse a point whose window's smaller gradient-matrix eigenvalue over the window area is
#: below this ((grey levels / px)²); OpenCV's default ``minEigThreshold`` of 1e-4.
MIN_EIGEN = 1e-4 * 1024


class FrameFlow:
    """Feed frames with :meth:`push`; :meth:`track` follows points from the previous frame
    into the current one, or back."""

    def __init__(self) -> None:
        self._frames = _core.FlowFrames(LEVELS, WINDOW)

    def push(self, frame: np.ndarray, crop: tuple[int, int, int, int]) -> None:
        """Take the next frame: it becomes the current one, the current one the previous.

        Parameters
        ----------
        frame
            (H, W) gray or (H, W, 3) RGB uint8 array (read as OpenCV's ``RGB2GRAY`` gray levels).
        crop
            (x0, y0, x1, y1) pixels of the frame, exclusive ends: the only part used; points
            outside it are not followed.
        """
        self._frames.push(
            np.ascontiguousarray(frame, np.uint8), (int(crop[0]), int(crop[1]), int(crop[2]), int(crop[3]))
        )

    def track(self, points: np.ndarray, backward: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Positions in the current frame of points of the previous one (or the reverse).

        Needs two frames pushed.

        Parameters
        ----------
        points
            (N, 2) float array: (x, y) pixels in the previous frame (in the current one with
            ``backward``).
        backward
            Follow the points from the current frame back into the previous one.

        Returns
        -------
        positions : (N, 2) float64 array
            (x, y) pixels in the current frame (the previous one with ``backward``), NaN where
            lost.
        followed : (N,) bool array
            True where the point was followed.
        """
        return self._frames.track(as_points(points), backward, ITERATIONS, EPSILON, MIN_EIGEN)
