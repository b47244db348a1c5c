"""Automatic reference points: on a synthetic render with known truth, on the shared videos and
on a photo without a face; the mouth's corners stretched to the ends of the lips."""

import cv2
import numpy as np
import pytest

from facemime.fit import NoFaceError, auto_points
from facemime.fit.auto import stretch_to_lips
from facemime.fit.points import GROUPS
from facemime.io.video import VideoReader
from facemime.metrics import curve_error
from facemime.render.head_view import render_head
from facemime.render.projection import Pose, project

CORNERS = {"eye_right_outer": ("eye_right", 0), "eye_right_inner": ("eye_right", 4),
           "eye_left_inner": ("eye_left", 0), "eye_left_outer": ("eye_left", 4)}


@pytest.mark.parametrize(("roll", "zoom"), [(0.0, 1.0), (6.0, 0.8), (-8.0, 1.2)])
def test_points_on_a_rendered_head_land_on_its_projected_vertices(actor, roll, zoom):
    # The real-textured head rendered at a known pose: truth is its projected vertices.
    pose = Pose(roll=roll, scale=actor.pose.scale * zoom, tx=240, ty=220)
    image = render_head(actor.model, actor.texture, pose, (480, 480), background=(120, 130, 140))
    truth = project(actor.model.vertices, pose)[0]
    g = actor.model.groups
    found = auto_points(image).points
    eyes = [np.linalg.norm(found[n][0] - truth[g[e][k]]) for n, (e, k) in CORNERS.items()]
    brows = [curve_error(found[n], truth[g[n]]) for n in GROUPS["brows"]]
    mouth = [curve_error(found[n], truth[g[n]]) for n in GROUPS["mouth"]]
    assert max(eyes) < 7.0 and np.mean(eyes) < 5.0, eyes  # pixels; IOD is 111-166 px here
    assert max(brows) < 4.0, brows
    assert max(mouth) < 3.0, mouth


@pytest.mark.parametrize("video", ["lp_d3", "vr_1"])
def test_points_on_real_first_frames_are_within_target(shared, points_of, video):
    frame = next(iter(VideoReader(shared / "video" / f"{video}.mp4")))
    z = np.load(shared / "video" / f"{video}.landmarks.npz")
    ref, iod = points_of(z["landmarks"][0]), float(z["iod"][0])
    found = auto_points(frame).points
    for group, names in GROUPS.items():
        errors = [np.linalg.norm(found[n][0] - ref[n][0]) if group == "eye_corners" else curve_error(found[n], ref[n])
                  for n in names]
        assert np.mean(errors) / iod < 0.05, (group, np.mean(errors) / iod)


def test_lp_d3s_mouth_corners_end_where_her_lips_do(shared, points_of):
    # Placed as a whole and settled by the snakes, her right corner stayed 0.073 IOD out on the
    # cheek, where the tracker later lost the mouth onto the jaw as her head turned.
    frame = next(iter(VideoReader(shared / "video" / "lp_d3.mp4")))
    z = np.load(shared / "video" / "lp_d3.landmarks.npz")
    ref, iod = points_of(z["landmarks"][0]), float(z["iod"][0])
    corners = auto_points(frame).points["mouth_outer_upper"][[0, -1]]
    errors = np.linalg.norm(corners - ref["mouth_outer_upper"][[0, -1]], axis=1) / iod
    assert errors.max() < 0.03, errors


def _lips_photo(lip_colour: tuple[int, int, int]) -> np.ndarray:
    """Skin with lips: an ellipse centred at (100, 60) px, half-axes 30 × 10 px."""
    image = np.full((120, 200, 3), (205, 160, 140), np.uint8)
    cv2.ellipse(image, (100, 60), (30, 10), 0, 0, 360, lip_colour, -1)
    return image


def _mouth(left: float, right: float) -> dict[str, np.ndarray]:
    """Mouth curves from x = ``left`` to ``right`` px: the outer ones 10 px above and below
    y = 60 at the middle, the inner ones closed on y = 60."""
    x = np.linspace(left, right, 11)
    bulge = 10.0 * np.sin(np.linspace(0.0, np.pi, 11))
    line = np.stack([x, np.full(11, 60.0)], axis=1)
    return {"mouth_outer_upper": line - np.c_[np.zeros(11), bulge], "mouth_outer_lower": line + np.c_[np.zeros(11), bulge],
            "mouth_inner_upper": line.copy(), "mouth_inner_lower": line.copy()}


def test_a_mouth_placed_too_wide_is_stretched_to_its_lips():
    photo = _lips_photo((170, 70, 90))
    mouth = _mouth(70.0, 136.0)  # the lips end at x = 130
    moved = stretch_to_lips(photo, mouth, iod=100.0)
    for name, curve in moved.items():
        assert abs(curve[0, 0] - 70.0) < 1.5 and abs(curve[-1, 0] - 130.0) < 1.5, (name, curve[[0, -1]])
        np.testing.assert_allclose(curve[:, 1], mouth[name][:, 1])  # along the mouth's line only
    # The left half, already at its end of the lips, keeps its shape.
    np.testing.assert_allclose(moved["mouth_outer_upper"][:5], mouth["mouth_outer_upper"][:5], atol=1.5)


def test_corners_stay_where_the_lips_cannot_be_told_from_the_skin_or_lie_too_far():
    mouth = _mouth(70.0, 140.0)
    grey = _lips_photo((205, 160, 140))  # lips the colour of the skin
    for name, curve in stretch_to_lips(grey, mouth, iod=100.0).items():
        np.testing.assert_array_equal(curve, mouth[name])
    far = _mouth(70.0, 180.0)  # the right half would shrink by 45%: not these lips' end
    moved = stretch_to_lips(_lips_photo((170, 70, 90)), far, iod=100.0)
    assert moved["mouth_outer_upper"][-1, 0] == 180.0


def test_no_face_is_an_error():
    rng = np.random.default_rng(1)
    with pytest.raises(NoFaceError, match="no face found"):
        auto_points(rng.integers(90, 110, (240, 320, 3), dtype=np.uint8))
