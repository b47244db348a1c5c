"""Head-motion compensation: the robust similarity fit, the head followed on real videos and
reproducible tracks."""

import itertools

import cv2
import numpy as np
import pytest

from facemime.io.video import VideoReader
from facemime.track import Tracker
from facemime.track.motion import CORNER_BLOCK, DETECT_MARGIN, QUALITY, HeadMotion
from facemime.track.synthetic import band_face
from facemime.types.contours import from_face_mesh
from facemime.types.similarity import apply, robust_similarity

NOSE_BRIDGE = [6, 197, 195, 5]  # Face Mesh landmarks on the nose, between the eyes and the tip


def gray_frames(shared, video: str, count: int) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The first ``count`` frames of a shared video in gray, its landmarks and IODs."""
    with VideoReader(shared / "video" / f"{video}.mp4") as reader:
        frames = [cv2.cvtColor(f, cv2.COLOR_RGB2GRAY) for f in itertools.islice(reader, count)]
    z = np.load(shared / "video" / f"{video}.landmarks.npz")
    return frames, z["landmarks"], z["iod"]


def test_robust_similarity_recovers_the_motion_despite_gross_outliers():
    rng = np.random.default_rng(3)
    src = rng.uniform(100, 300, (40, 2))
    angle, scale = np.radians(4.0), 1.05
    truth = np.array(
        [[scale * np.cos(angle), -scale * np.sin(angle), 7.5], [scale * np.sin(angle), scale * np.cos(angle), -3.0]]
    )
    dst = apply(truth, src) + rng.normal(0.0, 0.1, src.shape)
    bad = rng.choice(40, 12, replace=False)  # 30 % of the points jump 5-40 px
    dst[bad] += rng.uniform(5, 40, (12, 2)) * rng.choice([-1, 1], (12, 2))
    m, inliers = robust_similarity(src, dst, limit=1.0)
    assert np.abs(apply(m, src) - apply(truth, src)).max() < 0.15
    assert not inliers[bad].any() and inliers.sum() >= 40 - 12 - 1


def test_the_same_frames_give_the_same_track_twice_in_one_process():
    frames = [band_face(shift=(0.8 * t, -0.5 * t), opening=0.5 * t, noise=3.0, seed=t)[0] for t in range(12)]
    _, truth0 = band_face()
    runs = []
    for _ in range(2):
        tracker = Tracker(frames[0], truth0)
        runs.append([tracker.update(f).contours for f in frames[1:]])
    for a, b in zip(*runs):
        for name in a:
            np.testing.assert_array_equal(a[name], b[name])


def test_the_head_motion_carries_the_nose_with_the_face(shared):
    frames, lm, iod = gray_frames(shared, "lp_d0", 60)
    head = HeadMotion(frames[0], from_face_mesh(lm[0]))
    for t in range(1, len(frames)):
        _, ok, _ = head.update(frames[t], head.brow_points(from_face_mesh(lm[t - 1])))
        assert ok
        moved = apply(head.total, lm[0][NOSE_BRIDGE, :2])
        assert np.abs(moved - lm[t][NOSE_BRIDGE, :2]).max() < 0.03 * iod[t], t


def test_rgb_frames_are_followed_as_their_opencv_grey_levels(shared):
    # The core converts the part of an RGB frame the flow reads itself; the head's track is
    # the one OpenCV's RGB2GRAY frames give, bit for bit (lp_d12 turns its head: new corners
    # are found in RGB frames too).
    with VideoReader(shared / "video" / "lp_d12.mp4") as reader:
        frames = list(itertools.islice(reader, 30))
    lm = np.load(shared / "video" / "lp_d12.landmarks.npz")["landmarks"]
    rgb = HeadMotion(frames[0], from_face_mesh(lm[0]))
    grey = HeadMotion(cv2.cvtColor(frames[0], cv2.COLOR_RGB2GRAY), from_face_mesh(lm[0]))
    for t in range(1, len(frames)):
        brows = rgb.brow_points(from_face_mesh(lm[t - 1]))
        a = rgb.update(frames[t], brows, extra=lm[t - 1][:, :2])
        b = grey.update(cv2.cvtColor(frames[t], cv2.COLOR_RGB2GRAY), brows, extra=lm[t - 1][:, :2])
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[2], b[2])
        np.testing.assert_array_equal(rgb.points, grey.points)
        np.testing.assert_array_equal(rgb.ids, grey.ids)


def test_points_keep_their_identity_while_followed_and_new_ones_get_new_ones(shared):
    # lp_d12 turns its head: points fail the similarity fit and new ones are found often.
    frames, lm, _ = gray_frames(shared, "lp_d12", 40)
    head = HeadMotion(frames[0], from_face_mesh(lm[0]))
    found_again = 0
    for t in range(1, len(frames)):
        before = set(head.ids.tolist())
        _, _, moved = head.update(
            frames[t], head.brow_points(from_face_mesh(lm[t - 1])), extra=lm[t - 1][NOSE_BRIDGE, :2]
        )
        followed = head.followed[1].tolist()
        assert set(followed) <= before
        assert moved.shape == (len(NOSE_BRIDGE), 2)
        if head.ids.tolist() != followed:
            found_again += 1
            assert head.ids.min() > max(before)
        assert head.points.dtype == np.float32 and len(head.points) == len(head.ids)
    assert found_again > 0


@pytest.mark.parametrize("blur", [6.0, 10.0])
def test_a_jump_too_blurred_for_the_flow_is_measured_by_the_coarse_search(shared, blur):
    frames, lm, _ = gray_frames(shared, "lp_d0", 1)
    head = HeadMotion(frames[0], from_face_mesh(lm[0]))
    first = head.ids.copy()
    jumped = cv2.GaussianBlur(np.roll(frames[0], 12, axis=1), (0, 0), blur)
    step, ok, moved = head.update(jumped, head.brow_points(from_face_mesh(lm[0])))
    assert ok and moved is None
    # The search runs at a quarter of the size: within 4 px of the 12 px jump.
    assert abs(step[0, 2] - 12.0) <= 4.0 and abs(step[1, 2]) <= 4.0
    np.testing.assert_array_equal(step[:, :2], np.eye(2))
    # The flow followed no point; new ones were found, with new identities.
    assert len(head.followed[0]) == 0
    assert len(head.ids) > 0 and head.ids.min() > first.max()


def test_the_corners_found_in_the_rigid_zones_are_opencvs(shared):
    # Through lp_d12's head turn, where new corners are found often: the core's corner
    # detector picks the same corners, in the same order, as OpenCV's goodFeaturesToTrack.
    frames, lm, _ = gray_frames(shared, "lp_d12", 40)
    head = HeadMotion(frames[0], from_face_mesh(lm[0]))
    for t in range(1, len(frames)):
        head.update(frames[t], head.brow_points(from_face_mesh(lm[t - 1])))
        zones = head._head.zones
        x0, y0, x1, y1 = head._zones_box(zones, frames[t].shape, DETECT_MARGIN)
        mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
        for poly in zones:
            cv2.fillConvexPoly(mask, np.round(poly - [x0, y0]).astype(np.int32), 255)
        theirs = cv2.goodFeaturesToTrack(
            frames[t][y0:y1, x0:x1],
            head._max_points,
            QUALITY,
            head._min_distance,
            mask=mask,
            blockSize=CORNER_BLOCK,
        )
        ours = head._detect(zones)
        assert ours.dtype == np.float32 and len(ours) > 20
        np.testing.assert_array_equal(ours, theirs.reshape(-1, 2) + [x0, y0])
