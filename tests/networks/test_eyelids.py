"""The eye model's lids on real eyes, against the shared references (MediaPipe Face Mesh with
its refined eyes: a different model, so a small disagreement is expected)."""

import numpy as np
import pytest

from facemime.io.video import VideoReader
from facemime.networks.eyelids import RIM, eye_crop, eye_openings, eye_rims

# The Face Mesh points of each eye's rim, in the order eye_rim gives them.
RIMS = (
    (33, 7, 163, 144, 145, 153, 154, 155, 133, 246, 161, 160, 159, 158, 157, 173),
    (263, 249, 390, 373, 374, 380, 381, 382, 362, 466, 388, 387, 386, 385, 384, 398),
)


def frames(path, wanted):
    with VideoReader(path) as reader:
        return {i: f for i, f in zip(range(max(wanted) + 1), reader) if i in wanted}


def test_a_crop_is_turned_along_the_eye_and_centred_between_its_corners():
    p = np.zeros((468, 2))
    p[362], p[263] = [100.0, 50.0], [130.0, 80.0]  # the left eye, tilted 45 degrees
    crop = eye_crop(p, 1)
    assert crop.angle == pytest.approx(np.pi / 4)
    np.testing.assert_allclose(crop.centre, [115.0, 65.0])
    assert crop.side == pytest.approx(2.3 * 30.0 * np.sqrt(2.0))


@pytest.mark.parametrize("name", ["lp_d3", "st_kh"])
def test_the_rims_of_both_eyes_lie_on_the_reference_lids(shared, name):
    """Both eyes, so that the left eye's mirrored crop is mapped back the right way round (a
    mirror left in swaps the corners: errors of an eye width)."""
    frame = frames(shared / "video" / f"{name}.mp4", {0})[0]
    landmarks = np.load(shared / "video" / f"{name}.landmarks.npz")["landmarks"][0]
    rims = eye_rims(frame, landmarks)
    assert rims.shape == (2, RIM, 2)
    np.testing.assert_allclose(eye_rims(frame, landmarks, [1])[0], rims[1], atol=1e-6)  # alone as in the batch
    for eye, rim in enumerate(rims):
        reference = landmarks[list(RIMS[eye]), :2]
        width = np.linalg.norm(reference[8] - reference[0])
        error = np.linalg.norm(rim - reference, axis=1) / width
        # measured: mean 0.030-0.039, largest 0.051-0.060 eye widths
        assert error.mean() < 0.06 and error.max() < 0.1


def test_shut_eyes_read_nearly_closed_and_eyes_looking_down_half_open(shared):
    """lp_d3: frame 0 open, 75 open and looking down (the upper lids follow the eyes down), 120
    shut. The quick measures read 75 as nearly as closed as 120; the eye model does not."""
    path = shared / "video" / "lp_d3.mp4"
    pictures = frames(path, {0, 75, 120})
    landmarks = np.load(shared / "video" / "lp_d3.landmarks.npz")["landmarks"]
    opening = {i: eye_openings(pictures[i], landmarks[i]) for i in pictures}
    # measured: 0.385 0.423 open, 0.269 0.279 looking down, 0.100 0.137 shut
    assert opening[0].min() > 0.3
    assert np.all(opening[75] / opening[0] > 0.55)
    assert np.all(opening[120] / opening[0] < 0.4)
