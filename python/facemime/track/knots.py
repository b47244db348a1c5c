"""What a tracker is given and gives back: the checks of a start frame and its contours, the
shared knot array the eight curves are laid out on, and one frame's result. (x, y) pixels, origin
at the centre of the top-left pixel, y down."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from facemime import validate
from facemime.errors import InvalidInputError
from facemime.metrics import resample
from facemime.track.params import TrackerParams
from facemime.types.contours import CONTOUR_NAMES, FEATURES


@dataclass
class FrameResult:
    """One frame's output: ``contours`` name -> (N, 2) float64 pixels; ``confidence`` feature ->
    0..1; ``lost`` features flagged in this frame (a lost brow is reported where the brow search
    matched it, or else on its rest shape);
    ``iterations`` the solver ran; ``motion_ok`` whether the head motion was measured;
    ``redetected`` whether the face landmark model put the contours right on this frame
    (:class:`facemime.track.redetect.FaceTracker`)."""

    index: int
    contours: dict[str, np.ndarray]
    confidence: dict[str, float]
    lost: list[str] = field(default_factory=list)
    iterations: int = 0
    motion_ok: bool = True
    redetected: bool = False

    @property
    def face(self) -> bool:
        """Whether the face is still held: its head motion measured and not every feature lost."""
        return self.motion_ok and len(self.lost) < len(FEATURES)


def layout(contours: Mapping[str, np.ndarray], params: TrackerParams) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Shared knot array and each contour's knot indices; mouth corners are shared.

    Features are laid out in the order of :data:`~facemime.types.contours.FEATURES`, each upper
    curve then its lower one. A mouth's two corners are single knots, at the mean of its upper
    and lower curves' ends.

    Parameters
    ----------
    contours
        Contour name -> (N, 2) float array, (x, y) pixels; all eight contours of
        :data:`~facemime.types.contours.FEATURES`.
    params
        The tracker's settings: ``mouth_knots`` and ``brow_knots`` resample each curve to that
        many knots equally spaced in arc length (None: the contour's own points, or the longer
        curve's count where a feature's upper and lower curves differ).

    Returns
    -------
    knots : (M, 2) float64 array
        Every knot, (x, y) pixels.
    index : dict of str -> (n,) int array
        Contour name -> the indices into ``knots`` of its knots, in the contour's order.
    """
    knots: list[np.ndarray] = []
    index: dict[str, np.ndarray] = {}
    for feature, (up, low) in FEATURES.items():
        count = params.mouth_knots if feature.startswith("mouth") else params.brow_knots
        u, lo = (np.asarray(contours[n], np.float64) for n in (up, low))
        if count is None and len(u) != len(lo):
            count = max(len(u), len(lo))
        if count is not None:
            u, lo = resample(u, count), resample(lo, count)
        base = sum(len(k) for k in knots)
        if feature.startswith("mouth"):
            ends = (u[[0, -1]] + lo[[0, -1]]) / 2.0
            u, lo = u.copy(), lo.copy()
            u[[0, -1]] = ends
            knots += [u, lo[1:-1]]
            index[up] = np.arange(base, base + len(u))
            index[low] = np.concatenate([[base], np.arange(base + len(u), base + 2 * len(u) - 2), [base + len(u) - 1]])
        else:
            knots += [u, lo]
            index[up] = np.arange(base, base + len(u))
            index[low] = np.arange(base + len(u), base + 2 * len(u))
    return np.concatenate(knots), index


def check_contours(contours: Mapping[str, object], width: int, height: int) -> dict[str, np.ndarray]:
    """Check a start frame's contours: all eight present, each of finite points inside the image.

    Parameters
    ----------
    contours
        Contour name -> (N, 2) points, (x, y) pixels; N at least 2, each point within the
        image's outer pixel edges (-0.5 to ``width`` - 0.5 and ``height`` - 0.5).
    width
        Width of the image, pixels.
    height
        Height of the image, pixels.

    Returns
    -------
    dict of str -> (N, 2) float64 array
        The eight contours of :data:`~facemime.types.contours.CONTOUR_NAMES`, in that order, as
        C-contiguous float64 (other entries left out).
    """
    if not isinstance(contours, Mapping):
        raise InvalidInputError(
            f"contours must be a mapping of contour name to (N, 2) points, got {type(contours).__name__}"
        )
    missing = [n for n in CONTOUR_NAMES if n not in contours]
    if missing:
        raise InvalidInputError(f"contours lack {', '.join(missing)}")
    out = {}
    for n in CONTOUR_NAMES:
        pts = validate.float_array(f"contour {n}", contours[n], (None, 2))
        if len(pts) < 2:
            raise InvalidInputError(f"contour {n} needs at least 2 points, got {len(pts)}")
        if (pts < -0.5).any() or (pts[:, 0] > width - 0.5).any() or (pts[:, 1] > height - 0.5).any():
            raise InvalidInputError(f"contour {n} has points outside the {width}x{height} image")
        if np.hypot(*(pts[-1] - pts[0])) < 1.0:  # the features' directions come from their ends
            raise InvalidInputError(f"contour {n} ends where it starts: it must run across its feature, left to right")
        out[n] = pts
    return out


def rgb_frame(name: str, frame: object) -> np.ndarray:
    """Check that ``frame`` is an RGB image.

    Parameters
    ----------
    name
        What the frame is called in the error raised.
    frame
        The image: must be an (H, W, 3) uint8 numpy array.

    Returns
    -------
    (H, W, 3) uint8 array
        ``frame``, C-contiguous (a copy only where it was not).
    """
    img = validate.image(name, frame)
    if img.ndim != 3 or img.shape[2] != 3:
        raise InvalidInputError(f"{name} must be an (H, W, 3) RGB image, got shape {img.shape}")
    return img
