"""Following the whole mouth when the optical flow loses its knots, and finding it again when
it has been lost for a while.

A mouth pushed sideways or pulled into a grimace within a frame or two (face-pulling, or a video
that drops frames) deforms faster than the flow's windows follow: most mouth knots fail its
forward-backward check and stay where the head motion puts them, often more than the snakes'
reach (δ0/(1−σ) px) from the lips. The mouth region as a whole still looks much as it did in the
previous frame: matching that region, gray, around where the head motion put it
(:mod:`facemime.track.template`) measures how far the mouth moved beyond the head; the tracker
moves the knots the flow lost by its part along the mouth line (an opening, up and down, is
left to the lip searches).

A mouth that slid off the lips (onto the cheek, after a cut between takes) can hold an edge
there and stay, flagged lost. After a lost frame (the tracker's ``mouth_relocate``) the lips are
looked for by their colour: the first frame's outer mouth, placed where the brows put it, is
slid and scaled over the lip score (:func:`facemime.track.template.locate`) within most of a mouth
width sideways, half a width down the face (a dropping jaw) and a fifth up (the upper lip is
borne by the skull: further up lie the nostrils), and kept only where it is clearly more
lip-coloured, against the skin around it, than the tracked mouth.

Coordinates are (x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

import numpy as np

from facemime import _core
from facemime.track.template import Placement, crop_box, find, gray_crop, locate

#: The template is the box of the previous frame's mouth knots grown by this fraction of the
#: mouth's width (some skin around the lips: measured on the six videos, 0.1 followed the mouth
#: worse than 0.15 and 0.25).
MARGIN = 0.25
#: The window searched: ± this fraction of the mouth's width around where the head moved it.
REACH = 0.4
#: A match below this correlation is no match (on lp_d6 the matches that moved the mouth right
#: correlate 0.6 to 0.97; across a cut between takes a wrong one, 27 px off, 0.53).
MIN_MATCH = 0.6
#: A lost mouth is looked for within these fractions of its width of where the brows put it:
#: ± the first along the mouth line, the second up and the third down the face, at these scales.
#: Measured on lp_d6 from eight starts (the reference and seven with 0.2 px of noise on it): with
#: 0.4 both ways, in one start a wide-open mouth was put on the nostrils and stayed there,
#: unflagged, for 55 frames, and the outer mouth's frames with NME > 0.1 were 4 to 89 per start
#: (mean 24); with (0.2, 0.5), 1 to 16 (mean 8). Up/down 0.15/0.6 gave a mean of 15, 0.2/0.6
#: 27, 0.25/0.5 12.
RELOCATE_REACH = (0.8, 0.2, 0.5)
RELOCATE_SCALES = (0.8, 1.0, 1.25)
#: The band of skin around the mouth that its inside is compared with, a fraction of its width.
RING = 0.12
#: The lip score is clipped to ± this (skin standard deviations), so that a few vivid pixels do
#: not outweigh the rest.
CLIP = 2.0
#: A place found is kept when its contrast (mean clipped lip score inside minus in the ring)
#: beats the tracked mouth's by this much.
GAIN = 0.5


def mouth_shift(prev_image: np.ndarray, image: np.ndarray, prev: np.ndarray, carried: np.ndarray) -> np.ndarray | None:
    """How far the mouth moved from ``prev_image`` to ``image`` beyond the head: the previous
    frame's mouth region (the box of ``prev`` grown by :data:`MARGIN` of the mouth's width) matched
    in ``image`` within :data:`REACH` of its width of where the head motion put it.

    Parameters
    ----------
    prev_image
        (H, W) grey or (H, W, 3) RGB uint8: the previous frame.
    image
        (H, W) grey or (H, W, 3) RGB uint8: this frame.
    prev
        (K, 2) float array, (x, y) pixels: the mouth's knots in the previous frame; their x
        extent is the mouth's width.
    carried
        (K, 2) float array, (x, y) pixels: the same knots moved by the head motion into this
        frame.

    Returns
    -------
    (2,) float64 array or None
        (x, y) pixels from where the head motion put the region (the mean of ``carried`` less
        that of ``prev``) to where it matched best; None when the region is under 8 px a side
        or flat (grey standard deviation under 1 level), or matched nowhere above
        :data:`MIN_MATCH`.
    """
    height, width = image.shape[:2]
    size = float(np.ptp(prev[:, 0]))
    lo, hi = crop_box(prev, MARGIN * size, width, height)
    template = gray_crop(prev_image, lo, hi)
    if min(template.shape) < 8 or template.std() < 1.0:
        return None
    expected = (lo + hi - 1) / 2.0 + carried.mean(axis=0) - prev.mean(axis=0)
    found = find(image, template, expected, REACH * size, MIN_MATCH)
    return None if found is None else found - expected


def relocate(
    frame: np.ndarray, colour: tuple[float, float, float], expected: np.ndarray, current: np.ndarray, down: np.ndarray
) -> Placement | None:
    """Where the lips of ``frame`` are, as the placement of the outer mouth polygon ``expected``
    that fits them best, searched :data:`RELOCATE_REACH` of its width around it at the scales of
    :data:`RELOCATE_SCALES` (the window is an image-aligned box, so for a tilted head the reaches
    hold along the image axes).

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the frame searched.
    colour
        (w_r, w_g, bias): the lip score of the first frame
        (:func:`facemime.track.lips.lip_colour`), in skin standard deviations.
    expected
        (N, 2) float array, (x, y) pixels: the outer mouth polygon (upper curve, then the lower
        one reversed) where the mouth is expected; its x extent is the mouth's width.
    current
        (N, 2) float array, (x, y) pixels: the tracked outer mouth polygon, in the same order.
    down
        (2,) float array: the face's unit down direction in the image.

    Returns
    -------
    Placement or None
        How to move ``expected`` (:meth:`Placement.apply` about its centroid): scale, then
        shift in pixels; ``contrast`` is the mean clipped lip score inside the polygon minus that
        in the ring of skin around it (:data:`RING`). None unless it beats the contrast of
        ``current`` by :data:`GAIN`.
    """
    height, width = frame.shape[:2]
    size = float(np.ptp(expected[:, 0]))
    sideways, up, lower = RELOCATE_REACH
    # The window's centre moves down the face by half the difference of its reaches.
    offset = 0.5 * (lower - up) * size * down
    middle = expected + offset
    reach, ring = (sideways * size, 0.5 * (lower + up) * size), max(2.0, RING * size)
    lo, hi = crop_box(np.concatenate([middle, current]), max(RELOCATE_SCALES) * max(reach) + ring, width, height)
    scores = _core.lip_score_map(frame, colour, (int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])))
    channel = np.clip(scores, -CLIP, CLIP)
    found = locate(channel, middle - lo, reach, ring, RELOCATE_SCALES)
    now = locate(channel, current - lo, (0.0, 0.0), ring)
    if found.contrast <= now.contrast + GAIN:
        return None
    return Placement(found.shift + offset, found.scale, found.contrast)
