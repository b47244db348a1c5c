"""Finding a human face and its landmarks in an image: detection, then two landmark passes.

The largest detected face is taken. Its landmarks are measured on the detection's crop, then
again on the crop those landmarks frame (:func:`facemime.networks.landmarks.crop_from_landmarks`),
and the two passes are averaged: on the ten shared videos' first frames and the seven shared
photos, the mean of the two was closer to the reference than either pass alone or a third pass
(mean NME of the eye corners / outer lips / inner lips / brows 0.0165 / 0.0115 / 0.0104 / 0.0116
against 0.0173 / 0.0120 / 0.0116 / 0.0118 for the first pass alone; worst image 0.029 / 0.023 /
0.019 / 0.029).

Points are (x, y) pixels, x right, y down, (0, 0) at the centre of the top-left pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facemime.errors import NoFaceError
from facemime.networks.detector import Detection, detect_faces
from facemime.networks.landmarks import MIN_FACE_SCORE, crop_from_detection, crop_from_landmarks, landmark_pass

#: Lowest detection score of a human face. MediaPipe keeps detections from 0.5, which takes the
#: shared photos of a monkey (0.78) and a dog (0.75) for faces (the landmark model then scores
#: them as faces too: 1.00 and 0.69). Human faces scored 0.83 to 0.97: every third frame of the
#: ten shared videos (lowest on lp_d12's blurred, turning head), the seven shared photos
#: (paintings, a cartoon and old prints included) 0.93 to 0.97.
FACE_SCORE = 0.8
#: Another face counts (for the several-faces warning) when at least this fraction of the
#: chosen face's size.
MIN_OTHER_FACE = 0.4


@dataclass(frozen=True)
class Face:
    """A face found in an image.

    Attributes
    ----------
    landmarks : (468, 3) float64 array
        Face Mesh landmarks, (x, y) pixels and relative depth in the same scale.
    detection : Detection
        The detection the face was found from.
    faces : int
        How many faces were detected (at least :data:`MIN_OTHER_FACE` of this one's size).
    """

    landmarks: np.ndarray
    detection: Detection
    faces: int = 1

    @property
    def iod(self) -> float:
        """Distance between the outer eye corners (Face Mesh 33 and 263), pixels."""
        return float(np.linalg.norm(self.landmarks[33, :2] - self.landmarks[263, :2]))


def find_face(rgb: np.ndarray, min_score: float = FACE_SCORE) -> Face:
    """The largest human face of an image and its landmarks.

    The detections are tried largest first; the first whose crop the landmark model scores as a
    face is taken. Raises :class:`facemime.errors.NoFaceError` when no face scores ``min_score``
    or more.

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image.
    min_score
        Lowest detection score of a face, 0..1.

    Returns
    -------
    Face
        The face: its (468, 3) landmarks in pixels of ``rgb`` (the mean of the two passes, or
        the first alone where the second finds no face), its detection and how many faces were
        detected (at least :data:`MIN_OTHER_FACE` of its size).
    """
    detections = detect_faces(rgb, min_score)
    for detection in sorted(detections, key=lambda d: -d.size):
        first, score = landmark_pass(rgb, crop_from_detection(detection))
        if score < MIN_FACE_SCORE:
            continue
        second, score = landmark_pass(rgb, crop_from_landmarks(first))
        points = (first + second) / 2 if score >= MIN_FACE_SCORE else first
        others = sum(d.size >= MIN_OTHER_FACE * detection.size for d in detections)
        return Face(points, detection, max(1, others))
    raise NoFaceError("no face found")


def follow_face(rgb: np.ndarray, previous: np.ndarray) -> np.ndarray | None:
    """The landmarks of a face found in an earlier frame, measured on the crop its landmarks
    frame in this one (one landmark pass, no detection).

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image: the frame.
    previous
        (468, 2+) float array: the face's landmarks in an earlier frame, (x, y) pixels first.

    Returns
    -------
    (468, 3) float64 array or None
        The landmarks, (x, y) pixels of ``rgb`` and relative depth in the same scale; None when
        the crop holds no face.
    """
    points, score = landmark_pass(rgb, crop_from_landmarks(previous))
    return points if score >= MIN_FACE_SCORE else None
