"""Orthographic projection of model vertices into an image.

Model space: right-handed, x to the subject's left, y up, z towards the camera (millimetres for
the built-in head). Image space: pixels, x right, y down, (0, 0) at the centre of the top-left
pixel. Depth out of :func:`project` is larger for points nearer the camera.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from facemime import validate
from facemime.shared_constants import POSE_FIELDS


def rotation_matrix(yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """The rotation ``Rz(roll) @ Rx(pitch) @ Ry(yaw)``.

    All three are right-handed rotations of the model about its own axes: positive yaw turns the
    nose towards +x (the subject's left, the image's right), positive pitch tilts the nose down,
    positive roll turns the head counter-clockwise as seen in the image.

    Parameters
    ----------
    yaw
        Rotation about the model's y axis, degrees.
    pitch
        Rotation about the model's x axis, degrees.
    roll
        Rotation about the model's z axis, degrees.

    Returns
    -------
    (3, 3) float64 array
        Rotates model-space column vectors (``R @ v``; row vectors: ``v @ R.T``).

    Examples
    --------
    >>> np.round(rotation_matrix(yaw=90) @ [0, 0, 1], 6).tolist()
    [1.0, 0.0, 0.0]
    """
    y, p, r = np.radians([yaw, pitch, roll])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rx = np.array([[1, 0, 0], [0, np.cos(p), -np.sin(p)], [0, np.sin(p), np.cos(p)]])
    rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
    return rz @ rx @ ry


@dataclass(frozen=True)
class Pose:
    """Global motion of the head under orthographic projection.

    Attributes
    ----------
    yaw, pitch, roll : float
        Degrees, see :func:`rotation_matrix`.
    scale : float
        Image pixels per model unit (zoom).
    tx, ty : float
        Image position (pixels) of the model origin.
    """

    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    scale: float = 1.0
    tx: float = 0.0
    ty: float = 0.0

    def as_dict(self) -> dict[str, float]:
        """The pose as a track file's ``pose`` entry.

        Returns
        -------
        dict
            ``yaw``, ``pitch``, ``roll`` (degrees), ``scale`` (pixels per model unit), ``tx``,
            ``ty`` (pixels), in that order.
        """
        return {k: getattr(self, k) for k in POSE_FIELDS}

    @classmethod
    def framing(cls, vertices: np.ndarray, size: tuple[int, int], fill: float = 0.9, **angles: float) -> Pose:
        """The pose that shows vertices, rotated, centred in an image, their bounding box filling
        a share of the image's tighter side.

        Parameters
        ----------
        vertices
            (N, 3) float array: model coordinates, model units.
        size
            (width, height) of the image, pixels.
        fill
            Share of the tighter side (width or height) the rotated bounding box fills.
        **angles
            ``yaw``, ``pitch``, ``roll``, degrees (:func:`rotation_matrix`); missing ones are 0.

        Returns
        -------
        Pose
            ``angles``, the scale in pixels per model unit and the origin's position in pixels.

        Examples
        --------
        >>> v = np.array([[-50.0, -60, 0], [50, 60, 0]])
        >>> Pose.framing(v, (200, 240), fill=1.0)
        Pose(yaw=0.0, pitch=0.0, roll=0.0, scale=2.0, tx=99.5, ty=119.5)
        """
        w, h = validate.image_size("size", size)
        v = validate.float_array("vertices", vertices, (None, 3))
        rotated = v @ rotation_matrix(**angles).T
        lo, hi = rotated[:, :2].min(axis=0), rotated[:, :2].max(axis=0)
        extent = np.maximum(hi - lo, 1e-9)
        scale = float(fill * min(w / extent[0], h / extent[1]))
        cx, cy = (lo + hi) / 2
        base = cls(**{k: float(a) for k, a in angles.items()})
        return replace(base, scale=scale, tx=float((w - 1) / 2 - scale * cx), ty=float((h - 1) / 2 + scale * cy))


def project(vertices: np.ndarray, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
    """Project model vertices orthographically.

    Parameters
    ----------
    vertices
        (N, 3) float array: model coordinates (x to the subject's left, y up, z towards the
        camera), model units.
    pose
        The head pose that places the model in the image.

    Returns
    -------
    points : (N, 2) float64 array
        (x, y) pixels, y down, origin at the centre of the top-left pixel.
    depth : (N,) float64 array
        Pixels along the view direction, larger = nearer.

    Examples
    --------
    >>> pts, z = project(np.array([[10.0, 20.0, 5.0]]), Pose(scale=2, tx=100, ty=100))
    >>> pts.tolist(), z.tolist()
    ([[120.0, 60.0]], [10.0])
    """
    v = validate.float_array("vertices", vertices, (None, 3))
    rotated = v @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T
    points = np.empty((len(v), 2))
    points[:, 0] = pose.tx + pose.scale * rotated[:, 0]
    points[:, 1] = pose.ty - pose.scale * rotated[:, 1]
    return points, pose.scale * rotated[:, 2]


def head_plane(points: np.ndarray, depth: np.ndarray, pose: Pose) -> np.ndarray:
    """Model-space (x, y) of image points of known model depth: the inverse of the orthographic
    projection for points of known z.

    Parameters
    ----------
    points
        (K, 2) float array: (x, y) pixels of the image.
    depth
        (K,) float array: each point's model z, model units.
    pose
        The pose the points are seen in (a nonzero scale, the model's x-y plane not seen
        edge-on).

    Returns
    -------
    (K, 2) float64 array
        Model (x, y), model units.
    """
    r = rotation_matrix(pose.yaw, pose.pitch, pose.roll)
    # (u - tx - s·r02·z, v - ty + s·r12·z) = s·[[r00, r01], [-r10, -r11]] (x, y), inverted.
    det = pose.scale * (r[1, 0] * r[0, 1] - r[0, 0] * r[1, 1])
    inverse = np.array([[-r[1, 1], -r[0, 1]], [r[1, 0], r[0, 0]]]) / det
    rhs = np.column_stack(
        [points[:, 0] - pose.tx - pose.scale * r[0, 2] * depth, points[:, 1] - pose.ty + pose.scale * r[1, 2] * depth]
    )
    return rhs @ inverse.T
