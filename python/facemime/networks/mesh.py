"""Which of the Face Mesh's 468 landmarks mark facemime's reference points and contours.

The index lists of the eight contours are those of the shared data's README
(:data:`facemime.types.contours.FACE_MESH_INDICES`); the eye corners, nose tip and chin follow
the same numbering, and the face outline is the Face Mesh's face oval, clockwise on screen from
the top of the forehead like the model's ``face_outline``.
"""

from __future__ import annotations

import numpy as np

from facemime.types.contours import from_face_mesh

#: Single reference points -> Face Mesh index.
POINT_INDICES = {
    "eye_right_outer": 33,  # the subject's right eye: image left
    "eye_right_inner": 133,
    "eye_left_inner": 362,
    "eye_left_outer": 263,
    "eye_right_upper": 159,
    "eye_right_lower": 145,
    "eye_left_upper": 386,
    "eye_left_lower": 374,
    "nose_tip": 4,
    "chin": 152,
}
#: The face oval, clockwise on screen from the top of the forehead (open: it stops beside its
#: start, as the model's outline does).
FACE_OVAL = (
    10,
    338,
    297,
    332,
    284,
    251,
    389,
    356,
    454,
    323,
    361,
    288,
    397,
    365,
    379,
    378,
    400,
    377,
    152,
    148,
    176,
    149,
    150,
    136,
    172,
    58,
    132,
    93,
    234,
    127,
    162,
    21,
    54,
    103,
    67,
    109,
)


def reference_points(landmarks: np.ndarray) -> dict[str, np.ndarray]:
    """facemime's reference points (:mod:`facemime.types.points`) from one face's Face Mesh
    landmarks.

    Parameters
    ----------
    landmarks
        (468 or 478, 2+) float array: the landmarks, (x, y) pixels first.

    Returns
    -------
    dict of str -> (K, 2) float64 array
        Name -> (x, y) pixels: the single points of :data:`POINT_INDICES` (K = 1), the eight
        contours and ``face_outline``.

    Examples
    --------
    >>> points = reference_points(np.arange(478 * 2, dtype=float).reshape(478, 2))
    >>> points["nose_tip"].tolist(), len(points["face_outline"]), len(points)
    ([[8.0, 9.0]], 36, 19)
    """
    xy = np.asarray(landmarks, dtype=np.float64)[:, :2]
    points = {name: xy[[i]] for name, i in POINT_INDICES.items()}
    return points | from_face_mesh(xy) | {"face_outline": xy[list(FACE_OVAL)]}
