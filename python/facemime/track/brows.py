"""The tracker's wide search for a brow it has lost.

A brow raised fast, or a head that jumps between frames (a video that dropped frames), moves a
brow further than the snakes reach (δ0/(1−σ) px per frame) and than the optical flow follows:
the snakes then settle on the eyelid's crease or on bare skin and the brow's edge response
collapses. Such a brow is looked for again by matching the first frame's brow, gray and scaled
with the head, over a window around where the head motion put it (:mod:`facemime.track.template`).
Coordinates are (x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

import cv2
import numpy as np

from facemime.track.template import crop_box, find, gray_crop

#: The template is the box of the brow's knots grown by this fraction of the brow's width.
MARGIN = 0.12
#: The window searched: ± this fraction of the brow's width around the expected position.
REACH = 0.5
#: A match below this correlation is no match.
MIN_MATCH = 0.5


class BrowSearch:
    """Finds one brow again.

    The template is the first frame's gray box around the brow's knots grown by :data:`MARGIN`
    of the brow's width; a template under 8 px on a side or with a gray-level spread under 1
    leaves the search inactive (:meth:`find` then finds nothing).

    Parameters
    ----------
    image
        The first frame, (H, W) gray or (H, W, 3) RGB uint8 array.
    knots
        (K, 2) float array: that brow's knots on it, (x, y) pixels.
    """

    def __init__(self, image: np.ndarray, knots: np.ndarray):
        self._knots0 = np.asarray(knots, np.float64)
        self._width = float(np.ptp(self._knots0[:, 0]))
        lo, hi = crop_box(self._knots0, MARGIN * self._width, image.shape[1], image.shape[0])
        self._template = gray_crop(image, lo, hi)
        self._centre0 = (lo + hi - 1) / 2.0  # the template's centre, px of the first frame
        self.active = min(self._template.shape) >= 8 and self._template.std() >= 1.0

    def find(self, image: np.ndarray, scale: float, expected: np.ndarray) -> np.ndarray | None:
        """The brow's knots in ``image``, or None when nothing matched.

        The template is searched within ± :data:`REACH` of the brow's width (scaled) around where
        ``expected`` puts it; a correlation below :data:`MIN_MATCH` is no match.

        Parameters
        ----------
        image
            The current frame, (H, W) gray or (H, W, 3) RGB uint8 array.
        scale
            The head's scale since the first frame (1 = unchanged); the template is resized by it.
        expected
            (K, 2) float array: where the head motion put the knots, (x, y) pixels.

        Returns
        -------
        (K, 2) float64 array or None
            The first frame's knots, (x, y) pixels, scaled by ``scale`` about the template's
            centre and moved to the match; None when the search is inactive or nothing matched.
        """
        if not self.active:
            return None
        templ = self._template
        if abs(scale - 1.0) > 0.02:
            templ = cv2.resize(
                templ, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR
            )
        centre = np.asarray(expected, np.float64).mean(axis=0) + (self._centre0 - self._knots0.mean(axis=0)) * scale
        found = find(image, templ, centre, REACH * self._width * scale, MIN_MATCH)
        return None if found is None else (self._knots0 - self._centre0) * scale + found
