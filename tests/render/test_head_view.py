import cv2
import numpy as np
import pytest

from facemime.head import generic_head
from facemime.io.wfm import load_wfm
from facemime.render.head_view import LIGHT, draw_wireframe, render_shaded, views_sheet
from facemime.types.pose import Pose, project, rotation_matrix


def shaded_one_by_one(model, pose, size, colour=(205, 180, 160), background=255):
    """The former render_shaded: one anti-aliased cv2 polygon per front face, far to near."""
    v, t = model.vertices, model.triangles
    points, depth = project(v, pose)
    img = np.full((size[1], size[0], 3), background, np.uint8)
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    view_normals = normals @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T
    light = 0.25 + 0.75 * np.clip(view_normals @ LIGHT, 0, 1)
    for f in np.argsort(depth[t].mean(axis=1)):
        if view_normals[f, 2] > 0:
            poly = np.round(points[t[f]] * 16).astype(np.int32)
            cv2.fillConvexPoly(img, poly, tuple(float(light[f] * ch) for ch in colour), cv2.LINE_AA, 4)
    return img


def wireframe_one_by_one(image, points, triangles, colour):
    """The former draw_wireframe: one cv2.line per distinct edge."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    for i, j in np.unique(edges, axis=0):
        p, q = (np.round(points[[i, j]] * 16).astype(int)).tolist()
        cv2.line(image, tuple(p), tuple(q), colour, 1, cv2.LINE_AA, 4)
    return image


@pytest.fixture(params=["generic", "candide"])
def model(request):
    return generic_head() if request.param == "generic" else load_wfm(request.getfixturevalue("candide_path"))


@pytest.mark.parametrize("yaw", [-60, 0, 35])
def test_shading_matches_the_one_by_one_polygons_away_from_edges(model, yaw):
    pose = Pose.framing(model.vertices, (320, 300), 0.88, yaw=yaw, pitch=10)
    new = render_shaded(model, pose, (320, 300)).astype(int)
    old = shaded_one_by_one(model, pose, (320, 300)).astype(int)
    assert new.shape == (300, 320, 3)
    # Face colours are the same; only the anti-aliased fringe (1 px beyond an anti-aliased edge) differs.
    edges = wireframe_one_by_one(np.zeros((300, 320), np.uint8), project(model.vertices, pose)[0], model.triangles, 255)
    fringe = cv2.dilate(edges, np.ones((3, 3), np.uint8)) > 0
    differ = np.abs(new - old).max(axis=2) > 0
    assert not (differ & ~fringe).any()
    assert differ.mean() < 0.12 and np.abs(new - old).mean() < 3
    assert ((new != 255).any(axis=2) & ~fringe).sum() > 5000  # many head pixels are compared


def test_wireframe_is_the_same_as_one_line_per_edge(model):
    pose = Pose.framing(model.vertices, (300, 300), 0.9, yaw=25)
    points = project(model.vertices, pose)[0]
    background = np.full((300, 300, 3), 200, np.uint8)
    new = draw_wireframe(background.copy(), points, model.triangles, (30, 110, 40))
    old = wireframe_one_by_one(background.copy(), points, model.triangles, (30, 110, 40))
    np.testing.assert_array_equal(new, old)


def test_views_sheet_layout():
    sheet = views_sheet(generic_head(), None, cell=100, yaws=(-30, 0, 30))
    assert sheet.shape == (100, 300, 3) and sheet.dtype == np.uint8
