import numpy as np
import pytest

from facemime.animate.deform import Deformer
from facemime.errors import InvalidInputError
from facemime.head import generic_head
from facemime.io.wfm import load_wfm
from facemime.types.pose import Pose, head_plane, project


def test_head_plane_undoes_the_projection_at_known_depth():
    head = generic_head()
    pose = Pose(yaw=-20, pitch=8, roll=-6, scale=1.7, tx=300, ty=210)
    pts = project(head.vertices, pose)[0]
    assert np.allclose(head_plane(pts, head.vertices[:, 2], pose), head.vertices[:, :2])


def test_first_frame_contours_give_zero_offsets_and_the_rest_shape():
    head = generic_head()
    d = Deformer(head)
    pose = Pose(roll=4, scale=2.0, tx=250, ty=240)
    pts = project(head.vertices, pose)[0]
    contours = {n: pts[head.groups[n]] for n in d.model.groups if n.startswith(("mouth", "brow"))}
    assert np.allclose(d.knot_positions(contours, pose), head.vertices[d.knots, :2])
    assert np.array_equal(d.vertices(np.zeros((len(d.knots), 2))), head.vertices)


def test_an_opening_mouth_pulls_the_chin_down_and_leaves_eyes_and_nose_still():
    head = generic_head()
    d = Deformer(head)
    g = head.groups
    offsets = np.zeros((len(d.knots), 2))
    lower = np.isin(d.knots, np.concatenate([g["mouth_outer_lower"][1:-1], g["mouth_inner_lower"][1:-1]]))
    offsets[lower, 1] = -10.0  # mm, down
    moved = d.vertices(offsets) - head.vertices
    chin = g["face_outline"][9]
    assert -10.0 < moved[chin, 1] < -3.0
    for still in ("eye_left", "eye_right", "nose"):
        assert np.abs(moved[g[still]]).max() == 0.0
    assert np.abs(moved[g["brow_left_upper"]]).max() == 0.0
    assert (moved[:, 1] <= 1e-12).all()  # nothing moves up
    assert np.allclose(d.vertices(offsets, gain=2.0) - head.vertices, 2 * moved)


def test_raised_brows_lift_the_forehead_but_not_the_mouth():
    head = generic_head()
    d = Deformer(head)
    offsets = np.zeros((len(d.knots), 2))
    offsets[np.isin(d.knots, np.concatenate([head.groups[n] for n in head.groups if n.startswith("brow")])), 1] = 6.0
    moved = d.vertices(offsets) - head.vertices
    forehead = head.vertices[:, 1] > 30
    assert (moved[forehead, 1] > 0.5).all()
    assert np.abs(moved[head.vertices[:, 1] < -20]).max() == 0.0


def test_a_model_without_contour_groups_is_refused(candide_path):
    with pytest.raises(InvalidInputError, match="lacks the contour groups"):
        Deformer(load_wfm(candide_path))
