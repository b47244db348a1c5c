"""``facemime.points/1`` files: reference points of a frontal face, marked by hand or by a tool.

``{"format": "facemime.points/1", "points": {"eye_right_outer": [x, y], ...,
"mouth_outer_upper": [[x, y], ...], ...}}`` — names and required ones in
:mod:`facemime.types.points`; (x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

from pathlib import Path

from facemime.errors import InvalidInputError
from facemime.io.contours_json import ContourFileError, load_document
from facemime.types.points import ReferencePoints, check_points

POINTS_FORMAT = "facemime.points/1"


def read_points(path: str | Path, size: tuple[int, int]) -> ReferencePoints:
    """Read and validate a ``facemime.points/1`` file.

    Parameters
    ----------
    path
        The points file.
    size
        (width, height) of the image the points are on, pixels: every point must lie inside it.

    Returns
    -------
    ReferencePoints
        Name -> (K, 2) float64 array of (x, y) pixels (K = 1 for a single point); an invalid file
        raises :class:`ContourFileError`.
    """
    doc = load_document(path, "points", POINTS_FORMAT)
    try:
        return check_points(doc.get("points"), *size, where=str(path))
    except InvalidInputError as e:
        raise ContourFileError(str(e)) from None
