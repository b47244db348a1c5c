"""Reference points found automatically on a frontal face photo, offline.

1. OpenCV's Haar cascades find the largest face and its eyes (:mod:`facemime.fit.detect`).
2. The generic head is placed on the eye centres (rotation, uniform scale, translation).
3. Each brow and the lips are slid and scaled to where the image contrast puts them
   (:func:`facemime.track.match.locate`): brows darker than the skin around them, lips
   redder.
4. The mouth and brow curves settle on their edges with the tracker's snakes.
5. Each half of the mouth is stretched along the line through its corners so that the corner
   ends where the lip-coloured region does (:func:`lip_ends`): the lips' outline placed as a
   whole, and the snakes, whose corners hold no edge of their own, can leave a corner on the
   cheek.

Points are (x, y) pixels of the photo (origin at the centre of the top-left pixel, y down).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from facemime import _core
from facemime.fit.detect import FaceDetection, detect_face
from facemime.fit.placement import frontal_pose, model_eye_centres, model_iod
from facemime.fit.points import GROUPS, ReferencePoints, model_chain
from facemime.model.head import HeadModel, generic_head
from facemime.render.projection import project
from facemime.track.contours import CONTOUR_NAMES
from facemime.track.lips import lip_colour
from facemime.track.match import locate
from facemime.track.tracker import Tracker, TrackerParams

#: Search settings per feature, in units of the inter-ocular distance (outer eye corners):
#: reach (x, y), surrounding band width, scales tried.
BROW_SEARCH = ((0.06, 0.12), 0.05, (0.85, 0.92, 1.0, 1.08, 1.16))
MOUTH_SEARCH = ((0.06, 0.12), 0.06, (0.9, 1.0, 1.1))
#: Snake passes that settle the mouth and brow curves on the image edges.
SETTLE_PASSES = 4
#: A mouth corner is the mean of the lip-coloured pixels within this fraction of the IOD of the
#: region's end along the mouth's line (:func:`lip_ends`). Each half of the mouth is stretched
#: to it by at most ``CORNER_STRETCH`` of its length; a farther end is not the lips' and the
#: half stays. On the shared videos' first frames the outer corners moved from 0.073 IOD (lp_d3,
#: right) and 0.053 (lp_d6, right) off the reference to 0.009 and 0.018 (vr_1's and vr_2's
#: lip colour does not separate from the skin: they keep theirs), and 48 noisy automatic starts
#: of lp_d3 stopped losing the mouth onto the jaw as her head turns (outer-mouth failures
#: 2.51% → 0%).
CORNER_TIP = 0.02
CORNER_STRETCH = 0.25


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
    points.update(stretch_to_lips(rgb, points, iod))
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


def lip_ends(rgb: np.ndarray, points: ReferencePoints, iod: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The two ends, (2,) px each, along the line through the outer mouth corners of
    ``points``, of the lip-coloured region that holds most of the outer mouth; each end is the
    mean of the region's pixels within :data:`CORNER_TIP` · ``iod`` px of its extreme. The
    region: pixels of an (H, W, 3) uint8 RGB photo, within half a mouth width of the mouth's
    box, where the lip score (:func:`facemime.track.lips.lip_colour`, fitted on the mouth
    curves of ``points``), smoothed by a Gaussian of 1% of the IOD, is positive; 8-connected.
    None where lips and skin do not separate by colour or no lip pixel lies in the mouth."""
    colour = lip_colour(rgb, points)
    if colour is None:
        return None
    upper, lower = points["mouth_outer_upper"], points["mouth_outer_lower"]
    left, right = upper[0], upper[-1]
    half = 0.5 * float(np.linalg.norm(right - left))
    h, w = rgb.shape[:2]
    x0, y0 = np.maximum(np.floor(np.minimum(left, right) - half).astype(int), 0)
    x1, y1 = np.minimum(np.ceil(np.maximum(left, right) + half).astype(int) + 1, (w, h))
    score = _core.lip_score_map(np.ascontiguousarray(rgb), colour, (int(x0), int(y0), int(x1), int(y1)))
    lips = (cv2.GaussianBlur(score, (0, 0), max(1.0, 0.01 * iod)) > 0).astype(np.uint8)
    count, labels = cv2.connectedComponents(lips, connectivity=8)
    mouth = np.zeros_like(lips)
    cv2.fillPoly(mouth, [np.round(np.concatenate([upper, lower[::-1]]) - (x0, y0)).astype(np.int32)], 1)
    held = np.bincount(labels[(mouth == 1) & (lips == 1)], minlength=count)
    held[0] = 0
    if held.max() == 0:
        return None
    ys, xs = np.nonzero(labels == int(np.argmax(held)))
    region = np.stack([xs + x0, ys + y0], axis=1).astype(np.float64)
    along = (region - left) @ ((right - left) / (2.0 * half))
    tip = CORNER_TIP * iod
    return region[along <= along.min() + tip].mean(axis=0), region[along >= along.max() - tip].mean(axis=0)


def stretch_to_lips(rgb: np.ndarray, points: ReferencePoints, iod: float) -> ReferencePoints:
    """The four mouth curves of ``points``, each half of the mouth (either side of the middle
    of its outer corners) stretched along the line through them so that its outer corner lies
    across from its end of the lips (:func:`lip_ends`; a half stays where that would stretch it
    by more than :data:`CORNER_STRETCH`, or all where the ends are not found)."""
    mouth = {n: points[n] for n in CONTOUR_NAMES[:4]}
    ends = lip_ends(rgb, points, iod)
    if ends is None:
        return mouth
    left, right = points["mouth_outer_upper"][[0, -1]]
    centre, half = 0.5 * (left + right), 0.5 * float(np.linalg.norm(right - left))
    axis = (right - left) / (2.0 * half)
    factors = [float((end - centre) @ axis) / (sign * half) for end, sign in zip(ends, (-1.0, 1.0))]
    factors = [f if abs(f - 1.0) <= CORNER_STRETCH else 1.0 for f in factors]
    out = {}
    for name, curve in mouth.items():
        t = (curve - centre) @ axis
        out[name] = curve + ((np.where(t < 0, factors[0], factors[1]) - 1.0) * t)[:, None] * axis
    return out
