"""Contours drawn over frames: on a copy, or into part of a larger canvas."""

import numpy as np

from facemime.track.overlay import COLOURS, LOST_COLOUR, draw_contours
from facemime.track.synthetic import band_face


def test_contours_are_drawn_on_a_copy_in_their_feature_colours():
    frame, contours = band_face()
    before = frame.copy()
    out = draw_contours(frame, contours, lost=["brow_left"])
    assert np.array_equal(frame, before)  # the caller's frame is untouched
    middle = len(contours["mouth_outer_upper"]) // 2  # the corners are the inner mouth's too
    x, y = np.round(contours["mouth_outer_upper"][middle]).astype(int)
    assert tuple(out[y, x]) == COLOURS["mouth_outer"]  # a knot dot, drawn opaque at its centre
    x, y = np.round(contours["brow_left_upper"][middle // 2]).astype(int)
    assert tuple(out[y, x]) == LOST_COLOUR


def test_drawing_into_half_a_side_by_side_canvas_matches_the_copy_and_spares_the_other_half():
    frame, contours = band_face()
    h, w = frame.shape[:2]
    canvas = np.full((h, 2 * w, 3), 7, np.uint8)
    draw_contours(frame, contours, out=canvas[:, :w])
    assert np.array_equal(canvas[:, :w], draw_contours(frame, contours))
    assert (canvas[:, w:] == 7).all()
