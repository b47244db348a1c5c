"""Reference points found automatically on a face photo, offline: the largest human face and its
Face Mesh landmarks (:func:`facemime.networks.find_face`), read as facemime's reference points
(:func:`facemime.networks.reference_points`).

The points are the landmark model's, not settled on the image edges: on the ten shared videos'
first frames and the seven shared photos, settling the mouth and brow curves with the tracker's
snakes took them further from the reference (mean brow NME 0.0116 -> 0.0191, mouth 0.0110 ->
0.0154); the tracker settles its own start and keeps the landmark convention
(:class:`facemime.track.Tracker`).

Points are (x, y) pixels of the photo (origin at the centre of the top-left pixel, y down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facemime.networks.finder import Face, find_face
from facemime.networks.mesh import reference_points
from facemime.types.points import ReferencePoints


@dataclass(frozen=True)
class AutoPoints:
    """Automatic reference points and the face they were found on."""

    points: ReferencePoints
    face: Face


def auto_points(rgb: np.ndarray) -> AutoPoints:
    """Reference points of the largest human face in a photo, clipped to the photo.

    Raises :class:`facemime.errors.NoFaceError` when no face is found.

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB photo.

    Returns
    -------
    AutoPoints
        The points, name -> (K, 2) float64 (x, y) pixels within the photo (-0.5 to W - 0.5,
        -0.5 to H - 0.5), and the face they were found on.
    """
    face = find_face(rgb)
    h, w = rgb.shape[:2]
    points = {n: np.clip(p, -0.5, [w - 0.5, h - 0.5]) for n, p in reference_points(face.landmarks).items()}
    return AutoPoints(points, face)
