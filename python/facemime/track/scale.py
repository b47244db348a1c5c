"""The tracker's working scale: a face much larger than those the tracker's pixel settings were
tuned on (its reach per frame, smoothing, flow window and lip edge steps are in pixels) is
tracked on frames shrunk to a standard face size, and its contours are reported back in the
frame's own pixels.

Pixel centres map as OpenCV's ``resize`` samples them: a frame point x is at
(x + 0.5)·f − 0.5 in the working frame, f (per axis) about working size / frame size.
"""

from __future__ import annotations

import cv2
import numpy as np

from facemime.track.motion import HeadMotion


class FrameScale:
    """Frame to working pixels, for a face tracked at most ``limit`` px wide; no limit or a face
    no wider keeps the frame as it is.

    A frame shrinks in two steps, each fast in OpenCV (one area-averaging resize by a fraction
    took 4 ms on a 1024 × 1024 frame, longer than tracking it): averaging k × k blocks, k the
    whole number nearest to 1 / factor (the last width mod k columns and height mod k rows are
    dropped), then bilinear resampling by the rest of the factor, about 2/3 to 3/2.

    ``size`` is the frame's (width, height) and ``work`` the working frames' (width, height),
    pixels; ``active`` is whether they differ.

    Parameters
    ----------
    width
        Width of the frames, pixels.
    height
        Height of the frames, pixels.
    face_width
        The face's width (the outer width of the brows), frame pixels.
    limit
        Widest face tracked, pixels (a wider one is shrunk to it); None: no limit.
    """

    def __init__(self, width: int, height: int, face_width: float, limit: float | None):
        self.size = (width, height)
        factor = 1.0 if limit is None or face_width <= limit else limit / face_width
        self._k = max(round(1.0 / factor), 1)
        self._blocks = (max(width // self._k, 1), max(height // self._k, 1))
        rest = factor * self._k
        self.work = (max(round(self._blocks[0] * rest), 1), max(round(self._blocks[1] * rest), 1))
        self.active = self.work != self.size
        self._f = np.array(self.work) / (self._k * np.array(self._blocks))

    def frame(self, image: np.ndarray) -> np.ndarray:
        """An image of the frame's size resized to the working size.

        Parameters
        ----------
        image
            (height, width) grey or (height, width, 3) RGB uint8, the frame's size.

        Returns
        -------
        uint8 array of the working size
            The shrunk image, with ``image``'s channels; ``image`` itself when not :attr:`active`.
        """
        if not self.active:
            return image
        if self._k > 1:
            w, h = self._blocks
            image = cv2.resize(image[: h * self._k, : w * self._k], self._blocks, interpolation=cv2.INTER_AREA)
        if self.work != self._blocks:
            image = cv2.resize(image, self.work, interpolation=cv2.INTER_LINEAR)
        return image

    def to_work(self, pts: np.ndarray) -> np.ndarray:
        """Frame pixels to working pixels.

        Parameters
        ----------
        pts
            (N, 2) float array, (x, y) frame pixels.

        Returns
        -------
        (N, 2) float64 array
            (x, y) working pixels (a new array).
        """
        return (np.asarray(pts, np.float64) + 0.5) * self._f - 0.5 if self.active else np.array(pts, np.float64)

    def frame_step(self, step: np.ndarray) -> np.ndarray:
        """A transform of working pixels as the transform of frame pixels it is.

        Parameters
        ----------
        step
            (2, 3) float array: an affine map of (x, y) working pixels (a frame's head motion).

        Returns
        -------
        (2, 3) float64 array
            The same map of (x, y) frame pixels (a new array).
        """
        out = np.array(step, np.float64)
        if self.active:
            f, c = self._f, 0.5 * self._f - 0.5  # working = f·frame + c, per axis
            out[:, :2] = out[:, :2] * f[None, :] / f[:, None]
            out[:, 2] = (step[:, :2] @ c + step[:, 2] - c) / f
        return out

    def to_frame(self, pts: np.ndarray) -> np.ndarray:
        """Working pixels to frame pixels.

        Parameters
        ----------
        pts
            (N, 2) float array, (x, y) working pixels.

        Returns
        -------
        (N, 2) float64 array
            (x, y) frame pixels (a new array).
        """
        return (np.asarray(pts, np.float64) + 0.5) / self._f - 0.5 if self.active else np.array(pts, np.float64)


class ScaledMotion:
    """The rigid points of a :class:`facemime.track.motion.HeadMotion` that runs on working
    frames, in the frame's pixels: ``points`` (M, 2) float32, ``ids`` (M,) int64,
    ``followed`` and the last frame's 2×3 ``step``, as the head motion's own.

    Parameters
    ----------
    motion
        The head motion, fed working frames.
    scale
        The frame's scale to those working frames.
    """

    def __init__(self, motion: HeadMotion, scale: FrameScale):
        self._motion, self._scale = motion, scale

    def _frame_points(self, pts: np.ndarray) -> np.ndarray:
        return self._scale.to_frame(pts).astype(np.float32)

    @property
    def points(self) -> np.ndarray:
        return self._frame_points(self._motion.points)

    @property
    def ids(self) -> np.ndarray:
        return self._motion.ids

    @property
    def followed(self) -> tuple[np.ndarray, np.ndarray]:
        pts, ids = self._motion.followed
        return self._frame_points(pts), ids

    @property
    def step(self) -> np.ndarray:
        return self._scale.frame_step(self._motion.step)
