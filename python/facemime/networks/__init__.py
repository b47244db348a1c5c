"""Finding human faces and their landmarks with MediaPipe's face detector and face landmark
model (shipped in ``models/``, run by OpenCV's ``cv2.dnn``): the automatic start of fitting and
tracking, and the tracker's re-detection; and the eyes' lids with its eye model
(:mod:`facemime.networks.eyelids`), for the blinks."""

from facemime.networks.detector import Detection, detect_faces
from facemime.networks.finder import FACE_SCORE, Face, find_face, follow_face
from facemime.networks.landmarks import Crop, crop_from_detection, crop_from_landmarks, landmark_pass
from facemime.networks.mesh import FACE_OVAL, POINT_INDICES, reference_points

__all__ = [
    "FACE_OVAL",
    "FACE_SCORE",
    "POINT_INDICES",
    "Crop",
    "Detection",
    "Face",
    "crop_from_detection",
    "crop_from_landmarks",
    "detect_faces",
    "find_face",
    "follow_face",
    "landmark_pass",
    "reference_points",
]
