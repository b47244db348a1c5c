"""The lip colour and the wide lip-edge search for mouth knots the flow could not follow."""

import cv2
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
    # for the nearest falling edge would take; the flow followed the other curves.
    opened, truth = band_face(opening=24.0, noise=2.0, seed=1)
    knots = _knots(truth)
    knots[11:22] = contours["mouth_outer_lower"]
    unfollowed = np.zeros(len(knots), bool)
    unfollowed[11:22] = True  # the outer lower lip's knots
    search.move(opened, knots, unfollowed, 1.0)
    assert _error(knots[12:21], truth["mouth_outer_lower"]) < 1.0  # its interior knots (corners never move)
    assert np.array_equal(np.delete(knots, np.s_[12:21], axis=0), np.delete(_knots(truth), np.s_[12:21], axis=0))


def _error(knots, curve):
    """Largest distance (px) of ``knots`` from the polyline ``curve``."""
    s = np.linspace(0.0, len(curve) - 1.0, 100 * len(curve))
    dense = np.stack([np.interp(s, np.arange(len(curve)), curve[:, i]) for i in (0, 1)], axis=1)
    return np.linalg.norm(knots[:, None] - dense[None], axis=2).min(axis=1).max()


def test_lips_left_behind_by_the_flow_as_the_mouth_opens_on_teeth_are_moved_to_their_edges():
    # The flow followed every knot, but the mouth opened on teeth under them: the outer upper
    # lip's knots sit on the lip's inner edge (the lip colour continues above them), and the
    # inner lower lip's on the closed mouth's line, 17 px above its edge (the lower lip is now
    # nearly three times as thick as on the first frame).
    frame, contours = band_face(noise=2.0)
    search = LipSearch(frame, contours, _index(), _knots(contours), reach=0.3, min_step=0.3)
    opened, truth = band_face(opening=24.0, noise=2.0, seed=1)
    teeth = np.concatenate([truth["mouth_inner_upper"], truth["mouth_inner_lower"][::-1]])
    cv2.fillPoly(opened, [np.round(teeth * 16).astype(np.int32)], (235, 230, 220), cv2.LINE_AA, 4)
    knots = _knots(truth)
    knots[0:11] = truth["mouth_inner_upper"]
    knots[33:44] = contours["mouth_inner_lower"]
    assert _error(knots[1:10], truth["mouth_outer_upper"]) > 7.0
    assert _error(knots[34:43], truth["mouth_inner_lower"]) > 16.0
    search.move(opened, knots, np.zeros(len(knots), bool), 1.0)
    assert _error(knots[1:10], truth["mouth_outer_upper"]) < 1.5
    # within the snakes' reach (6 px) of its edge: the knot keeps the first frame's offset
    # from the colour edge, which on a closed mouth is the line where the lips met
    assert _error(knots[34:43], truth["mouth_inner_lower"]) < 6.0
    for k, name in ((1, "mouth_outer_lower"), (2, "mouth_inner_upper")):  # left on their edges
        np.testing.assert_array_equal(knots[11 * k : 11 * (k + 1)], truth[name])


def test_the_inner_lips_follow_a_real_mouth_opening_wide_on_teeth(shared):
    # lp_d6's first 520 frames open her mouth wide on her teeth several times. Without the
    # searches for lips left inside their lips or inside the mouth, the inner lips stayed on
    # the teeth near where the lips met: mean NME 0.057–0.060, 13–15% of frames above 0.10
    # (with them: 0.036–0.038, 0.6–2.7%, as small changes elsewhere move the track).
    from facemime.io.video import VideoReader
    from facemime.metrics import group_nme
    from facemime.track import Tracker
    from facemime.types.contours import GROUPS
    from facemime.types.contours import from_face_mesh as reference_contours

    z = np.load(shared / "video" / "lp_d6.landmarks.npz")
    with VideoReader(shared / "video" / "lp_d6.mp4") as reader:
        frames = [f for _, f in zip(range(520), reader)]
    tracker = Tracker(frames[0], reference_contours(z["landmarks"][0]))
    errors = []
    for i, frame in enumerate(frames[1:], 1):
        contours = tracker.update(frame).contours
        errors.append(
            group_nme(contours, reference_contours(z["landmarks"][i]), GROUPS["mouth_inner"], float(z["iod"][i]))
        )
    assert np.mean(errors) < 0.045 and np.mean(np.array(errors) > 0.10) < 0.05


def test_an_outer_lip_under_reddish_skin_stays_on_its_edge():
    # Skin as red as the lips above the mouth (a flush, a shadow) is lip colour outside the
    # outer upper lip, but no skin follows farther out: the lip is not moved there.
    frame, contours = band_face(noise=2.0)
    search = LipSearch(frame, contours, _index(), _knots(contours), reach=0.3, min_step=0.3)
    flushed = frame.copy()
    flushed[100:158, 70:186] = LIP  # from 1 to 59 px above the middle of the upper lip
    knots = _knots(contours)
    search.move(flushed, knots, np.zeros(len(knots), bool), 1.0)
    np.testing.assert_array_equal(knots, _knots(contours))
