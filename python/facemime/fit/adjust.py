"""Placing and elastically adjusting a head model on reference points (docs/method.md §2).

The model is seen frontally (yaw = pitch = 0) under the orthographic projection of
:mod:`facemime.types.pose`: a :class:`~facemime.types.pose.Pose` with a roll, a
scale (pixels per model unit) and a translation maps it onto the photo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facemime import _core
from facemime.shared_constants import SEAL
from facemime.types.head import HeadModel, model_iod
from facemime.types.points import LIDS, POINTS, ReferencePoints, model_chain
from facemime.types.pose import Pose, project, rotation_matrix

#: Elastic adjustment settings: initial rigidity ψ as a fraction of the inter-ocular distance,
#: its shrink factor per iteration, ε, most iterations, and the stop threshold (fraction of the
#: inter-ocular distance) on the mean contour disagreement.
PSI = 0.3
SHRINK = 0.4
EPSILON = 2.0
ITERATIONS = 8
TOLERANCE = 0.004
#: Points whose inner lips stand further apart than this share of the mouth's width somewhere (an
#: open mouth: twice the gap the synthesis seals, :data:`~facemime.shared_constants.SEAL`) are
#: adjusted :data:`OPEN_ITERATIONS` times, not stopped at :data:`TOLERANCE`: that threshold is on
#: the mean over all contours, and the inner lips, pulled apart from the generic head's closed
#: mouth, were left 0.03-0.04 IOD off (st_kh, mt_sun, vr_2, st_aoc: nearly closed) while the rest
#: agreed; after 16 iterations 0.0004-0.002 (st_aoc's lower lip, open wide, 0.019).
OPEN_LIPS = 2 * SEAL
OPEN_ITERATIONS = 16


def frontal_pose(model_points: np.ndarray, image_points: np.ndarray) -> Pose:
    """The frontal pose (roll, scale, translation) that best maps model points onto image
    points, least squares.

    Parameters
    ----------
    model_points
        (K, 3) float array, K >= 2: model coordinates, model units; z is ignored (frontal view).
    image_points
        (K, 2) float array: the matching (x, y) pixels, y down.

    Returns
    -------
    Pose
        Yaw and pitch 0; roll degrees, scale pixels per model unit, tx, ty pixels.

    Examples
    --------
    >>> frontal_pose(np.array([[-45.0, 0, 0], [45, 0, 0]]), np.array([[100.0, 50], [190, 50]]))
    Pose(yaw=0.0, pitch=0.0, roll=-0.0, scale=1.0, tx=145.0, ty=50.0)
    """
    q = model_points[:, 0] - 1j * model_points[:, 1]  # image orientation: y down
    p = image_points[:, 0] + 1j * image_points[:, 1]
    qc, pc = q - q.mean(), p - p.mean()
    z = (np.conj(qc) @ pc) / max(float(np.vdot(qc, qc).real), 1e-12)
    t = p.mean() - z * q.mean()
    return Pose(roll=float(-np.degrees(np.angle(z))), scale=float(abs(z)), tx=float(t.real), ty=float(t.imag))


@dataclass(frozen=True)
class Fit:
    """A head model fitted to a photo.

    Attributes
    ----------
    vertices : (N, 3) float64 array
        The adjusted vertices, model units, in the model's own frame (frontal, upright).
    pose : Pose
        Maps ``vertices`` onto the photo (frontal: only roll, scale, translation).
    residuals : (I + 1,) float64 array
        Mean contour disagreement before and after each elastic iteration, pixels.
    """

    vertices: np.ndarray
    pose: Pose
    residuals: np.ndarray


def fit_model(model: HeadModel, points: ReferencePoints) -> Fit:
    """Scale and place a head model on reference points, then adjust it elastically until its
    contours lie on theirs.

    The placement is the least-squares similarity of the single points (but the lids) and the
    curve ends; the adjusted image positions are taken back into model space through it, so
    proportions that differ from the generic head (a longer face, a wider mouth) stay in the
    vertices. Points of an open mouth (:func:`lips_opening` over :data:`OPEN_LIPS`) are adjusted
    :data:`OPEN_ITERATIONS` times.

    Parameters
    ----------
    model
        The head to fit; its groups hold the vertices each point marks
        (:func:`~facemime.types.points.model_chain`).
    points
        Validated reference points (:func:`facemime.types.points.check_points`), name -> (K, 2)
        (x, y) pixels of the photo.

    Returns
    -------
    Fit
        The adjusted vertices (model units; x and y adjusted, z the model's own), the placing
        pose and the residual of each iteration, pixels.
    """
    anchors_m, anchors_i = [], []
    for name, pts in points.items():
        chain = model_chain(model, name)
        if name in LIDS:
            continue
        if name in POINTS:
            anchors_m.append(model.vertices[chain])
            anchors_i.append(pts)
        elif name != "face_outline":
            anchors_m.append(model.vertices[chain[[0, -1]]])
            anchors_i.append(pts[[0, -1]])
    pose = frontal_pose(np.concatenate(anchors_m), np.concatenate(anchors_i))
    start = project(model.vertices, pose)[0]
    names = list(points)
    chains = [model_chain(model, n) for n in names]
    iod = pose.scale * model_iod(model)
    opened = lips_opening(points) > OPEN_LIPS
    adjusted, residuals = _core.elastic_adjust(
        np.ascontiguousarray(start),
        np.concatenate(chains).astype(np.uint32),
        np.array([len(c) for c in chains], np.uint32),
        np.ascontiguousarray(np.concatenate([points[n] for n in names])),
        np.array([len(points[n]) for n in names], np.uint32),
        PSI * iod,
        SHRINK,
        EPSILON,
        OPEN_ITERATIONS if opened else ITERATIONS,
        0.0 if opened else TOLERANCE * iod,
    )
    # Back to model space: undo translation, scale and roll; depth stays the generic one.
    rot = rotation_matrix(roll=pose.roll)[:2, :2]
    local = np.column_stack([adjusted[:, 0] - pose.tx, pose.ty - adjusted[:, 1]]) / pose.scale
    vertices = model.vertices.copy()
    vertices[:, :2] = local @ rot  # rot is orthonormal: rot.T undoes it (row vectors)
    return Fit(vertices, pose, residuals)


def lips_opening(points: ReferencePoints) -> float:
    """How far apart the points' inner lips stand.

    Parameters
    ----------
    points
        Reference points, name -> (K, 2) (x, y) pixels; those without both inner lips (of one
        length) count as closed.

    Returns
    -------
    float
        The largest distance between the upper and the lower inner lip's points of one index,
        over the distance between the outer lips' corners (0 where the points do not say).

    Examples
    --------
    >>> lips = {"mouth_outer_upper": np.array([[0.0, 0], [50, -5], [100, 0]])}
    >>> lips |= {"mouth_inner_upper": np.array([[10.0, 0], [50, 2], [90, 0]])}
    >>> lips_opening(lips | {"mouth_inner_lower": np.array([[10.0, 0], [50, 12], [90, 0]])})
    0.1
    """
    upper, lower, outer = (points.get(n) for n in ("mouth_inner_upper", "mouth_inner_lower", "mouth_outer_upper"))
    if upper is None or lower is None or outer is None or len(upper) != len(lower):
        return 0.0
    width = float(np.linalg.norm(outer[-1] - outer[0]))
    return float(np.linalg.norm(upper - lower, axis=1).max()) / width if width > 0 else 0.0
