"""The lip colour and the wide lip-edge search for mouth knots the flow could not follow."""

import numpy as np

from facemime.track.lips import MOUTH, LipSearch, lip_colour
from facemime.track.synthetic import LIP, SKIN, band_face


def _score(colour, rgb):
    r, g, b = (float(v) for v in rgb)
    return colour[0] * r / (r + g + b + 1) + colour[1] * g / (r + g + b + 1) - colour[2]


def test_the_lip_score_is_positive_on_lips_and_negative_on_skin():
    frame, contours = band_face(noise=2.0)
    colour = lip_colour(frame, contours)
    assert colour is not None
    assert _score(colour, LIP) > 1.0 and _score(colour, SKIN) < -1.0


def test_no_lip_score_when_lips_and_skin_have_the_same_colour():
    frame, contours = band_face(noise=2.0)
    grey = np.repeat(frame.mean(axis=2, keepdims=True).astype(np.uint8), 3, axis=2)
    assert lip_colour(grey, contours) is None
    search = LipSearch(grey, contours, _index(), _knots(contours), reach=0.3, min_step=0.3)
    knots = _knots(contours)
    search.move(band_face(opening=16.0, noise=2.0)[0], knots, np.ones(len(knots), bool), 1.0)
    assert not search.active and np.array_equal(knots, _knots(contours))


def _index():
    return {n: np.arange(11 * k, 11 * (k + 1)) for k, n in enumerate(MOUTH)}


def _knots(contours):
    return np.concatenate([contours[n] for n in MOUTH])


def test_a_lip_that_jumped_far_is_moved_onto_its_edge():
    frame, contours = band_face(noise=2.0)
    search = LipSearch(frame, contours, _index(), _knots(contours), reach=0.3, min_step=0.3)
    # The lower lip drops 17 px, past the upper lip's edge on the dark opening, which a search
    # for the nearest falling edge would take.
    opened, truth = band_face(opening=24.0, noise=2.0, seed=1)
    knots = _knots(contours)
    unfollowed = np.zeros(len(knots), bool)
    unfollowed[11:22] = True  # the outer lower lip's knots
    search.move(opened, knots, unfollowed, 1.0)
    moved = knots[12:21]  # its interior knots (the corners are never moved)
    expected = np.interp(moved[:, 0], truth["mouth_outer_lower"][:, 0], truth["mouth_outer_lower"][:, 1])
    assert np.abs(moved[:, 1] - expected).max() < 1.0
    assert np.array_equal(np.delete(knots, np.s_[12:21], axis=0), np.delete(_knots(contours), np.s_[12:21], axis=0))
