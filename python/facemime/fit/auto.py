"""Reference points found automatically on a frontal face photo, offline.

1. OpenCV's Haar cascades find the largest face and its eyes (:mod:`facemime.fit.detect`).
2. The generic head is placed on the eye centres (rotation, uniform scale, translation).
3. Each brow and the lips are slid and scaled to where the image contrast puts them
   (:func:`facemime.track.match.locate`): brows darker than the skin around them, lips
   redder.
4. The mouth and brow curves settle on their edges with the tracker's snakes.

Points are (x, y) pixels of the photo (origin at the centre of the top-left pixel, y down).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from facemime.fit.detect import FaceDetection, detect_face
from facemime.fit.placement import frontal_pose, model_eye_centres, model_iod
from facemime.fit.points import GROUPS, ReferencePoints, model_chain
from facemime.model.head import HeadModel, generic_head
from facemime.render.projection import project
from facemime.track.contours import CONTOUR_NAMES
from facemime.track.match import locate
from facemime.track.tracker import Tracker, TrackerParams

#: Search settings per feature, in units of the inter-ocular distance (outer eye corners):
#: reach (x, y), surrounding band width, scales tried.
BROW_SEARCH = ((0.06, 0.12), 0.05, (0.85, 0.92, 1.0, 1.08, 1.16))
MOUTH_SEARCH = ((0.06, 0.12), 0.06, (0.9, 1.0, 1.1))
#: Snake passes that settle the mouth and brow curves on the image edges.
SETTLE_PASSES = 4


@dataclass(frozen=True)
class AutoPoints:
    """Automatic reference points and how they were found."""

    points: ReferencePoints
    detection: FaceDetection


def lip_channel(rgb: np.ndarray) -> np.ndarray:
    """How lip-like each pixel is, (H, W) float32: CIELAB a* (green to red) minus half the
    lightness L*, as lips are redder *and* darker than the skin around them. (Measured on the
    six shared videos: R - G or a* alone let the search slide onto a reddish chin.)"""
    lab = cv2.cvtColor(rgb, cv2.COLOR_RGB2LAB).astype(np.float32)
    return lab[..., 1] - 0.5 * lab[..., 0]


def _polygon(p: np.ndarray, model: HeadModel, upper: str, lower: str) -> np.ndarray:
    return np.concatenate([p[model.groups[upper]], p[model.groups[lower]][::-1]])


def auto_points(rgb: np.ndarray, model: HeadModel | None = None) -> AutoPoints:
    """Reference points of the largest face in an (H, W, 3) uint8 RGB photo.

    Raises :class:`facemime.fit.detect.NoFaceError` when no face is found.
    """
    model = model or generic_head()
    det = detect_face(rgb)
    g = model.groups
    pose = frontal_pose(model_eye_centres(model), det.eyes)
    p = project(model.vertices, pose)[0]
    iod = pose.scale * model_iod(model)

    blur = max(0.6, 0.01 * iod)
    dark = -cv2.GaussianBlur(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float32), (0, 0), blur)
    red = cv2.GaussianBlur(lip_channel(rgb), (0, 0), blur)

    def place(channel: np.ndarray, poly: np.ndarray, search: tuple, *others: np.ndarray) -> list[np.ndarray]:
        (rx, ry), band, scales = search
        found = locate(channel, poly, (rx * iod, ry * iod), max(2.0, band * iod), scales)
        return [found.apply(q, poly.mean(axis=0)) for q in (poly, *others)]

    points: ReferencePoints = {n: p[model_chain(model, n)] for n in GROUPS["eye_corners"]}
    for side in ("left", "right"):
        up, low = f"brow_{side}_upper", f"brow_{side}_lower"
        _, points[up], points[low] = place(dark, _polygon(p, model, up, low), BROW_SEARCH, p[g[up]], p[g[low]])
    outer = _polygon(p, model, "mouth_outer_upper", "mouth_outer_lower")
    moved = place(red, outer, MOUTH_SEARCH, *(p[g[n]] for n in CONTOUR_NAMES[:4]))
    for name, curve in zip(CONTOUR_NAMES[:4], moved[1:]):
        points[name] = curve
    mouth_shift = moved[1].mean(axis=0) - p[g["mouth_outer_upper"]].mean(axis=0)
    points["nose_tip"] = p[g["nose"][[6]]]
    points["chin"] = p[g["face_outline"][[9]]] + mouth_shift
    points.update(settle(rgb, points))
    h, w = rgb.shape[:2]
    for name in points:
        points[name] = np.clip(points[name], -0.5, [w - 0.5, h - 0.5])
    return AutoPoints(points, det)


def settle(rgb: np.ndarray, points: ReferencePoints) -> ReferencePoints:
    """The mouth and brow curves of ``points`` moved onto the image edges by the snakes."""
    h, w = rgb.shape[:2]
    contours = {n: np.clip(points[n], 0.0, [w - 1.0, h - 1.0]) for n in CONTOUR_NAMES}
    tracker = Tracker(rgb, contours, TrackerParams(calibration_passes=SETTLE_PASSES, motion=False))
    return tracker.edges
