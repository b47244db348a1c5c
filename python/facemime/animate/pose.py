"""Head pose per frame from the optical flow: the orthographic pose (yaw, pitch, roll, scale,
translation; see :class:`facemime.types.pose.Pose`) that best maps rigid 3D points of the
actor's model onto where the optical flow followed them. The analysis measures the pose on the
Face Mesh landmarks (:mod:`facemime.animate.landmark_pose`) and falls back to this on frames
whose landmark pass finds no face.

The rigid points are the tracker's head-motion points (nose, nose bridge, forehead). When a point
is first seen, it is lifted onto the model: the front-most model triangle under it, at the pose
of that frame, gives its 3D position (model units). Later frames fit the pose to those 3D points
by Gauss-Newton with Huber weights, started from the previous pose.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from facemime import _core
from facemime.track.motion import HeadMotion
from facemime.track.scale import ScaledMotion
from facemime.types.pose import Pose, project

#: Fewest lifted points that fit a pose.
MIN_POINTS = 6
#: Huber threshold of the pose fit, pixels.
HUBER = 1.5
#: Weight (px² per degree²) holding yaw and pitch near the previous frame's: the rigid points
#: span little depth, so the two out-of-plane angles are the weakly measured ones.
ANGLE_PRIOR = 0.05
#: Weight (px² per degree²) pulling yaw and pitch towards the first frame's: it bounds the drift
#: that re-lifting new points at an estimated pose accumulates (the faces here stay roughly
#: frontal; a head held turned for long is under-estimated).
RELAX = 0.05
GN_ITERATIONS = 6


def lift(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
    """3D model positions of image points: where the ray through each point meets the front-most
    facing triangle of the mesh in ``pose``, or, for a point beside the mesh (the forehead above
    it), the plane of the facing triangle nearest to it on the image.

    Parameters
    ----------
    points
        (M, 2) float array: (x, y) image pixels.
    vertices
        (N, 3) float array: the mesh's vertices, model units.
    triangles
        (F, 3) int array: the mesh's triangles, vertex indices; those counter-clockwise on the
        image face the camera.
    pose
        The pose the mesh is seen in.

    Returns
    -------
    positions : (M, 3) float64 array
        Model coordinates, model units (all NaN when no triangle of the mesh faces the camera).
    ok : (M,) bool array
        Whether the points were placed: all True, or all False when no triangle faces the camera.
    """
    pts = np.asarray(points, np.float64).reshape(-1, 2)
    img, depth = project(vertices, pose)
    a, b, c = (img[triangles[:, k]] for k in range(3))
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    facing = area < -1e-9  # counter-clockwise on the image (y down) has negative signed area
    a, b, c, area, tris = a[facing], b[facing], c[facing], area[facing], triangles[facing]
    rel = pts[:, None, :]

    def edge(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return (q[None, :, 0] - p[None, :, 0]) * (rel[..., 1] - p[None, :, 1]) - (q[None, :, 1] - p[None, :, 1]) * (
            rel[..., 0] - p[None, :, 0]
        )

    wa, wb, wc = edge(b, c) / area, edge(c, a) / area, edge(a, b) / area
    inside = (wa >= -1e-9) & (wb >= -1e-9) & (wc >= -1e-9)
    z = wa * depth[tris[:, 0]] + wb * depth[tris[:, 1]] + wc * depth[tris[:, 2]]
    z = np.where(inside, z, -np.inf)
    best = np.argmax(z, axis=1)
    rows = np.arange(len(pts))
    beside = ~np.isfinite(z[rows, best])
    if beside.any() and len(tris):
        centres = (a + b + c) / 3.0
        best[beside] = np.argmin(np.linalg.norm(pts[beside, None] - centres[None], axis=2), axis=1)
    w = np.stack([wa[rows, best], wb[rows, best], wc[rows, best]], axis=1) if len(tris) else np.zeros((len(pts), 3))
    ok = np.full(len(pts), len(tris) > 0)
    xyz = np.einsum("mk,mkd->md", w, vertices[tris[best]]) if len(tris) else np.full((len(pts), 3), np.nan)
    return xyz, ok


def _params(pose: Pose) -> np.ndarray:
    return np.array([pose.yaw, pose.pitch, pose.roll, np.log(pose.scale), pose.tx, pose.ty])


def _pose(p: np.ndarray) -> Pose:
    return Pose(
        yaw=float(p[0]), pitch=float(p[1]), roll=float(p[2]), scale=float(np.exp(p[3])), tx=float(p[4]), ty=float(p[5])
    )


def fit_pose(
    model_points: np.ndarray, image_points: np.ndarray, start: Pose, towards: tuple[float, float] = (0.0, 0.0)
) -> Pose:
    """The pose that maps model points onto image points: Gauss-Newton with Huber weights
    (:data:`HUBER`) from ``start`` (``facemime._core.fit_pose``, analytic Jacobian); yaw and pitch
    are held towards ``start``'s (weight :data:`ANGLE_PRIOR`) and ``towards`` (weight
    :data:`RELAX`).

    Parameters
    ----------
    model_points
        (M, 3) float array: model coordinates, model units.
    image_points
        (M, 2) float array: where they are seen, (x, y) image pixels.
    start
        The pose the fit starts from (the previous frame's).
    towards
        (yaw, pitch), degrees, that yaw and pitch are also pulled towards (the first frame's).

    Returns
    -------
    Pose
        The fitted pose, yaw and pitch clipped to [-75, 75] degrees.
    """
    x = np.ascontiguousarray(model_points, np.float64)
    target = np.ascontiguousarray(image_points, np.float64)
    p = _params(start)
    anchor = (ANGLE_PRIOR * p[:2] + RELAX * np.asarray(towards)) / (ANGLE_PRIOR + RELAX)
    p = np.array(_core.fit_pose(x, target, tuple(p), tuple(anchor), ANGLE_PRIOR + RELAX, HUBER, GN_ITERATIONS))
    p[:2] = np.clip(p[:2], -75.0, 75.0)
    return _pose(p)


def moved(pose: Pose, step: np.ndarray) -> Pose:
    """A pose followed by an image similarity.

    Parameters
    ----------
    pose
        The pose before the step.
    step
        (2, 3) float array: the image's similarity, pixels to pixels.

    Returns
    -------
    Pose
        ``pose`` with the step's turn added to the roll (counter-clockwise on the image, y down),
        its scale multiplying the scale and the model origin's image position moved by it; yaw
        and pitch stay.
    """
    m = np.asarray(step, np.float64)
    turn = np.degrees(np.arctan2(m[1, 0] - m[0, 1], m[0, 0] + m[1, 1]))
    origin = m[:, :2] @ (pose.tx, pose.ty) + m[:, 2]
    return replace(
        pose,
        roll=pose.roll - float(turn),
        scale=pose.scale * float(np.sqrt(abs(np.linalg.det(m[:, :2])))),
        tx=float(origin[0]),
        ty=float(origin[1]),
    )


class PoseTracker:
    """Follows the head pose of one actor model through a video, on the rigid points of a
    :class:`facemime.track.motion.HeadMotion`.

    Parameters
    ----------
    vertices
        (N, 3) float array: the actor's model vertices, model units.
    triangles
        (F, 3) int array: the model's triangles, vertex indices.
    pose
        The pose on the first frame (the fitted actor's).
    motion
        The head-motion follower, on the first frame: its points are lifted at ``pose``.
    """

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray, pose: Pose, motion: HeadMotion | ScaledMotion):
        self._vertices = np.asarray(vertices, np.float64)
        self._triangles = np.asarray(triangles, np.int64)
        self._frontal = pose
        self.pose = pose
        self._known: dict[int, np.ndarray] = {}
        self._lift(motion.points, motion.ids)

    def _lift(self, points: np.ndarray, ids: np.ndarray) -> None:
        new = np.array([i not in self._known for i in ids.tolist()], bool)
        if new.any():
            xyz, ok = lift(points[new], self._vertices, self._triangles, self.pose)
            for i, p, good in zip(ids[new].tolist(), xyz, ok):
                if good:
                    self._known[i] = p

    def update(self, motion: HeadMotion | ScaledMotion) -> bool:
        """Fit the pose to the points the head motion followed into the current frame.

        An unmeasured frame moves the last pose by the head's step in the image (``motion.step``;
        the step's fallback, when the flow lost the points in a fast motion, drops them all). Yaw
        and pitch relax towards the first frame's by :data:`RELAX` per frame.

        Parameters
        ----------
        motion
            The head-motion follower, updated to the current frame.

        Returns
        -------
        bool
            Whether the pose was measured (at least :data:`MIN_POINTS` known points followed).
        """
        points, ids = motion.followed
        known = np.array([i in self._known for i in ids.tolist()], bool)
        ok = int(known.sum()) >= MIN_POINTS
        if ok:
            xyz = np.array([self._known[i] for i in ids[known].tolist()])
            self.pose = fit_pose(
                xyz, np.asarray(points, np.float64)[known], self.pose, towards=(self._frontal.yaw, self._frontal.pitch)
            )
        else:
            self.pose = moved(self.pose, motion.step)
        self._keep(motion)
        return ok

    def follow(self, pose: Pose, motion: HeadMotion | ScaledMotion) -> None:
        """Take a pose measured otherwise (on the landmarks) as the current frame's.

        Parameters
        ----------
        pose
            The current frame's pose.
        motion
            The head-motion follower, updated to the current frame: the points it follows are
            kept and new ones lifted at ``pose``, for the frames the flow measures.
        """
        self.pose = pose
        self._keep(motion)

    def _keep(self, motion: HeadMotion | ScaledMotion) -> None:
        """Forget the points ``motion`` no longer follows; lift its new ones at the current pose."""
        current = set(motion.ids.tolist())
        self._known = {i: p for i, p in self._known.items() if i in current}
        self._lift(np.asarray(motion.points, np.float64), motion.ids)

    def reset(self, pose: Pose, motion: HeadMotion | ScaledMotion) -> None:
        """Start again on a new first frame (after the face was lost).

        Parameters
        ----------
        pose
            The pose on the new first frame.
        motion
            The head-motion follower, on that frame: its points are lifted at ``pose``.
        """
        self._frontal = self.pose = pose
        self._known.clear()
        self._lift(motion.points, motion.ids)
