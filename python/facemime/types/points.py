"""Reference points of a frontal face: the named points and curves the model is fitted to.

Points are (x, y) pixels of the photo, x right, y down, (0, 0) at the centre of the top-left
pixel. Each name maps to a chain of generic-head vertices (``model_chain``): a single point is a
chain of one vertex, a curve is ordered like the model group of the same name (image-left to
image-right for the mouth and brow curves of :data:`facemime.types.contours.CONTOUR_NAMES`, clockwise
from the forehead top for ``face_outline``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facemime.errors import InvalidInputError
from facemime.types.contours import CONTOUR_NAMES
from facemime.types.head import HeadModel

#: Single points -> (model group, position in the group).
POINTS = {
    "eye_right_outer": ("eye_right", 0),  # subject's right eye: image left
    "eye_right_inner": ("eye_right", 4),
    "eye_left_inner": ("eye_left", 0),
    "eye_left_outer": ("eye_left", 4),
    "eye_right_upper": ("eye_right", 2),  # the middle of each upper and lower lid
    "eye_right_lower": ("eye_right", 6),
    "eye_left_upper": ("eye_left", 2),
    "eye_left_lower": ("eye_left", 6),
    "nose_tip": ("nose", 6),
    "chin": ("face_outline", 9),
}
#: Curves, named like the model groups they follow.
CURVES = CONTOUR_NAMES + ("face_outline",)
#: Points that move with the face's expression: the elastic adjustment follows them, the
#: placement does not.
LIDS = ("eye_right_upper", "eye_right_lower", "eye_left_upper", "eye_left_lower")
#: Every name a reference-point set may hold.
NAMES = tuple(POINTS) + CURVES
#: Names a set must hold: enough to place and scale the model.
REQUIRED = (
    "eye_right_outer",
    "eye_right_inner",
    "eye_left_inner",
    "eye_left_outer",
    "mouth_outer_upper",
    "mouth_outer_lower",
)
#: The point groups accuracy is reported for (README of the shared data): name -> members.
GROUPS = {
    "eye_corners": ("eye_right_outer", "eye_right_inner", "eye_left_inner", "eye_left_outer"),
    "brows": ("brow_left_upper", "brow_left_lower", "brow_right_upper", "brow_right_lower"),
    "mouth": CONTOUR_NAMES[:4],
}

#: The least distance between the outer eye corners, px: closer, the points mark no face to fit.
MIN_EYE_DISTANCE = 8.0

ReferencePoints = dict[str, np.ndarray]


def model_chain(model: HeadModel, name: str) -> np.ndarray:
    """The model vertex indices a reference point or curve marks.

    Parameters
    ----------
    model
        The head; it needs the groups the name maps to.
    name
        A reference point or curve name (:data:`NAMES`).

    Returns
    -------
    (K,) int64 array
        One index for a single point, the group's ordered indices for a curve.
    """
    if name in POINTS:
        group, at = POINTS[name]
        return model.groups[group][[at]]
    if name in CURVES:
        return model.groups[name]
    raise InvalidInputError(f"unknown reference point {name!r}; known: {', '.join(NAMES)}")


def check_points(points: object, width: int, height: int, where: str = "points") -> ReferencePoints:
    """Validate a reference-point set for an image: known names, the required ones present,
    single points as (2,) or (1, 2), curves as (K >= 2, 2), all inside the image, the outer eye
    corners at least :data:`MIN_EYE_DISTANCE` pixels apart.

    Parameters
    ----------
    points
        Name -> [x, y] pixels or a list of them (e.g. a parsed JSON object).
    width
        The image's width, pixels.
    height
        The image's height, pixels.
    where
        Names the points in error messages.

    Returns
    -------
    dict of str -> (K, 2) float64 array
        Name -> (x, y) pixels, K = 1 for a single point.
    """
    if not isinstance(points, Mapping):
        raise InvalidInputError(f"{where} must map point names to [x, y] positions, got {type(points).__name__}")
    unknown = [n for n in points if n not in NAMES]
    if unknown:
        raise InvalidInputError(f"{where}: unknown point {', '.join(map(str, unknown))}; known: {', '.join(NAMES)}")
    missing = [n for n in REQUIRED if n not in points]
    if missing:
        raise InvalidInputError(f"{where}: missing {', '.join(missing)}")
    out: ReferencePoints = {}
    for name, raw in points.items():
        try:
            arr = np.atleast_2d(np.asarray(raw, dtype=np.float64))
        except (TypeError, ValueError, OverflowError):
            arr = np.empty((0, 0))
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) == 0 or not np.isfinite(arr).all():
            raise InvalidInputError(f"{where}: {name} must be [x, y] numbers or a list of them")
        if name in POINTS and len(arr) != 1:
            raise InvalidInputError(f"{where}: {name} is a single point [x, y], got {len(arr)} points")
        if name in CURVES and len(arr) < 2:
            raise InvalidInputError(f"{where}: {name} is a curve and needs at least 2 points, got {len(arr)}")
        if (arr < -0.5).any() or (arr[:, 0] > width - 0.5).any() or (arr[:, 1] > height - 0.5).any():
            raise InvalidInputError(f"{where}: {name} has points outside the {width}x{height} image")
        out[name] = arr
    iod = float(np.linalg.norm(out["eye_right_outer"][0] - out["eye_left_outer"][0]))
    if iod < MIN_EYE_DISTANCE:
        raise InvalidInputError(
            f"{where}: the outer eye corners are {iod:.1f} px apart; a face needs at least {MIN_EYE_DISTANCE:g}"
        )
    return out
