"""Following the whole mouth by matching its region when the optical flow loses its knots."""

import cv2
import numpy as np
import pytest

from facemime.metrics import group_nme
from facemime.track import Tracker, TrackerParams
from facemime.track.contours import GROUPS
from facemime.track.match import find
from facemime.track.mouth import mouth_shift


def texture(seed: int, size: int = 256) -> np.ndarray:
    noise = np.random.default_rng(seed).normal(0.0, 1.0, (size, size)).astype(np.float32)
    smooth = cv2.GaussianBlur(noise, (0, 0), 3.0)
    return np.clip(128 + smooth * 400, 0, 255).astype(np.uint8)


def mouth_knots(centre=(128.0, 140.0), width=60.0) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False)
    return np.stack([centre[0] + width / 2 * np.cos(t), centre[1] + width / 5 * np.sin(t)], axis=1)


def test_find_puts_the_template_centre_where_it_was_cut():
    image = texture(1)
    template = image[100:131, 60:101]  # centre (80, 115)
    assert np.allclose(find(image, template, np.array([86.0, 111.0]), 10.0, 0.6), [80.0, 115.0])
    # Out of reach, in a window that cannot hold it, or against another texture: no match.
    assert find(image, template, np.array([120.0, 115.0]), 10.0, 0.6) is None
    assert find(image, template, np.array([2.0, 2.0]), 0.0, 0.6) is None
    assert find(texture(2), template, np.array([80.0, 115.0]), 10.0, 0.6) is None


@pytest.mark.parametrize("head", [(0.0, 0.0), (5.0, -2.0)])
def test_the_mouth_shift_is_its_motion_beyond_the_head(head):
    prev = texture(3)
    moved = np.roll(prev, (3, 15), axis=(0, 1))  # everything 15 px right, 3 px down
    knots = mouth_knots()
    shift = mouth_shift(prev, moved, knots, knots + head)
    assert np.allclose(shift, np.array([15.0, 3.0]) - head)


def test_no_shift_where_the_mouth_is_not_found():
    knots = mouth_knots()
    assert mouth_shift(texture(4), texture(5), knots, knots) is None
    flat = np.full((256, 256), 90, np.uint8)
    assert mouth_shift(flat, texture(5), knots, knots) is None


@pytest.mark.parametrize("patch", [0.5, 0.0])
def test_follows_a_mouth_pushed_sideways_in_a_real_video(shared, patch):
    # lp_d6 frames 545-575: she pushes her mouth sideways and back within a few frames (a video
    # that also drops frames), and most mouth knots fail the flow's forward-backward check.
    # Without the region match the outer mouth was off by up to 0.10 (NME).
    from facemime.io.video import VideoReader
    from facemime.track.contours import from_face_mesh as reference_contours

    z = np.load(shared / "video" / "lp_d6.landmarks.npz")
    with VideoReader(shared / "video" / "lp_d6.mp4") as reader:
        frames = [f for i, f in zip(range(575), reader) if i >= 545]
    tracker = Tracker(frames[0], reference_contours(z["landmarks"][545]), TrackerParams(mouth_patch=patch))
    errors = []
    for i, frame in enumerate(frames[1:], 546):
        contours = tracker.update(frame).contours
        reference = reference_contours(z["landmarks"][i])
        errors.append(group_nme(contours, reference, GROUPS["mouth_outer"], float(z["iod"][i])))
    if patch:
        assert max(errors) < 0.07 and np.mean(errors) < 0.035
    else:
        assert max(errors) > 0.08
