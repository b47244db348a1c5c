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
    """3D model positions of image ``points`` (M, 2) px: where the ray through each point meets
    the front-most facing triangle of the mesh (``vertices`` (N, 3) in ``pose``), or, for a
    point beside the mesh (the forehead above it), the plane of the facing triangle nearest to
    it on the image. Returns the (M, 3) positions and an (M,) mask, False where no triangle faces
    the camera."""
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
    """The pose that maps (M, 3) ``model_points`` onto (M, 2) ``image_points`` (px): Gauss-Newton
    with Huber weights (:data:`HUBER`) from ``start`` (``facemime._core.fit_pose``, analytic
    Jacobian); yaw and pitch are held towards ``start``'s (weight :data:`ANGLE_PRIOR`) and
    ``towards`` (weight :data:`RELAX`), degrees."""
    x = np.ascontiguousarray(model_points, np.float64)
    target = np.ascontiguousarray(image_points, np.float64)
    p = _params(start)
    anchor = (ANGLE_PRIOR * p[:2] + RELAX * np.asarray(towards)) / (ANGLE_PRIOR + RELAX)
    p = np.array(_core.fit_pose(x, target, tuple(p), tuple(anchor), ANGLE_PRIOR + RELAX, HUBER, GN_ITERATIONS))
    p[:2] = np.clip(p[:2], -75.0, 75.0)
    return _pose(p)


def moved(pose: Pose, step: np.ndarray) -> Pose:
    """``pose`` followed by the image's 2×3 similarity ``step`` (pixels to pixels): the step's
    turn added to the roll (counter-clockwise on the image, y down), its scale to the scale and
    the model origin's image position moved by it; yaw and pitch stay."""
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
    vertices : (N, 3) float array
        The actor's model vertices (model units).
    triangles : (F, 3) int array
    pose : Pose
        The pose on the first frame (the fitted actor's).
    motion : HeadMotion
        The head-motion follower, on the first frame.
    """

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray, pose: Pose, motion: HeadMotion):
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

    def update(self, motion: HeadMotion) -> bool:
        """Fit the pose to the points ``motion`` followed into the current frame; returns whether
        it could be measured (at least :data:`MIN_POINTS` known points). An unmeasured frame
        moves the last pose by the head's step in the image (``motion.step``; the step's
        fallback, when the flow lost the points in a fast motion, drops them all). Yaw and pitch
        relax towards the first frame's by :data:`RELAX` per frame."""
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

    def follow(self, pose: Pose, motion: HeadMotion) -> None:
        """Take ``pose``, measured otherwise (the landmarks), as the current frame's; the points
        ``motion`` follows are kept and new ones lifted at it, for the frames the flow measures."""
        self.pose = pose
        self._keep(motion)

    def _keep(self, motion: HeadMotion) -> None:
        """Forget the points ``motion`` no longer follows; lift its new ones at the current pose."""
        current = set(motion.ids.tolist())
        self._known = {i: p for i, p in self._known.items() if i in current}
        self._lift(np.asarray(motion.points, np.float64), motion.ids)

    def reset(self, pose: Pose, motion: HeadMotion) -> None:
        """Start again from ``pose`` on a new first frame (after the face was lost)."""
        self._frontal = self.pose = pose
        self._known.clear()
        self._lift(motion.points, motion.ids)
