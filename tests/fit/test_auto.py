"""Automatic reference points: on a synthetic render with known truth, on the shared videos and
on a photo without a face."""

import numpy as np
import pytest

from facemime.errors import NoFaceError
from facemime.fit import auto_points
from facemime.io.video import VideoReader
from facemime.metrics import curve_error
from facemime.render.head_view import render_head
from facemime.types.points import GROUPS
from facemime.types.pose import Pose, project

CORNERS = {
    "eye_right_outer": ("eye_right", 0),
    "eye_right_inner": ("eye_right", 4),
    "eye_left_inner": ("eye_left", 0),
    "eye_left_outer": ("eye_left", 4),
}


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
        errors = [
            np.linalg.norm(found[n][0] - ref[n][0]) if group == "eye_corners" else curve_error(found[n], ref[n])
            for n in names
        ]
        assert np.mean(errors) / iod < 0.05, (group, np.mean(errors) / iod)


def test_no_face_is_an_error():
    rng = np.random.default_rng(1)
    with pytest.raises(NoFaceError, match="no face found"):
        auto_points(rng.integers(90, 110, (240, 320, 3), dtype=np.uint8))
