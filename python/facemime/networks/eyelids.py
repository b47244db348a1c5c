"""Each eye's lids from MediaPipe's iris landmark model (64 x 64 input), run by OpenCV's
``cv2.dnn``: a finer look at an eye than the 468 Face Mesh landmarks give, whose lids are coarse
(they read a shut eye half shut).

The model sees a square crop of one eye, centred between its corners (Face Mesh points 33 and
133 for the subject's right eye, 362 and 263 for the left), turned along the line between them,
its side :data:`GROW` times their distance (MediaPipe's setting). It was trained on the subject's
right eye (the image-left one): the left eye's crop is mirrored. Of the 71 eye points it gives,
the first 16 are the lids' rims: the lower lid corner to corner (0 to 8), then the upper lid
between the corners (9 to 15); 4 and 12 are the lids' middles (Face Mesh points 145 and 159, and
374 and 386 for the left eye).

Points are (x, y) pixels of the image, x right, y down, (0, 0) at the centre of the top-left
pixel.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from facemime.networks.landmarks import Crop
from facemime.networks.network import load_network

#: Side of the model's square input, pixels.
INPUT = 64
#: A crop's side over the distance between the eye's corners.
GROW = 2.3
#: Face Mesh points of each eye's corners, the subject's right eye first; each pair image-left
#: corner first.
CORNERS = ((33, 133), (362, 263))
#: The lids' rims among the model's eye points: the lower lid corner to corner, then the upper
#: lid between the corners.
RIM = 16
# Among the rim's points: the corners, and the lower and upper lids' middles.
_ENDS = (0, 8)
_LOWER, _UPPER = 4, 12


def eye_crop(landmarks: np.ndarray, eye: int) -> Crop:
    """The model's crop of one eye.

    Parameters
    ----------
    landmarks
        (468, 2+) float array: the face's Face Mesh landmarks, (x, y) pixels first.
    eye
        0: the subject's right eye (image left); 1: the left eye.

    Returns
    -------
    Crop
        Centred between the eye's corners, turned along them, :data:`GROW` times their distance.

    Examples
    --------
    >>> p = np.zeros((468, 2)); p[33] = [10.0, 20.0]; p[133] = [30.0, 20.0]
    >>> crop = eye_crop(p, 0)
    >>> crop.centre.tolist(), round(crop.side, 6), crop.angle
    ([20.0, 20.0], 46.0, 0.0)
    """
    a, b = (np.asarray(landmarks, np.float64)[i, :2] for i in CORNERS[eye])
    d = b - a
    return Crop((a + b) / 2.0, GROW * float(np.hypot(*d)), float(np.arctan2(d[1], d[0])))


def eye_rims(rgb: np.ndarray, landmarks: np.ndarray, eyes: Sequence[int] = (0, 1)) -> np.ndarray:
    """Eyes' lid rims, by one pass of the model (the eyes in one batch).

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image.
    landmarks
        (468, 2+) float array: the face's Face Mesh landmarks in ``rgb``, (x, y) pixels first.
    eyes
        Which eyes: 0, the subject's right eye (image left); 1, the left eye.

    Returns
    -------
    (len(eyes), 16, 2) float64 array
        Per eye, the rims' points (:data:`RIM`), (x, y) image pixels: the lower lid from the outer
        corner to the inner, then the upper lid from the outer corner's side to the inner's.
    """
    crops = [eye_crop(landmarks, eye) for eye in eyes]
    # the model knows the subject's right eye: the left one is shown mirrored
    patches = [c.sample(rgb, INPUT)[:, :: -1 if eye == 1 else 1] for c, eye in zip(crops, eyes)]
    net = load_network("iris_landmark.tflite")
    net.setInput(cv2.dnn.blobFromImages(patches, 1.0 / 255.0))  # the model takes [0, 1]
    (points,) = net.forward(["output_eyes_contours_and_brows"])
    local = points.reshape(len(crops), -1, 3)[:, :RIM, :2].astype(np.float64)  # input-pixel edges (0..64)
    rims = np.empty_like(local)
    for k, (crop, eye) in enumerate(zip(crops, eyes)):
        if eye == 1:
            local[k, :, 0] = INPUT - local[k, :, 0]
        affine = crop.affine(INPUT)
        rims[k] = (local[k] - 0.5) @ affine[:, :2].T + affine[:, 2]
    return rims


def eye_openings(rgb: np.ndarray, landmarks: np.ndarray, eyes: Sequence[int] = (0, 1)) -> np.ndarray:
    """How open eyes are, by the model: the distance between each one's lids' middles over the
    distance between its corners.

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image.
    landmarks
        (468, 2+) float array: the face's Face Mesh landmarks in ``rgb``, (x, y) pixels first.
    eyes
        Which eyes: 0, the subject's right eye (image left); 1, the left eye.

    Returns
    -------
    (len(eyes),) float64 array
        Each opening over its eye's width (about 0.3 for an open eye, near 0 shut).
    """
    if not len(eyes):
        return np.zeros(0)
    rims = eye_rims(rgb, landmarks, eyes)
    width = np.linalg.norm(rims[:, _ENDS[1]] - rims[:, _ENDS[0]], axis=1)
    return np.linalg.norm(rims[:, _UPPER] - rims[:, _LOWER], axis=1) / np.maximum(width, 1e-9)
