"""Elastic adjustment (method.md §2) in the core, and fitting the generic head to real points."""

import numpy as np
import pytest

from facemime import _core
from facemime.errors import InvalidInputError
from facemime.fit import fit_model, frontal_pose
from facemime.head import generic_head
from facemime.metrics import curve_error
from facemime.types.points import check_points
from facemime.types.pose import project


def grid() -> np.ndarray:
    y, x = np.mgrid[0:12, 0:12] * 10.0
    return np.column_stack([x.ravel(), y.ravel()])


def adjust(points, chains, targets, psi, iterations=8, tolerance=0.1):
    return _core.elastic_adjust(
        points,
        np.concatenate(chains).astype(np.uint32),
        np.array([len(c) for c in chains], np.uint32),
        np.concatenate(targets),
        np.array([len(t) for t in targets], np.uint32),
        psi,
        0.5,
        2.0,
        iterations,
        tolerance,
    )


def test_a_model_contour_moves_onto_its_target_in_a_few_iterations():
    p = grid()
    row = np.arange(60, 72)  # the row at y = 50
    x = np.linspace(0, 110, 40)
    target = np.column_stack([x, 50 + 7 * np.sin(np.pi * x / 110)])  # bulges 7 px down
    out, residuals = adjust(p, [row], [target], psi=30.0)
    assert residuals[0] > 3.0 and residuals[-1] < 0.5
    assert len(residuals) - 1 <= 5
    assert curve_error(out[row], target) < 0.5


def test_small_rigidity_leaves_far_vertices_still():
    p = grid()
    out, _ = adjust(p, [[0]], [np.array([[5.0, 4.0]])], psi=6.0, iterations=1, tolerance=0.0)
    np.testing.assert_allclose(out[0], [5.0, 4.0], atol=1e-9)
    far = np.hypot(p[:, 0], p[:, 1]) >= 30
    assert np.abs(out[far] - p[far]).max() < 1e-3


def test_large_rigidity_moves_everything_together():
    p = grid()
    out, _ = adjust(
        p, [[0], [143]], [np.array([[3.0, 2.0]]), np.array([[113.0, 112.0]])], psi=1e5, iterations=1, tolerance=0.0
    )
    np.testing.assert_allclose(out - p, np.tile([3.0, 2.0], (len(p), 1)), atol=1e-3)


@pytest.mark.parametrize(
    ("chains", "targets", "psi", "message"),
    [
        ([[200]], [np.zeros((1, 2))], 10.0, "uses vertex 200, but there are 144 vertices"),
        ([[1]], [np.zeros((1, 2))], 0.0, "psi must be a positive number"),
        ([[1]], [np.array([[np.nan, 0.0]])], 10.0, "target of contour 0 holds NaN"),
    ],
)
def test_bad_input_is_refused(chains, targets, psi, message):
    with pytest.raises(InvalidInputError, match=message):
        adjust(grid(), chains, targets, psi)


def test_frontal_pose_recovers_a_known_placement():
    model = generic_head()
    truth = frontal_pose(
        model.vertices[:3],
        project(model.vertices[:3], frontal_pose(model.vertices[:2], np.array([[10.0, 20], [90, 35]])))[0],
    )
    pts = project(model.vertices, truth)[0]
    again = frontal_pose(model.vertices, pts)
    assert again.roll == pytest.approx(truth.roll) and again.scale == pytest.approx(truth.scale)
    assert (again.tx, again.ty) == pytest.approx((truth.tx, truth.ty))


def test_fitting_real_points_puts_the_model_contours_on_them(lp_d0):
    _frame, points, iod = lp_d0
    model = generic_head()
    fit = fit_model(model, check_points(points, 512, 512))
    assert fit.residuals[-1] < 0.01 * iod and len(fit.residuals) - 1 <= 6
    projected = project(fit.vertices, fit.pose)[0]
    for name in ("mouth_outer_upper", "mouth_inner_lower", "brow_left_upper", "brow_right_lower"):
        assert curve_error(projected[model.groups[name]], points[name]) < 0.01 * iod, name
    # Depth is the generic head's, and the face keeps a plausible size (IOD in model units).
    np.testing.assert_array_equal(fit.vertices[:, 2], model.vertices[:, 2])
    g = fit.vertices[model.groups["eye_left"][4]] - fit.vertices[model.groups["eye_right"][0]]
    assert 80 < np.linalg.norm(g[:2]) < 100


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda p: p.pop("eye_left_outer"), "missing eye_left_outer"),
        (lambda p: p.__setitem__("ear", [1, 2]), "unknown point ear"),
        (lambda p: p.__setitem__("nose_tip", [[1, 2], [3, 4]]), "nose_tip is a single point"),
        (lambda p: p.__setitem__("chin", [900, 10]), "chin has points outside the 512x512 image"),
        (lambda p: p.__setitem__("mouth_outer_upper", "abc"), "mouth_outer_upper must be"),
    ],
)
def test_bad_points_are_refused(lp_d0, change, message):
    points = {k: v.tolist() for k, v in lp_d0[1].items()}
    change(points)
    with pytest.raises(InvalidInputError, match=message):
        check_points(points, 512, 512)
