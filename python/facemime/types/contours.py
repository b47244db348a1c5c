"""The eight tracked contours and the four features they form.

Contours are open curves ordered image-left to image-right (../data/README.md of the shared
data; the project's interchange format). "left"/"right" are the subject's own sides.
The upper and lower curves of each mouth contour share their two corner points.
"""

from __future__ import annotations

import numpy as np

from facemime.shared_constants import CONTOUR_GROUPS

#: The contours' names in the order of the interchange format: the head model's groups of the
#: same names, whose vertices are the knots.
CONTOUR_NAMES = CONTOUR_GROUPS

#: Feature name -> its (upper, lower) contours.
FEATURES = {
    "mouth_outer": ("mouth_outer_upper", "mouth_outer_lower"),
    "mouth_inner": ("mouth_inner_upper", "mouth_inner_lower"),
    "brow_left": ("brow_left_upper", "brow_left_lower"),
    "brow_right": ("brow_right_upper", "brow_right_lower"),
}

#: Reporting groups of the NME metric -> their contours.
GROUPS = {
    "mouth_outer": FEATURES["mouth_outer"],
    "mouth_inner": FEATURES["mouth_inner"],
    "brows": FEATURES["brow_left"] + FEATURES["brow_right"],
}

#: Edge polarity of each contour: the sign of the luma change going *down* across it
#: (-1: brighter above, darker below) and of the red-minus-green change.
POLARITY = {
    "mouth_outer_upper": (-1.0, +1.0),  # skin above, darker and redder lip below
    "mouth_outer_lower": (+1.0, -1.0),  # redder lip above, brighter skin below
    "mouth_inner_upper": (-1.0, -1.0),  # lip above, dark mouth opening / lip line below
    "mouth_inner_lower": (+1.0, +1.0),  # dark opening above, lip below
    "brow_left_upper": (-1.0, 0.0),  # skin above, dark brow below
    "brow_left_lower": (+1.0, 0.0),
    "brow_right_upper": (-1.0, 0.0),
    "brow_right_lower": (+1.0, 0.0),
}

#: MediaPipe Face Mesh (478-point) indices of each contour, image-left to image-right.
FACE_MESH_INDICES = {
    "mouth_outer_upper": (61, 185, 40, 39, 37, 0, 267, 269, 270, 409, 291),
    "mouth_outer_lower": (61, 146, 91, 181, 84, 17, 314, 405, 321, 375, 291),
    "mouth_inner_upper": (78, 191, 80, 81, 82, 13, 312, 311, 310, 415, 308),
    "mouth_inner_lower": (78, 95, 88, 178, 87, 14, 317, 402, 318, 324, 308),
    "brow_left_upper": (336, 296, 334, 293, 300),
    "brow_left_lower": (285, 295, 282, 283, 276),
    "brow_right_upper": (70, 63, 105, 66, 107),
    "brow_right_lower": (46, 53, 52, 65, 55),
}
#: Face Mesh indices of the outer eye corners (subject's right, subject's left): the IOD points.
FACE_MESH_IOD = (33, 263)


def from_face_mesh(landmarks: np.ndarray) -> dict[str, np.ndarray]:
    """The eight contours of one face's Face Mesh landmarks.

    Parameters
    ----------
    landmarks
        (478, 2 or 3) float array: the face's Face Mesh landmarks, (x, y) pixels first (a third
        column, depth, is ignored; the first 468 landmarks suffice).

    Returns
    -------
    dict of str -> (K, 2) float64 array
        Contour name (:data:`CONTOUR_NAMES` order) -> (x, y) pixels, image-left to image-right,
        11 points per mouth contour and 5 per brow contour.
    """
    pts = np.asarray(landmarks, dtype=np.float64)
    return {name: pts[list(idx), :2] for name, idx in FACE_MESH_INDICES.items()}
