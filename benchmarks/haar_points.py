"""The automatic reference points facemime used before its face models, kept as the baseline of
``benchmarks/fit_points.py``: OpenCV's bundled Haar cascades find the largest face and its eyes,
the generic head is placed on the eyes, each brow and the lips are slid and scaled to where the
image contrast puts them (brows darker, lips redder: CIELAB a* - L*/2), and the mouth and brow
curves settle on their edges with the tracker's snakes.

Boxes are (x, y, w, h) pixels; points are (x, y) pixels (origin at the centre of the top-left
pixel, y down).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import cv2
import numpy as np

from facemime.errors import FacemimeError, NoFaceError
from facemime.fit.adjust import frontal_pose
from facemime.head.generic import generic_head
from facemime.track.params import TrackerParams
from facemime.track.template import locate
from facemime.track.tracker import Tracker
from facemime.types.contours import CONTOUR_NAMES
from facemime.types.head import HeadModel, model_eye_centres, model_iod
from facemime.types.points import GROUPS, ReferencePoints, model_chain
from facemime.types.pose import project

#: Another face counts (for the several-faces warning) when at least this fraction of the
#: chosen face's width.
MIN_OTHER_FACE = 0.4
#: Where the eye centres sit in a frontal-face box of the default cascade, as fractions of the
#: box width (measured on the first frames of the six shared videos: 0.32-0.36, 0.65-0.71 across,
#: 0.33-0.43 down).
EYE_PRIOR = np.array([[0.335, 0.395], [0.665, 0.395]])
#: An eye cascade hit further than this (fraction of the box width) from the prior is ignored.
EYE_REACH = 0.12
#: Turns of the face (degrees) the eye cascades are run at.
EYE_ANGLES = (0.0, -8.0, 8.0, -14.0, 14.0)
#: Hits closer than this (fraction of the box width) count as the same eye.
EYE_CLUSTER = 0.05
#: Plausible distance between the eye centres, fractions of the box width.
EYE_GAP = (0.26, 0.52)


@dataclass(frozen=True)
class FaceDetection:
    """The face chosen in an image.

    Attributes
    ----------
    box : (4,) int array
        (x, y, w, h) of the largest frontal face, pixels.
    faces : int
        How many faces were found (the largest is used; hits under MIN_OTHER_FACE of its
        width are not counted).
    eyes : (2, 2) float64 array
        Eye centres, (x, y) pixels, image-left eye first.
    eyes_found : bool
        Whether the eye cascades found both eyes (else the eyes come from the box).
    """

    box: np.ndarray
    faces: int
    eyes: np.ndarray
    eyes_found: bool


@cache
def _cascade(name: str) -> cv2.CascadeClassifier:
    c = cv2.CascadeClassifier(cv2.data.haarcascades + name)
    if c.empty():  # the installed OpenCV lacks its bundled cascades
        raise FacemimeError(f"OpenCV's cascade file {name} is missing; install opencv-python-headless 4.x")
    return c


def detect_face(rgb: np.ndarray) -> FaceDetection:
    """The largest frontal face of an (H, W, 3) uint8 RGB image and its two eye centres.

    Raises :class:`NoFaceError` when no face is found.
    """
    gray = cv2.equalizeHist(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
    smallest = max(24, min(gray.shape) // 10)
    faces: np.ndarray = np.empty((0, 4), int)
    for name in ("haarcascade_frontalface_default.xml", "haarcascade_frontalface_alt2.xml"):
        found = _cascade(name).detectMultiScale(gray, 1.1, 5, minSize=(smallest, smallest))
        faces = _distinct(np.asarray(found, int).reshape(-1, 4))
        if len(faces):
            break
    if not len(faces):
        raise NoFaceError("no face found")
    box = faces[np.argmax(faces[:, 2] * faces[:, 3])]
    eyes, found = _eyes(gray, box)
    count = int((faces[:, 2] >= MIN_OTHER_FACE * box[2]).sum())  # smaller hits are mostly false alarms
    return FaceDetection(box, count, eyes, found)


def _distinct(boxes: np.ndarray) -> np.ndarray:
    """Drop boxes whose centre lies inside a larger box (the cascade's nested hits)."""
    order = np.argsort(-(boxes[:, 2] * boxes[:, 3]))
    kept: list[np.ndarray] = []
    for b in boxes[order]:
        c = b[:2] + b[2:] / 2
        if not any((k[:2] <= c).all() and (c <= k[:2] + k[2:]).all() for k in kept):
            kept.append(b)
    return np.array(kept, int).reshape(-1, 4)


def _eyes(gray: np.ndarray, box: np.ndarray) -> tuple[np.ndarray, bool]:
    """Eye centres: the densest cluster of eye-cascade hits near each expected place, else the
    expected place in the box. The cascades miss tilted eyes, so the face is also searched
    turned by a few degrees and all hits are pooled."""
    x, y, w, h = (int(v) for v in box)
    prior = np.array([x, y]) + EYE_PRIOR * w
    top, bottom = y + int(0.15 * h), y + int(0.62 * h)
    size = max(8, w // 10)
    centre = (x + w / 2, y + h / 2)
    hits = []
    for angle in EYE_ANGLES:
        turn = cv2.getRotationMatrix2D(centre, angle, 1.0)
        roi = (cv2.warpAffine(gray, turn, gray.shape[::-1]) if angle else gray)[top:bottom, x : x + w]
        back = cv2.invertAffineTransform(turn)
        for name in ("haarcascade_eye.xml", "haarcascade_eye_tree_eyeglasses.xml"):
            for ex, ey, ew, eh in _cascade(name).detectMultiScale(
                roi, 1.05, 3, minSize=(size, size), maxSize=(w // 3, w // 3)
            ):
                hits.append(back[:, :2] @ (x + ex + ew / 2, top + ey + eh / 2) + back[:, 2])
    eyes, support = prior.copy(), np.zeros(2, int)
    pts = np.array(hits).reshape(-1, 2)
    for k in range(2):
        near = pts[np.linalg.norm(pts - prior[k], axis=1) < EYE_REACH * w]
        if len(near):
            close = np.linalg.norm(near[:, None] - near[None], axis=2) < EYE_CLUSTER * w
            best = int(np.argmax(close.sum(axis=1)))
            eyes[k], support[k] = np.median(near[close[best]], axis=0), close[best].sum()
    if not support.all() or not EYE_GAP[0] <= np.linalg.norm(eyes[1] - eyes[0]) / w <= EYE_GAP[1]:
        return prior, False  # one eye alone, or an implausible pair (a brow, a frame): trust the box
    return eyes, True


#: Search settings per feature, in units of the inter-ocular distance (outer eye corners):
#: reach (x, y), surrounding band width, scales tried.
BROW_SEARCH = ((0.06, 0.12), 0.05, (0.85, 0.92, 1.0, 1.08, 1.16))
MOUTH_SEARCH = ((0.06, 0.12), 0.06, (0.9, 1.0, 1.1))
#: Snake passes that settle the mouth and brow curves on the image edges.
SETTLE_PASSES = 4


def lip_channel(rgb: np.ndarray) -> np.ndarray:
    """How lip-like each pixel is, (H, W) float32: CIELAB a* (green to red) minus half the
    lightness L*, as lips are redder *and* darker than the skin around them. (Measured on the
    six shared videos: R - G or a* alone let the search slide onto a reddish chin.)"""
    lab = cv2.cvtColor(rgb, cv2.COLOR_RGB2LAB).astype(np.float32)
    return lab[..., 1] - 0.5 * lab[..., 0]


def _polygon(p: np.ndarray, model: HeadModel, upper: str, lower: str) -> np.ndarray:
    return np.concatenate([p[model.groups[upper]], p[model.groups[lower]][::-1]])


def haar_points(rgb: np.ndarray, model: HeadModel | None = None) -> tuple[ReferencePoints, FaceDetection]:
    """Reference points of the largest face in an (H, W, 3) uint8 RGB photo.

    Raises :class:`facemime.errors.NoFaceError` when no face is found.
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
    return points, det


def settle(rgb: np.ndarray, points: ReferencePoints) -> ReferencePoints:
    """The mouth and brow curves of ``points`` moved onto the image edges by the snakes."""
    h, w = rgb.shape[:2]
    contours = {n: np.clip(points[n], 0.0, [w - 1.0, h - 1.0]) for n in CONTOUR_NAMES}
    tracker = Tracker(rgb, contours, TrackerParams(calibration_passes=SETTLE_PASSES, motion=False))
    return tracker.edges
