import numpy as np
import pytest

from facemime.errors import InvalidInputError
from facemime.head import generic_head, painted_texture
from facemime.render import coverage, fill, render_mesh, render_mesh_into
from facemime.types.pose import Pose, project

RNG = np.random.default_rng(7)


def texel_to_uv(p, tex):
    """Texel pixel coordinates -> [0, 1] texture coordinates."""
    return (np.asarray(p, float) + 0.5) / [tex.shape[1], tex.shape[0]]


def exact_bilinear(tex, s):
    """Float bilinear lookup with edge clamping at (N, 2) texel positions."""
    x0, y0 = np.floor(s[:, 0]).astype(int), np.floor(s[:, 1]).astype(int)
    fx, fy = (s[:, 0] - x0)[:, None], (s[:, 1] - y0)[:, None]
    h, w = tex.shape[:2]

    def at(x, y):
        return tex[np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)].astype(float)

    return (
        (1 - fx) * (1 - fy) * at(x0, y0)
        + fx * (1 - fy) * at(x0 + 1, y0)
        + (1 - fx) * fy * at(x0, y0 + 1)
        + fx * fy * at(x0 + 1, y0 + 1)
    )


def grid_mesh(nx, ny, x0, y0, dx, dy):
    """Flat grid of (nx x ny) cells: points (pixels), uv and front-facing triangles."""
    gx, gy = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1))
    pts = np.column_stack([x0 + gx.ravel() * dx, y0 + gy.ravel() * dy])
    uv = np.column_stack([gx.ravel() / nx, gy.ravel() / ny])
    tris = []
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 2, a + nx + 1
            tris += [[a, d, c], [a, c, b]]  # counter-clockwise as seen on the image
    return pts, uv, np.array(tris)


def test_triangle_under_exact_affine_map_reproduces_texture_nearest():
    tex = RNG.integers(0, 256, (40, 40, 3), dtype=np.uint8)
    src = np.array([[3.0, 2.0], [35.0, 4.0], [6.0, 37.0]])
    # A quarter turn and an integer shift map texel centres onto pixel centres exactly.
    rot = np.array([[0.0, -1.0], [1.0, 0.0]])
    dst = src @ rot.T + [50, 4]
    img = render_mesh(tex, texel_to_uv(src, tex), dst, np.zeros(3), [[0, 1, 2]], (64, 64), filter="nearest", cull=False)
    ys, xs = np.nonzero(coverage(dst, [[0, 1, 2]], (64, 64)))
    s = (np.column_stack([xs, ys]) - [50, 4]) @ rot  # inverse map back to texels
    assert len(xs) > 400
    np.testing.assert_array_equal(img[ys, xs], tex[s[:, 1].astype(int), s[:, 0].astype(int)])


def test_bilinear_within_one_level_of_exact():
    tex = RNG.integers(0, 256, (64, 64, 3), dtype=np.uint8)  # worst case: maximal contrast
    th = np.radians(27)
    a = 1.37 * np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    src = np.array([[5.2, 4.1], [58.3, 6.6], [9.9, 57.7]])
    dst = src @ a.T + [60.3, 10.7]
    img = render_mesh(tex, texel_to_uv(src, tex), dst, np.zeros(3), [[0, 1, 2]], (160, 160), cull=False)
    ys, xs = np.nonzero(coverage(dst, [[0, 1, 2]], (160, 160)))
    s = (np.column_stack([xs, ys]) - [60.3, 10.7]) @ np.linalg.inv(a).T
    diff = np.abs(img[ys, xs] - exact_bilinear(tex, s))
    assert len(xs) > 2000
    assert diff.max() <= 1.0


def test_tiled_mesh_covers_its_hull_exactly_once():
    pts, uv, tris = grid_mesh(7, 5, 3.3, 2.7, 8.1, 9.4)
    pts += RNG.uniform(-2.5, 2.5, pts.shape) * (np.arange(len(pts)) % 9 != 0)[:, None]  # warp inside
    border = np.zeros(len(pts), bool)
    gx, gy = np.meshgrid(np.arange(8), np.arange(6))
    border[(gx.ravel() % 7 == 0) | (gy.ravel() % 5 == 0)] = True
    pts[border] = grid_mesh(7, 5, 3.3, 2.7, 8.1, 9.4)[0][border]  # straight hull edges
    cov = coverage(pts, tris, (70, 56))
    x, y = np.meshgrid(np.arange(70), np.arange(56))
    inside = (x > 3.3 + 0.01) & (x < 3.3 + 7 * 8.1 - 0.01) & (y > 2.7 + 0.01) & (y < 2.7 + 5 * 9.4 - 0.01)
    outside = (x < 3.3 - 0.01) | (x > 3.3 + 7 * 8.1 + 0.01) | (y < 2.7 - 0.01) | (y > 2.7 + 5 * 9.4 + 0.01)
    assert (cov[inside] == 1).all(), "hole inside the mesh"
    assert (cov[outside] == 0).all()
    assert cov.max() == 1, "a pixel was covered twice"
    # The renderer writes each covered pixel once: pixel writes == covered pixels.
    out = np.zeros((56, 70, 3), np.uint8)
    stats = render_mesh_into(out, np.full((4, 4, 3), 200, np.uint8), uv, pts, np.zeros(len(pts)), tris)
    assert stats.pixels == int(cov.sum())
    assert (out[cov == 1] == 200).all() and (out[cov == 0] == 0).all()


def test_head_turned_away_draws_nothing():
    head = generic_head()
    pose = Pose.framing(head.vertices, (128, 128), yaw=180)
    pts, z = project(head.vertices, pose)
    out = np.zeros((128, 128, 3), np.uint8)
    stats = render_mesh_into(out, painted_texture(head, 64), head.uv, pts, z, head.triangles)
    assert stats.drawn == 0 and stats.pixels == 0
    assert stats.culled == len(head.triangles)
    assert not out.any()


@pytest.mark.parametrize("depth_test", ["painter", "zbuffer"])
def test_near_triangle_covers_far_one(depth_test):
    tex = np.zeros((2, 2), np.uint8)
    tex[:, 1] = 255  # u < 0.5 black, u > 0.5 white
    pts = np.array([[2.0, 2], [2, 30], [30, 2]] * 2)
    uv = np.array([[0.25, 0.5]] * 3 + [[0.75, 0.5]] * 3)
    z = np.array([1.0] * 3 + [5.0] * 3)  # the white triangle is nearer
    for order in ([[3, 4, 5], [0, 1, 2]], [[0, 1, 2], [3, 4, 5]]):
        img = render_mesh(tex, uv, pts, z, order, (32, 32), depth_test=depth_test, filter="nearest")
        assert img[8, 8] == 255


def test_nose_hides_cheek_in_profile():
    head = generic_head()
    tex = painted_texture(head, 128)
    pose = Pose.framing(head.vertices, (200, 200), yaw=75)
    pts, z = project(head.vertices, pose)
    painter = render_mesh(tex, head.uv, pts, z, head.triangles, (200, 200), depth_test="painter")
    zbuf = render_mesh(tex, head.uv, pts, z, head.triangles, (200, 200), depth_test="zbuffer")
    # Both methods agree on almost every pixel of the profile.
    assert (np.abs(painter.astype(int) - zbuf).max(axis=2) > 40).mean() < 0.01


def test_gray_texture_gives_gray_image_and_background_image_is_kept():
    bg = np.full((20, 20), 7, np.uint8)
    img = render_mesh(
        np.full((3, 3), 99, np.uint8),
        [[0, 0], [1, 0], [0, 1]],
        [[1.0, 1], [1, 15], [15, 1]],
        np.zeros(3),
        [[0, 1, 2]],
        (20, 20),
        background=bg,
    )
    assert img.shape == (20, 20) and img[3, 3] == 99 and img[18, 18] == 7
    assert (bg == 7).all()


def test_triangles_outside_the_image_are_clipped():
    pts = np.array([[-1e6, -1e6], [-1e6, 1e6], [1e6, 0.0], [500.0, 500], [500, 600], [600, 500]])
    img = render_mesh(
        np.full((2, 2), 50, np.uint8), np.zeros((6, 2)), pts, np.zeros(6), [[0, 1, 2], [3, 4, 5]], (16, 12)
    )
    assert (img == 50).all()


def test_zero_area_triangles_are_skipped():
    pts = np.array([[0.0, 0], [5, 5], [10, 10]])
    out = np.zeros((12, 12), np.uint8)
    stats = render_mesh_into(out, np.full((2, 2), 9, np.uint8), np.zeros((3, 2)), pts, np.zeros(3), [[0, 1, 2]])
    assert stats.degenerate == 1 and not out.any()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"points": np.array([[np.nan, 0], [1, 0], [0, 1]])}, "points must be finite"),
        ({"points": np.zeros((3, 3))}, r"points must have shape \(N, 2\)"),
        ({"triangles": [[0, 1, 5]]}, "index 5 is out of range for 3 vertices"),
        ({"triangles": [[0, 1, -1]]}, "index -1 is out of range"),
        ({"triangles": [[0.0, 1.0, 2.0]]}, "integer indices"),
        ({"depth": np.zeros(2)}, r"depth must have shape \(3,\)"),
        ({"texture": np.zeros((4, 4, 3), np.float32)}, "texture must be a uint8 numpy array"),
        ({"size": (100_000, 100_000)}, "too large"),
        ({"size": (0, 10)}, "must be positive"),
        ({"filter": "cubic"}, "filter must be one of 'nearest', 'bilinear'"),
        ({"background": (1, 2)}, "one value per texture channel"),
    ],
)
def test_bad_input_is_refused_with_a_message(change, message):
    args = {
        "texture": np.zeros((4, 4, 3), np.uint8),
        "tex_coords": np.zeros((3, 2)),
        "points": np.array([[0.0, 0], [1, 0], [0, 1]]),
        "depth": np.zeros(3),
        "triangles": [[0, 1, 2]],
        "size": (8, 8),
    }
    args.update(change)
    with pytest.raises(InvalidInputError, match=message):
        render_mesh(**args)


def test_empty_mesh_is_refused():
    with pytest.raises(InvalidInputError, match="triangles must have shape"):
        render_mesh(np.zeros((2, 2), np.uint8), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros((0,)), (4, 4))


def test_render_into_a_non_contiguous_or_readonly_image_is_refused():
    out = np.zeros((8, 8, 3), np.uint8)[:, ::2]
    with pytest.raises(InvalidInputError, match="C-contiguous"):
        render_mesh_into(
            out, np.zeros((2, 2, 3), np.uint8), np.zeros((3, 2)), np.zeros((3, 2)), np.zeros(3), [[0, 1, 2]]
        )


@pytest.mark.parametrize("shape, colour", [((5, 7, 3), (38, 40, 46)), ((5, 7, 4), (1, 2, 3, 255)), ((5, 7), 9)])
def test_fill_paints_every_pixel_with_the_colour(shape, colour):
    img = np.zeros(shape, np.uint8)
    assert fill(img, colour) is img
    assert (img.reshape(-1, *shape[2:]) == np.asarray(colour, np.uint8)).all()
