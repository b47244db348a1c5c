"""The scene mesh: the key frame as a 2-D mesh that covers the picture once, is wound like the
face mesh, keeps its border on the picture's edges, and warps the key frame as the face moves."""

import cv2
import numpy as np
import pytest

from facemime.errors import InvalidInputError
from facemime.render.raster import coverage
from facemime.render.scene import SceneMesh
from facemime.shared_constants import BORDER_STEPS, EDGE_MARGIN, RINGS

#: (picture size, centre of the face outline, its half-axes): a landscape picture with the face in
#: the middle, a tall portrait, a face near the left edge, one near the top of a larger picture.
PLACEMENTS = {
    "landscape": ((320, 240), (160, 120), (40, 55)),
    "portrait": ((200, 360), (100, 150), (35, 45)),
    "near-left-edge": ((320, 240), (45, 120), (30, 40)),
    "near-top": ((640, 480), (330, 75), (50, 62)),
}
#: Placements whose first ring lies wholly inside the picture.
WHOLE = ["landscape", "portrait"]


def ellipse(centre, axes, n=18):
    """A face outline: ``n`` points on an ellipse, (n, 2) pixels."""
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([centre[0] + axes[0] * np.cos(t), centre[1] + axes[1] * np.sin(t)])


def mesh_of(name):
    size, centre, axes = PLACEMENTS[name]
    outline = ellipse(centre, axes)
    return SceneMesh.build(size, np.arange(100, 100 + len(outline)), outline), outline


def plane(x, y):
    """A smooth textured plane, RGB float in 38..218, known at any (x, y): the key frame's truth."""
    return np.stack(
        [
            128 + 50 * np.sin(x / 9.0) + 40 * np.cos(y / 11.0),
            128 + 60 * np.sin((x + y) / 13.0),
            128 + 45 * np.cos(x / 7.0 - y / 10.0),
        ],
        axis=-1,
    )


#: The plane's steepest slope, grey levels per pixel (its third channel's).
PLANE_SLOPE = 45 * np.hypot(1 / 7.0, 1 / 10.0)


def key_frame(size):
    w, h = size
    y, x = np.mgrid[0:h, 0:w].astype(float)
    return np.round(plane(x, y)).astype(np.uint8)


def polygon_mask(points, size):
    """Pixels whose centres lie inside the convex hull of ``points`` ((N, 2) pixels)."""
    mask = np.zeros(size[::-1], np.uint8)
    hull = cv2.convexHull(np.round(np.asarray(points) * 16).astype(np.int32))
    cv2.fillConvexPoly(mask, hull, 1, cv2.LINE_8, 4)
    return mask.astype(bool)


def check_topology(mesh):
    """The invariants every scene mesh keeps, whatever the picture and the face."""
    w, h = mesh.size
    p, tris = mesh.rest, mesh.triangles
    a, b, c = (p[tris[:, k]] for k in range(3))
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (cross < 0).all(), "a triangle is not wound counter-clockwise in the image"
    # shared edges count once (the rasteriser's fill rule): at rest the picture is covered once
    cov = coverage(p, tris, mesh.size)
    assert cov.min() == 1, f"{int((cov == 0).sum())} pixels in holes"
    assert cov.max() == 1, f"{int((cov > 1).sum())} pixels covered twice"
    assert len(np.unique(tris)) == len(p), "a vertex in no triangle"
    # the border: the last vertices, still, on the picture's outer pixel edges, corners included
    n = 4 * (BORDER_STEPS - 1)
    border = np.zeros(len(p), bool)
    border[-n:] = True
    assert (mesh.follow[border] == 0).all()
    edge_x, edge_y = np.isin(p[border, 0], [-0.5, w - 0.5]), np.isin(p[border, 1], [-0.5, h - 0.5])
    assert (edge_x | edge_y).all()
    assert ((p[border] >= -0.5) & (p[border] <= [w - 0.5, h - 0.5])).all()
    corners = {(-0.5, -0.5), (w - 0.5, -0.5), (w - 0.5, h - 0.5), (-0.5, h - 0.5)}
    assert corners <= set(map(tuple, p[border].tolist()))
    for x in (-0.5, w - 0.5):
        assert (p[border, 0] == x).sum() == BORDER_STEPS
    for y in (-0.5, h - 0.5):
        assert (p[border, 1] == y).sum() == BORDER_STEPS
    # rings: inside the picture, kept EDGE_MARGIN of its shorter side away from its edges
    rings = p[len(mesh.anchors) : -n]
    margin = EDGE_MARGIN * min(w, h)
    assert ((rings > -0.5 + margin) & (rings < [w - 0.5 - margin, h - 0.5 - margin])).all()
    assert set(mesh.follow[len(mesh.anchors) : -n]) <= {share for _, share in RINGS}
    assert (mesh.follow[: len(mesh.anchors)] == 1).all()


@pytest.mark.parametrize("name", list(PLACEMENTS))
def test_the_mesh_covers_the_picture_once_wound_like_the_face(name):
    mesh, outline = mesh_of(name)
    check_topology(mesh)
    np.testing.assert_array_equal(mesh.rest[: len(outline)], outline)
    np.testing.assert_array_equal(mesh.anchors, np.arange(100, 118))
    # every ring vertex that fits is there: all around a face in the middle, fewer near an edge
    rings = len(mesh.rest) - len(outline) - 4 * (BORDER_STEPS - 1)
    first = (mesh.follow[len(outline) :] == 1).sum()
    if name in WHOLE:
        assert first == len(outline) and rings == len(RINGS) * len(outline)
    else:
        assert first < len(outline) and rings < len(RINGS) * len(outline)


def test_the_mesh_of_a_fitted_actor_covers_its_picture_once(actor):
    from facemime.animate.synth import scene_mesh

    mesh = scene_mesh(actor)
    assert mesh.size == (actor.source["width"], actor.source["height"])
    np.testing.assert_array_equal(mesh.anchors, actor.model.groups["face_outline"])
    check_topology(mesh)


@pytest.mark.parametrize("name", list(PLACEMENTS))
def test_the_rest_outline_leaves_the_mesh_at_rest_and_a_shift_moves_the_face_and_first_ring(name):
    mesh, outline = mesh_of(name)
    w, h = mesh.size
    a, n = len(outline), 4 * (BORDER_STEPS - 1)
    np.testing.assert_allclose(mesh.points(outline), mesh.rest, rtol=0, atol=1e-9)
    d = np.array([3.5, -2.25])
    moved = mesh.points(outline + d)
    np.testing.assert_array_equal(moved[:a], outline + d)
    shift = moved - mesh.rest
    np.testing.assert_allclose(shift[:-n], mesh.follow[:-n, None] * d, rtol=0, atol=1e-9)  # rings by their share
    np.testing.assert_allclose(shift[mesh.follow == 1], np.broadcast_to(d, shift[mesh.follow == 1].shape), atol=1e-9)
    np.testing.assert_array_equal(moved[-n:], mesh.rest[-n:])
    assert ((moved >= -0.5) & (moved <= [w - 0.5, h - 0.5])).all()


def test_rings_pushed_past_the_edge_stay_in_the_picture():
    mesh, outline = mesh_of("near-left-edge")
    w, h = mesh.size
    moved = mesh.points(outline + [-14.0, 30.0])  # the outline stays inside, its first ring would not
    assert ((moved >= -0.5) & (moved <= [w - 0.5, h - 0.5])).all()
    assert (moved[:, 0] == -0.5).sum() > BORDER_STEPS  # rings clamped onto the left edge


#: Small faces whose rings all fit in the picture: (size, centre, half-axes, shift of the face).
SHIFTED = {
    "landscape": ((320, 240), (160, 120), (25, 32), (3.4, -2.3)),
    "portrait": ((200, 360), (100, 180), (22, 30), (-2.6, 4.2)),
}


@pytest.mark.parametrize("name", list(SHIFTED))
def test_a_shifted_face_moves_its_surround_and_leaves_the_border(name):
    size, centre, axes, d = SHIFTED[name]
    w, h = size
    outline = ellipse(centre, axes)
    mesh = SceneMesh.build(size, np.arange(len(outline)), outline)
    outermost = np.zeros(len(mesh.rest), bool)
    outermost[len(RINGS) * len(outline) : (len(RINGS) + 1) * len(outline)] = True
    assert (mesh.follow[outermost] == RINGS[-1][1]).all()
    key = key_frame(size)
    out = np.full_like(key, 255)
    mesh.draw(out, key, outline + d)
    y, x = np.mgrid[0:h, 0:w].astype(float)
    # inside the first ring (less a margin for its edges) the picture is the key frame shifted
    inner = polygon_mask(np.array(centre) + 0.95 * RINGS[0][0] * (outline - centre) + d, size)
    assert inner.sum() > 2000
    err = np.abs(out - plane(x - d[0], y - d[1]))[inner]
    assert err.max() <= 1.6, f"the face's surround is not the shifted key frame (error {err.max():.1f})"
    # outside the outermost ring every pixel moves at most as far as that ring (its share of the
    # shift), and is sampled at most half a pixel off (nearest): the plane's slope bounds the change
    outer = ~polygon_mask(np.concatenate([mesh.rest[outermost], mesh.points(outline + d)[outermost]]), size)
    assert outer.sum() > 0.3 * w * h
    bound = PLANE_SLOPE * (RINGS[-1][1] * np.hypot(*d) + np.sqrt(0.5)) + 1
    assert np.abs(out.astype(int) - key)[outer].max() <= bound
    # triangles between border vertices only (the corners) show the key frame as it is, and the
    # picture's edges do not move
    still = coverage(mesh.rest, mesh.triangles[(mesh.follow[mesh.triangles] == 0).all(axis=1)], size) > 0
    assert still.sum() > 500
    np.testing.assert_array_equal(out[still], key[still])
    edges = np.zeros((h, w), bool)
    edges[[0, -1]] = edges[:, [0, -1]] = True
    assert np.abs(out.astype(int) - key)[edges].max() <= 2


@pytest.mark.parametrize("name", list(PLACEMENTS))
def test_draw_writes_every_pixel(name):
    mesh, outline = mesh_of(name)
    key = key_frame(mesh.size)  # no pixel of it is (255, 255, 255)
    centre = outline.mean(axis=0)
    turn = np.radians(12.0)
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    for now in (outline, outline + [0.4, -0.3], outline + [6.0, 9.0], centre + 1.2 * (outline - centre) @ rot.T):
        out = np.full_like(key, 255)
        mesh.draw(out, key, now)
        assert not (out == 255).all(axis=2).any()
    out = np.full_like(key, 255)
    mesh.draw(out, key, outline)
    np.testing.assert_array_equal(out, key)  # at rest, the key frame exactly


def test_bad_input_is_refused():
    size, centre, axes = PLACEMENTS["landscape"]
    outline = ellipse(centre, axes)
    with pytest.raises(InvalidInputError, match="at least three finite points"):
        SceneMesh.build(size, np.arange(2), outline[:2])
    bad = outline.copy()
    bad[3, 0] = np.nan
    with pytest.raises(InvalidInputError, match="at least three finite points"):
        SceneMesh.build(size, np.arange(18), bad)
    mesh = SceneMesh.build(size, np.arange(18), outline)
    with pytest.raises(InvalidInputError, match="the key frame is 300x240, the picture 320x240"):
        mesh.draw(np.zeros((240, 320, 3), np.uint8), np.zeros((240, 300, 3), np.uint8), outline)


@pytest.mark.parametrize(
    "centre, axes", [((100, 230), (40, 60)), ((-10, 100), (40, 60)), ((100, 120), (150, 190)), ((100, 120), (0, 0))]
)
def test_a_face_cut_by_the_picture_edge_or_degenerate_still_makes_a_whole_picture(centre, axes):
    """A face whose outline reaches past the picture (a chin below its bottom edge, a face half
    out, a face larger than the picture) or collapses to a point still gives a mesh that covers
    the picture once and a drawing that writes every pixel."""
    size = (200, 240)
    outline = ellipse(centre, axes)
    mesh = SceneMesh.build(size, np.arange(len(outline)), outline)
    assert coverage(mesh.rest, mesh.triangles, size).min() == 1
    key = key_frame(size)
    out = np.full_like(key, 255)
    mesh.draw(out, key, outline + [3.0, -2.0])
    assert not (out == 255).all(axis=2).any()
