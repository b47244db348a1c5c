"""A track's head poses and expression weights as glTF keyframes.

facemime's pose is orthographic (:mod:`facemime.types.pose`): a model point ``v`` lands
at pixel ``(tx, ty) + scale * (R v)_xy`` with the image's y down and
``R = Rz(roll) Rx(pitch) Ry(yaw)``. The model's axes are glTF's (x to the subject's left, y up,
z towards the camera: the asset's front faces +z), so the rotation goes over as it is. The
pixels have no 3-D meaning; the mapping written is relative to the first frame:

- rotation: ``R`` of each frame, as a unit quaternion (x, y, z, w);
- scale: ``scale / scale[0]`` (uniform): the head grows and shrinks as on screen;
- translation: ``((tx - tx[0]), -(ty - ty[0]), 0) * metres_per_pixel`` with
  ``metres_per_pixel = metres_per_unit / scale[0]``, so that the head moves by as many of its
  own sizes as on screen, and the first frame sits at the origin.

An orthographic camera looking down -z that shows ``metres_per_pixel`` metres a pixel with
pixel ``(tx[0], ty[0])`` on the world origin sees each frame as facemime projects it
(:func:`camera_box`).
"""

from __future__ import annotations

import numpy as np

#: The pose values of one frame, in the order of the (T, 6) arrays taken here.
POSE_KEYS = ("yaw", "pitch", "roll", "scale", "tx", "ty")


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products of (T, 4) quaternions (x, y, z, w): rotation ``b`` then ``a``."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=1,
    )


def quaternions(yaw: np.ndarray, pitch: np.ndarray, roll: np.ndarray) -> np.ndarray:
    """Unit quaternions of the rotations ``Rz(roll) Rx(pitch) Ry(yaw)`` (see
    :func:`facemime.types.pose.rotation_matrix`), each on the side of the one before.

    Parameters
    ----------
    yaw
        (T,) float array: each frame's yaw, degrees.
    pitch
        (T,) float array: each frame's pitch, degrees.
    roll
        (T,) float array: each frame's roll, degrees.

    Returns
    -------
    (T, 4) float64 array
        (x, y, z, w) unit quaternions, each on the side of the one before (``q`` and ``-q`` are
        one rotation; glTF interpolates between neighbours as given).

    Examples
    --------
    >>> np.round(quaternions(np.array([90.0]), np.zeros(1), np.zeros(1)), 4).tolist()
    [[0.0, 0.7071, 0.0, 0.7071]]
    """

    def about(axis: int, degrees: np.ndarray) -> np.ndarray:
        half = np.radians(np.asarray(degrees, np.float64)) / 2
        q = np.zeros((len(half), 4))
        q[:, axis], q[:, 3] = np.sin(half), np.cos(half)
        return q

    q = _multiply(about(2, roll), _multiply(about(0, pitch), about(1, yaw)))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    flip = np.cumsum(np.r_[False, np.einsum("ij,ij->i", q[1:], q[:-1]) < 0]) % 2 == 1
    q[flip] *= -1
    return q


def node_keys(poses: np.ndarray, metres_per_unit: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The keys of the head's node for a track's poses, as the module docstring maps them.

    Parameters
    ----------
    poses
        (T, 6) float array, each row in the order of :data:`POSE_KEYS`: yaw, pitch, roll degrees,
        scale pixels per model unit, tx, ty pixels.
    metres_per_unit
        Metres per model unit of the head (0.001 for millimetres).

    Returns
    -------
    translation : (T, 3) float64 array
        Metres, the first frame at the origin; y up (the image's y reversed), z 0.
    rotation : (T, 4) float64 array
        (x, y, z, w) unit quaternions (:func:`quaternions`).
    scale : (T, 3) float64 array
        Uniform scale relative to the first frame, the same in all three columns.

    Examples
    --------
    >>> t, r, s = node_keys(np.array([[0, 0, 0, 2.0, 100, 50], [0, 0, 0, 4.0, 110, 40]]), 0.001)
    >>> (t[1] * 1000).tolist(), s[1].tolist()
    ([5.0, 5.0, 0.0], [2.0, 2.0, 2.0])
    """
    p = np.asarray(poses, np.float64)
    first = p[0]
    per_pixel = metres_per_unit / first[3]
    translation = np.zeros((len(p), 3))
    translation[:, 0] = (p[:, 4] - first[4]) * per_pixel
    translation[:, 1] = -(p[:, 5] - first[5]) * per_pixel
    scale = np.repeat((p[:, 3] / first[3])[:, None], 3, axis=1)
    return translation, quaternions(p[:, 0], p[:, 1], p[:, 2]), scale


def camera_box(first: np.ndarray, size: tuple[int, int], metres_per_unit: float) -> tuple[float, float, float, float]:
    """The view box of the orthographic camera (looking down -z, y up) that shows the frames
    keyed by :func:`node_keys` as facemime projects them: pixel centres at integers, the image's
    edges half a pixel beyond the outer ones.

    Parameters
    ----------
    first
        (6,) float array: the first frame's pose in the order of :data:`POSE_KEYS` (degrees,
        pixels per model unit, pixels).
    size
        (width, height) of the image, pixels.
    metres_per_unit
        Metres per model unit of the head (0.001 for millimetres).

    Returns
    -------
    tuple of 4 float
        (left, right, top, bottom) of the camera's view, metres in the world (y up).

    Examples
    --------
    >>> camera_box(np.array([0, 0, 0, 1.0, 1.5, 1.5]), (4, 4), 1.0)
    (-2.0, 2.0, 2.0, -2.0)
    """
    per_pixel = metres_per_unit / float(first[3])
    tx, ty = float(first[4]), float(first[5])
    w, h = size
    return ((-0.5 - tx) * per_pixel, (w - 0.5 - tx) * per_pixel, (ty + 0.5) * per_pixel, (ty + 0.5 - h) * per_pixel)
