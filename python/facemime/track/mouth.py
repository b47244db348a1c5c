"""Following the whole mouth when the optical flow loses its knots.

A mouth pushed sideways or pulled into a grimace within a frame or two (face-pulling, or a video
that drops frames) deforms faster than the flow's windows follow: most mouth knots fail its
forward-backward check and stay where the head motion puts them, often more than the snakes'
reach (δ0/(1−σ) px) from the lips. The mouth region as a whole still looks much as it did in the
previous frame: matching that region, gray, around where the head motion put it
(:mod:`facemime.track.match`) measures how far the mouth moved beyond the head; the tracker
moves the knots the flow lost by its part along the mouth line (an opening, up and down, is
left to the lip searches). Coordinates are (x, y) pixels, origin at the centre of the top-left
pixel, y down.
"""

from __future__ import annotations

import numpy as np

from facemime.track.match import crop_box, find

#: The template is the box of the previous frame's mouth knots grown by this fraction of the
#: mouth's width (some skin around the lips: measured on the six videos, 0.1 followed the mouth
#: worse than 0.15 and 0.25).
MARGIN = 0.25
#: The window searched: ± this fraction of the mouth's width around where the head moved it.
REACH = 0.4
#: A match below this correlation is no match (on lp_d6 the matches that moved the mouth right
#: correlate 0.6 to 0.97; across a cut between takes a wrong one, 27 px off, 0.53).
MIN_MATCH = 0.6


def mouth_shift(prev_gray: np.ndarray, gray: np.ndarray, prev: np.ndarray, carried: np.ndarray) -> np.ndarray | None:
    """How far the mouth moved from ``prev_gray`` to ``gray`` ((H, W) uint8) beyond the head:
    the (2,) px from ``carried`` ((K, 2) px, the mouth's knots ``prev`` of the previous frame
    moved by the head motion) to where the previous frame's mouth region matched best; None when
    it matched nowhere."""
    height, width = gray.shape
    lo, hi = crop_box(prev, MARGIN * float(np.ptp(prev[:, 0])), width, height)
    template = prev_gray[lo[1]:hi[1], lo[0]:hi[0]]
    if min(template.shape) < 8 or template.std() < 1.0:
        return None
    expected = (lo + hi - 1) / 2.0 + carried.mean(axis=0) - prev.mean(axis=0)
    reach = REACH * float(np.ptp(prev[:, 0]))
    found = find(gray, template, expected, reach, MIN_MATCH)
    if found is None:
        return None
    return found - expected
