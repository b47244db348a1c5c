"""Head pose from the Face Mesh landmarks: the rigid landmarks' 3-D shape (x, y and the landmark
model's depth) aligned by weighted orthogonal Procrustes, yaw and pitch included.

The key frame's rigid landmarks are lifted into the actor's model frame once
(:class:`LandmarkPose`): their image positions and depths, undone by the key frame's pose, with
the depths' offset set so that they lie on the actor's mesh on average. Each later frame's rigid
landmarks are aligned to those model points (rotation, scale, translation; Huber-weighted
rounds against outlying points), which gives the frame's :class:`~facemime.types.pose.Pose`
absolutely, in the model's frame, not relative to the first frame.

Frames: landmarks are image pixels (x right, y down, depth smaller = nearer the camera, in the
same pixel scale). They are aligned in camera coordinates (x right, y up, z towards the camera:
``(x, -y, -depth)``), the frame in which :func:`~facemime.types.pose.project` places the
rotated model: image x = tx + scale · x, image y = ty − scale · y.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facemime.animate.pose import lift
from facemime.types.pose import Pose, rotation_matrix

#: Face Mesh landmarks that move with the skull, not with the expression: forehead, temples,
#: nose bridge and tip, the eyes' corners and the cheekbones (64 points).
RIGID = (
    # forehead and temples
    10, 151, 9, 8, 108, 337, 67, 297, 69, 299, 104, 333, 109, 338, 54, 284, 21, 251, 162, 389,
    # nose
    168, 6, 197, 195, 5, 4, 1, 19, 98, 327, 64, 294, 48, 278, 129, 358, 2,
    # eye corners
    33, 133, 263, 362, 130, 359, 243, 463,
    # cheekbones and the sides of the face at the eyes
    116, 345, 117, 346, 123, 352, 50, 280, 101, 330, 118, 347, 234, 454, 227, 447, 127, 356, 93,
)  # fmt: skip
#: Huber threshold of the alignment's residuals, in units of the face's size (RMS distance of
#: the rigid points from their centroid).
HUBER = 0.03
#: Reweighting rounds of the alignment.
ROUNDS = 3


def camera_points(landmarks: np.ndarray) -> np.ndarray:
    """Landmarks in camera coordinates: ``(x, -y, -depth)``.

    Parameters
    ----------
    landmarks
        (N, 3) float array: (x, y) image pixels and depth, pixels, smaller = nearer the camera.

    Returns
    -------
    (N, 3) float64 array
        Camera coordinates, pixels: x right, y up, z towards the camera.
    """
    p = np.asarray(landmarks, np.float64)
    return np.column_stack([p[:, 0], -p[:, 1], -p[:, 2]])


def procrustes(
    source: np.ndarray, target: np.ndarray, weights: np.ndarray | None = None
) -> tuple[float, np.ndarray, np.ndarray]:
    """The similarity that best maps one point set onto another in the weighted least-squares
    sense (Umeyama): ``target ≈ scale · source @ rotation.T + translation``, the rotation proper
    (determinant +1).

    Parameters
    ----------
    source
        (N, 3) float array: the points mapped.
    target
        (N, 3) float array: where they should land, in order.
    weights
        (N,) float array: non-negative weight per point (normalised to sum 1); None: equal.

    Returns
    -------
    scale : float
        Target units per source unit.
    rotation : (3, 3) float64 array
        The rotation, determinant +1.
    translation : (3,) float64 array
        In target units.

    Examples
    --------
    >>> r = rotation_matrix(yaw=20, pitch=-10, roll=5)
    >>> src = np.random.default_rng(0).normal(size=(10, 3))
    >>> s, rot, t = procrustes(src, 2 * src @ r.T + [1, 2, 3])
    >>> round(s, 9), bool(np.allclose(rot, r)), np.round(t, 9).tolist()
    (2.0, True, [1.0, 2.0, 3.0])
    """
    x, y = np.asarray(source, np.float64), np.asarray(target, np.float64)
    w = np.ones(len(x)) if weights is None else np.asarray(weights, np.float64)
    w = w / w.sum()
    mx, my = w @ x, w @ y
    xc, yc = x - mx, y - my
    cov = (yc * w[:, None]).T @ xc
    u, d, vt = np.linalg.svd(cov)
    sign = np.ones(3)
    sign[2] = np.sign(np.linalg.det(u @ vt)) or 1.0
    rotation = (u * sign) @ vt
    scale = float((d * sign).sum() / (w @ (xc**2).sum(axis=1)))
    return scale, rotation, my - scale * rotation @ mx


def angles(rotation: np.ndarray) -> tuple[float, float, float]:
    """The angles of a rotation ``Rz(roll) @ Rx(pitch) @ Ry(yaw)``
    (:func:`~facemime.types.pose.rotation_matrix`'s convention).

    Parameters
    ----------
    rotation
        (3, 3) float array: a proper rotation matrix.

    Returns
    -------
    tuple of (yaw, pitch, roll)
        Degrees; pitch in [-90, 90], yaw and roll in (-180, 180].

    Examples
    --------
    >>> np.round(angles(rotation_matrix(yaw=30, pitch=-12, roll=7)), 9).tolist()
    [30.0, -12.0, 7.0]
    """
    r = np.asarray(rotation, np.float64)
    pitch = np.degrees(np.arcsin(np.clip(r[2, 1], -1.0, 1.0)))
    yaw = np.degrees(np.arctan2(-r[2, 0], r[2, 2]))
    roll = np.degrees(np.arctan2(-r[0, 1], r[1, 1]))
    return float(yaw), float(pitch), float(roll)


class LandmarkPose:
    """Measures an actor's head pose from the Face Mesh landmarks of each frame.

    Parameters
    ----------
    landmarks
        (468, 3) float array: the key frame's Face Mesh landmarks, (x, y) image pixels and depth,
        pixels (smaller = nearer), where the actor was fitted.
    pose
        The actor's pose on the key frame.
    vertices
        (N, 3) float array: the actor's mesh vertices, model units; with ``triangles`` it sets the
        lifted points' depth offset.
    triangles
        (F, 3) int array: the mesh's triangles, vertex indices.
    """

    def __init__(self, landmarks: np.ndarray, pose: Pose, vertices: np.ndarray, triangles: np.ndarray):
        cam = camera_points(np.asarray(landmarks, np.float64)[list(RIGID)])
        rot = rotation_matrix(pose.yaw, pose.pitch, pose.roll)
        on_mesh, ok = lift(cam[:, :2] * [1, -1], vertices, triangles, pose)
        # the landmarks' depth is relative: offset it so that the points lie on the mesh on average
        mesh_depth = pose.scale * (on_mesh @ rot.T)[:, 2]
        offset = float(np.mean(mesh_depth[ok] - cam[ok, 2])) if ok.any() else 0.0
        origin = np.array([pose.tx, -pose.ty, -offset])  # the model origin in camera coordinates
        #: (len(RIGID), 3) the rigid points in model coordinates (model units).
        self.points = ((cam - origin) / pose.scale) @ rot
        self._size = float(np.sqrt(((self.points - self.points.mean(axis=0)) ** 2).sum(axis=1).mean()))

    def measure(self, landmarks: np.ndarray) -> Pose:
        """The head pose on a frame.

        Parameters
        ----------
        landmarks
            (468, 3) float array: the frame's Face Mesh landmarks, (x, y) image pixels and depth,
            pixels (smaller = nearer).

        Returns
        -------
        Pose
            The actor's pose on the frame, in the model's frame (not relative to the key frame).
        """
        target = camera_points(np.asarray(landmarks, np.float64)[list(RIGID)])
        weights = np.ones(len(target))
        for _ in range(ROUNDS):
            scale, rot, t = procrustes(self.points, target, weights)
            residual = np.linalg.norm(target - scale * self.points @ rot.T - t, axis=1) / (scale * self._size)
            weights = np.minimum(1.0, HUBER / np.maximum(residual, 1e-12))
        yaw, pitch, roll = angles(rot)
        return Pose(yaw=yaw, pitch=pitch, roll=roll, scale=scale, tx=float(t[0]), ty=float(-t[1]))


@dataclass
class OneEuro:
    """Casiez, Roussel and Vogel's One-Euro filter of a vector signal: a low-pass whose cutoff
    rises with the signal's speed, so that a still signal is smoothed and a moving one follows
    with little lag.

    ``min_cutoff`` (Hz): the cutoff of a still signal; ``beta`` (Hz per unit/s): how fast the
    cutoff rises with speed; ``d_cutoff`` (Hz): the cutoff of the speed's own estimate.
    """

    min_cutoff: float
    beta: float
    d_cutoff: float = 1.0
    _x: np.ndarray | None = field(default=None, repr=False)
    _dx: np.ndarray | None = field(default=None, repr=False)

    @staticmethod
    def _alpha(cutoff: np.ndarray | float, dt: float) -> np.ndarray:
        tau = 1.0 / (2.0 * np.pi * np.asarray(cutoff, np.float64))
        return 1.0 / (1.0 + tau / dt)

    def __call__(self, x: np.ndarray, dt: float) -> np.ndarray:
        """Filter the next sample.

        Parameters
        ----------
        x
            The sample, a float array of the same shape every call.
        dt
            Seconds since the last sample (> 0; unused on the first).

        Returns
        -------
        float64 array
            The filtered value, ``x``'s shape (a copy; the first sample as it is).
        """
        x = np.asarray(x, np.float64)
        if self._x is None or self._dx is None:
            self._x, self._dx = x.copy(), np.zeros_like(x)
            return x.copy()
        dx = (x - self._x) / dt
        self._dx = self._dx + self._alpha(self.d_cutoff, dt) * (dx - self._dx)
        cutoff = self.min_cutoff + self.beta * np.abs(self._dx)
        self._x = self._x + self._alpha(cutoff, dt) * (x - self._x)
        return self._x.copy()


#: :class:`PoseFilter`'s settings: the cutoff of a still head (Hz) and how fast it rises with the
#: head's speed (Hz per degree, per model unit or per percent of scale a second).
MIN_CUTOFF = 1.0
BETA = 0.3


class PoseFilter:
    """Smooths a sequence of poses against the landmark model's frame-to-frame jitter without
    lagging a moving head: a :class:`OneEuro` filter of yaw, pitch, roll (degrees), the scale
    (percent, as 100 ln scale) and the model origin's position (tx, ty in model units at the
    first pose's scale), so that one setting serves them all.

    Parameters
    ----------
    fps
        The poses' rate, frames/s: sets the filter's time step.
    min_cutoff
        The cutoff of a still head, Hz.
    beta
        How fast the cutoff rises with the head's speed, Hz per degree, per model unit or per
        percent of scale a second.
    """

    def __init__(self, fps: float, min_cutoff: float = MIN_CUTOFF, beta: float = BETA):
        self._dt = 1.0 / fps
        self._filter = OneEuro(min_cutoff, beta)
        self._unit: float | None = None

    def __call__(self, pose: Pose) -> Pose:
        """Filter the next frame's pose.

        Parameters
        ----------
        pose
            The frame's measured pose.

        Returns
        -------
        Pose
            The filtered pose (the first pose as it is).
        """
        if self._unit is None:
            self._unit = pose.scale
        u = self._unit
        v = self._filter(
            np.array([pose.yaw, pose.pitch, pose.roll, 100.0 * np.log(pose.scale), pose.tx / u, pose.ty / u]), self._dt
        )
        return Pose(
            yaw=float(v[0]), pitch=float(v[1]), roll=float(v[2]), scale=float(np.exp(v[3] / 100.0)),
            tx=float(v[4] * u), ty=float(v[5] * u),
        )  # fmt: skip
