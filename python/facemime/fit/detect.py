"""Finding a face and its eyes with OpenCV's bundled Haar cascades (no model downloads).

Boxes are (x, y, w, h) in pixels of the image, x right, y down; eye centres are (x, y) pixels,
the image-left eye (the subject's right) first.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import cv2
import numpy as np

from facemime.errors import FacemimeError

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


class NoFaceError(FacemimeError, ValueError):
    """No frontal face was found in an image."""


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
        roi = (cv2.warpAffine(gray, turn, gray.shape[::-1]) if angle else gray)[top:bottom, x:x + w]
        back = cv2.invertAffineTransform(turn)
        for name in ("haarcascade_eye.xml", "haarcascade_eye_tree_eyeglasses.xml"):
            for ex, ey, ew, eh in _cascade(name).detectMultiScale(roi, 1.05, 3, minSize=(size, size), maxSize=(w // 3, w // 3)):
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
