"""The 468 Face Mesh landmarks of one face, from MediaPipe's face landmark model (192 x 192
input), run by OpenCV's ``cv2.dnn``.

The model sees a square crop of the face, turned so that the eyes are level. The first crop
comes from a detection (:mod:`facemime.networks.detector`: its box grown 1.5 times, turned by its
eye keypoints, as MediaPipe does); the next from the landmarks themselves (their extent along
and across the line of the outer eye corners, grown 1.5 times), which frames the face the way
the model was trained on.

Points are (x, y) pixels of the image, x right, y down, (0, 0) at the centre of the top-left
pixel; the third coordinate is the model's relative depth in the same pixel scale (smaller is
nearer the camera).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from facemime.networks.detector import Detection
from facemime.networks.network import load_network
from facemime.render.bilinear import sample_affine

#: Side of the landmark model's square input, pixels.
INPUT = 192
#: Landmarks the model gives.
POINTS = 468
#: A crop is this many times the face's extent (MediaPipe's setting for this model).
GROW = 1.5
#: Lowest face score (the model's face-presence output after the sigmoid) that counts as a face.
MIN_FACE_SCORE = 0.5
#: Outer eye corners, the subject's right (image left) first: they set a crop's turn.
EYE_AXIS = (33, 263)


@dataclass(frozen=True)
class Crop:
    """A square region of the image turned by ``angle``.

    Attributes
    ----------
    centre : (2,) float64 array
        (x, y) pixels.
    side : float
        Side length, pixels.
    angle : float
        Radians from the image's x axis to the crop's (clockwise on screen, as y is down): the
        direction of the line from the image-left eye to the image-right one.
    """

    centre: np.ndarray
    side: float
    angle: float

    def affine(self, size: int = INPUT) -> np.ndarray:
        """The affine map from the pixels of the crop, sampled square, to image pixels.

        Parameters
        ----------
        size
            Side of the sampled crop, pixels.

        Returns
        -------
        (2, 3) float64 array
            Maps pixel (u, v, 1) of the ``size`` x ``size`` crop to (x, y) image pixels.

        Examples
        --------
        >>> Crop(np.array([10.0, 20.0]), 4.0, 0.0).affine(4).round(6) + 0.0
        array([[ 1. ,  0. ,  8.5],
               [ 0. ,  1. , 18.5]])
        """
        c, s = np.cos(self.angle), np.sin(self.angle)
        axes = np.array([[c, -s], [s, c]]) * (self.side / size)  # columns: the crop's x and y in the image
        origin = self.centre + axes @ np.full(2, 0.5 - size / 2)  # where crop pixel (0, 0) lies
        return np.column_stack([axes, origin])

    def sample(self, rgb: np.ndarray, size: int = INPUT) -> np.ndarray:
        """The crop of an image as a square image, bilinear, edges replicated beyond the image.

        Parameters
        ----------
        rgb
            (H, W, 3) uint8 RGB image.
        size
            Side of the result, pixels.

        Returns
        -------
        (size, size, 3) uint8 array
            The crop, RGB, turned so that its x axis lies along ``angle``.
        """
        return sample_affine(rgb, self.affine(size), (size, size))


def crop_from_detection(detection: Detection) -> Crop:
    """The landmark model's crop around a detected face: the box's centre, its larger side
    grown :data:`GROW` times, turned by the eye keypoints.

    Parameters
    ----------
    detection
        The face, in image pixels.

    Returns
    -------
    Crop
        The crop, in image pixels.
    """
    eyes = detection.keypoints[1] - detection.keypoints[0]
    centre = (detection.box[:2] + detection.box[2:]) / 2
    return Crop(centre, GROW * detection.size, float(np.arctan2(eyes[1], eyes[0])))


def crop_from_landmarks(points: np.ndarray) -> Crop:
    """The crop that frames a face's landmarks: turned by the outer eye corners, centred on the
    points' extent along and across that line, its side the larger extent grown :data:`GROW`
    times.

    Parameters
    ----------
    points
        (468, 2+) float array: Face Mesh landmarks, (x, y) pixels first.

    Returns
    -------
    Crop
        The crop, in image pixels.

    Examples
    --------
    >>> p = np.zeros((468, 2)); p[EYE_AXIS[1]] = [40.0, 0.0]; p[0] = [0, 60]
    >>> crop = crop_from_landmarks(p)
    >>> crop.centre.tolist(), crop.side, crop.angle
    ([20.0, 30.0], 90.0, 0.0)
    """
    xy = np.asarray(points, np.float64)[:, :2]
    eyes = xy[EYE_AXIS[1]] - xy[EYE_AXIS[0]]
    angle = float(np.arctan2(eyes[1], eyes[0]))
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    local = xy @ rot  # coordinates along and across the eye line
    lo, hi = local.min(axis=0), local.max(axis=0)
    return Crop(rot @ ((lo + hi) / 2), GROW * float((hi - lo).max()), angle)


def landmark_pass(rgb: np.ndarray, crop: Crop) -> tuple[np.ndarray, float]:
    """One pass of the landmark model on a crop of an image.

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image.
    crop
        The region of ``rgb`` the model sees.

    Returns
    -------
    landmarks : (468, 3) float64 array
        (x, y) image pixels and the relative depth in the same scale (smaller is nearer).
    score : float
        The face score, 0..1; below :data:`MIN_FACE_SCORE` the crop holds no face.
    """
    net = load_network("face_landmark.tflite")
    net.setInput(cv2.dnn.blobFromImage(crop.sample(rgb), 1.0 / 255.0))  # the model takes [0, 1]
    score, raw = net.forward(["conv2d_31", "conv2d_21"])
    local = raw.reshape(POINTS, 3).astype(np.float64)
    affine = crop.affine()
    # model outputs are input-pixel edges (0..192): centres are half a pixel less
    xy = (local[:, :2] - 0.5) @ affine[:, :2].T + affine[:, 2]
    z = local[:, 2] * crop.side / INPUT
    return np.column_stack([xy, z]), float(1.0 / (1.0 + np.exp(-float(score.ravel()[0]))))
