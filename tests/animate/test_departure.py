"""How far a real frame departs from its synthesis around the face: nothing for the same picture
or a few pixels of misplacement, about its area for something that is not there, and the frames a
hand passes in front of the face found when a video is run."""

import cv2
import numpy as np
import pytest

from facemime.animate.departure import DEPARTS_AT, FACE_GROWTH, departure
from facemime.app.run import SideBySide
from facemime.io.video import VideoReader

SIZE = (320, 240)


def face_outline(centre=(160, 110), axes=(40, 52), n=18):
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([centre[0] + axes[0] * np.cos(t), centre[1] + axes[1] * np.sin(t)])


def texture(sigma, seed=3):
    """A grey picture of SIZE with patches about ``sigma`` pixels across and luma spread over most
    of 0..255 (hair, clothes, a room)."""
    w, h = SIZE
    n = cv2.GaussianBlur(np.random.default_rng(seed).normal(size=(h, w)).astype(np.float32), (0, 0), sigma)
    g = np.clip(128 + 110 * (n - n.mean()) / n.std(), 0, 255).astype(np.uint8)
    return np.dstack([g, g, g])


def surround_area(outline):
    """Pixels outside the face's outline grown as the measure grows it."""
    centre = outline.mean(axis=0)
    grown = centre + (1.0 + 2.0 * FACE_GROWTH) * (outline - centre)
    face = np.zeros(SIZE[::-1], np.uint8)
    cv2.fillConvexPoly(face, np.round(cv2.convexHull(grown.astype(np.float32))).astype(np.int32), 1)
    return SIZE[0] * SIZE[1] - int(face.sum())


@pytest.mark.parametrize("sigma", [3, 8])
def test_a_frame_does_not_depart_from_itself(sigma):
    key = texture(sigma)
    assert departure(key, key, face_outline()) == 0.0


@pytest.mark.parametrize(("box", "luma"), [((8, 8, 60, 80), 250), ((240, 140, 64, 64), 5), ((0, 150, 100, 90), 250)])
def test_a_blob_that_is_not_in_the_synthesis_departs_by_its_area(box, luma):
    key = texture(8)
    key[:] = np.clip(key.astype(int) // 2 + 64, 0, 255).astype(np.uint8)  # lumas 64..191: the blob stands out
    outline = face_outline()
    x, y, w, h = box
    real = key.copy()
    real[y : y + h, x : x + w] = luma
    share = departure(real, key, outline)
    area = w * h / surround_area(outline)
    assert share == pytest.approx(area, rel=0.15)
    assert departure(real, real, outline) == 0.0


def test_something_over_the_face_departs_by_its_share_of_the_face():
    key = texture(8)
    outline = face_outline()
    real = key.copy()
    real[90:130, 140:180] = 255  # inside the face's core (a hull about 68 x 88 px)
    share = departure(real, key, outline)
    assert DEPARTS_AT < share < 0.3
    real[90:130, 140:180] = key[90:130, 140:180]
    assert departure(real, key, outline) == 0.0


def test_texture_misplaced_by_a_few_pixels_is_forgiven_a_different_picture_is_not():
    key = texture(8)
    outline = face_outline()
    for d in (1, 2):
        assert departure(np.roll(key, (d, -d), axis=(0, 1)), key, outline) < DEPARTS_AT / 4
        assert departure(np.roll(key, (-d, 0), axis=(0, 1)), key, outline) < DEPARTS_AT / 4
    assert departure(np.roll(key, (16, -16), axis=(0, 1)), key, outline) > 2 * DEPARTS_AT


# The honest limit: a hand passing in front of the face cannot be synthesised from one key frame.
# A short clip of a shared video with a hand composited in: it enters from the picture's bottom
# edge at CLEAR, rises over the face for RISE frames and is held there HOLD frames.
FRAMES, CLEAR, RISE, HOLD = 50, 15, 15, 8
HAND = range(CLEAR, CLEAR + RISE + HOLD)


def skin(frame, landmarks):
    """The face's own skin colour: the median of both cheeks (Face Mesh points 50 and 280)."""
    patches = [
        frame[int(y) - 6 : int(y) + 6, int(x) - 6 : int(x) + 6].reshape(-1, 3) for x, y in landmarks[[50, 280], :2]
    ]
    return tuple(int(v) for v in np.median(np.concatenate(patches), axis=0))


def paste_hand(frame, k, colour):
    """A hand ``k`` frames after it entered: a palm (a third of the picture wide, two fifths high)
    rising from below the picture to the face, its forearm reaching out of the bottom-right."""
    h, w = frame.shape[:2]
    t = min(k / (RISE - 1), 1.0)
    cx, cy = int(0.55 * w), int(h * (1.15 - 0.55 * t))
    cv2.line(frame, (cx, cy), (int(0.9 * w), int(1.1 * h)), colour, int(0.22 * w))
    cv2.ellipse(frame, (cx, cy), (int(0.16 * w), int(0.2 * h)), 0, 0, 360, colour, -1)


@pytest.fixture(scope="module", params=["lp_d0", "vr_2"])
def hand_run(request, shared):
    """The clip of ``request.param`` with the hand, run on its own face in its own scene: the
    per-frame records and the reported ranges."""
    name = request.param
    frames = [f.copy() for _, f in zip(range(FRAMES), VideoReader(shared / "video" / f"{name}.mp4"))]
    colour = skin(frames[0], np.load(shared / "video" / f"{name}.landmarks.npz")["landmarks"][0])
    for i in HAND:
        paste_hand(frames[i], i - CLEAR, colour)
    work = SideBySide(frames, name)
    for _ in work:
        pass
    return name, work.records, work.departs


def test_only_frames_with_the_hand_are_reported_and_the_ranges_say_which(hand_run):
    _, records, departs = hand_run
    assert len(records) == FRAMES and all(r["face"] for r in records)
    share = np.array([r["scene_departure"] for r in records])
    flagged = np.array([r["scene_departs"] for r in records])
    assert np.array_equal(flagged, share > DEPARTS_AT)
    clear = np.ones(FRAMES, bool)
    clear[list(HAND)] = False
    assert not flagged[clear].any() and share[clear].max() < 0.75 * DEPARTS_AT
    # the measure sees the hand, more as more of it shows
    assert share[list(HAND)[RISE:]].min() > 2 * share[clear].max()
    assert share[CLEAR + RISE - 1] > 2 * share[CLEAR + 1]
    ranges = []
    for i in np.flatnonzero(flagged).tolist():
        if ranges and ranges[-1][1] == i - 1:
            ranges[-1][1] = i
        else:
            ranges.append([i, i])
    assert departs == ranges


def test_a_hand_passing_in_front_of_the_face_is_reported(hand_run):
    name, records, _ = hand_run
    flagged = [r["scene_departs"] for r in records]
    hand = [flagged[i] for i in HAND]
    assert sum(hand) > len(hand) / 2, f"{name}: {sum(hand)} of {len(hand)} frames with the hand reported"
    assert all(hand[RISE:]), f"{name}: the hand held over the face is not reported in every frame"
