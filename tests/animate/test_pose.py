import numpy as np
import pytest

from facemime.animate.pose import fit_pose, lift, moved
from facemime.head import generic_head
from facemime.types.pose import Pose, project


@pytest.mark.parametrize(
    "pose", [Pose(scale=2, tx=200, ty=220), Pose(yaw=25, pitch=-10, roll=8, scale=1.5, tx=160, ty=170)]
)
def test_lift_puts_visible_vertices_back_where_they_were(pose):
    head = generic_head()
    pts, depth = project(head.vertices, pose)
    xyz, ok = lift(pts, head.vertices, head.triangles, pose)
    assert ok.all()
    # A vertex hidden behind the nose lifts onto the nose, never behind it.
    lifted_depth = project(xyz, pose)[1]
    assert (lifted_depth >= depth - 1e-6).all()
    visible = np.abs(lifted_depth - depth) < 1e-6
    assert visible.mean() > 0.8 and np.abs(xyz[visible] - head.vertices[visible]).max() < 1e-6


def test_lift_beside_the_mesh_uses_the_nearest_facet_plane():
    head = generic_head()
    pose = Pose(scale=2, tx=200, ty=260)
    top = head.vertices[np.argmax(head.vertices[:, 1])]
    above = project(top[None] + [0, 15, 0], pose)[0]
    xyz, ok = lift(above, head.vertices, head.triangles, pose)
    assert ok.all() and np.allclose(project(xyz, pose)[0], above) and abs(xyz[0, 2] - top[2]) < 20


def test_fit_pose_recovers_a_known_pose_from_noisy_points():
    head = generic_head()
    rng = np.random.default_rng(1)
    truth = Pose(yaw=18, pitch=-7, roll=5, scale=2.2, tx=260, ty=240)
    pts = project(head.vertices, truth)[0] + rng.normal(0, 0.4, (len(head.vertices), 2))
    pose = fit_pose(head.vertices, pts, Pose(scale=2.0, tx=250, ty=250), towards=(18, -7))
    assert abs(pose.yaw - 18) < 1 and abs(pose.pitch + 7) < 1 and abs(pose.roll - 5) < 0.3
    assert abs(pose.scale / 2.2 - 1) < 0.005 and abs(pose.tx - 260) < 0.5 and abs(pose.ty - 240) < 0.5
    assert np.median(np.hypot(*(project(head.vertices, pose)[0] - pts).T)) < 1.0  # px, the noise's scale
    # Outliers (points that moved with the face's expression) do not drag the pose.
    pts[:10] += 25
    pose = fit_pose(head.vertices, pts, Pose(scale=2.0, tx=250, ty=250), towards=(18, -7))
    assert abs(pose.roll - 5) < 0.5 and abs(pose.tx - 260) < 1.5


@pytest.mark.parametrize(
    ("turn", "zoom", "shift"), [(0.0, 1.0, (14.0, -9.0)), (-6.0, 1.04, (5.0, 3.0)), (4.0, 0.97, (0.0, 0.0))]
)
def test_a_pose_moved_by_an_image_step_projects_where_the_step_puts_its_projection(turn, zoom, shift):
    """A frame whose pose the rigid points could not measure moves it by the head's step in the
    image (turn in degrees, y down: clockwise as seen)."""
    head = generic_head()
    pose = Pose(yaw=15, pitch=-6, roll=7, scale=1.8, tx=230, ty=250)
    c, s = zoom * np.cos(np.radians(turn)), zoom * np.sin(np.radians(turn))
    step = np.array([[c, -s, shift[0]], [s, c, shift[1]]])
    before = project(head.vertices, pose)[0]
    after = project(head.vertices, moved(pose, step))[0]
    assert np.abs(after - (before @ step[:, :2].T + step[:, 2])).max() < 1e-9
    assert moved(pose, step).yaw == pose.yaw and moved(pose, step).pitch == pose.pitch
