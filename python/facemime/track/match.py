"""Finding a gray patch again near where it is expected: the normalised cross-correlation
(``cv2.matchTemplate``, TM_CCOEFF_NORMED) of a template over a window around the expected
position. It finds a lost brow again (:mod:`facemime.track.brows`) and follows the whole mouth
when the optical flow loses its knots (:mod:`facemime.track.mouth`). Coordinates are (x, y)
pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

import cv2
import numpy as np


def crop_box(points: np.ndarray, margin: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) integer (x, y) corners, ``hi`` exclusive: the box of ``points`` (N, 2) px grown
    by ``margin`` px, inside a ``width`` × ``height`` image."""
    lo = np.floor(points.min(axis=0) - margin).astype(int)
    hi = np.ceil(points.max(axis=0) + margin).astype(int) + 1
    return np.maximum(lo, 0), np.minimum(hi, [width, height])


def find(gray: np.ndarray, template: np.ndarray, centre: np.ndarray, reach: float, min_match: float) -> np.ndarray | None:
    """Where the centre of ``template`` ((h, w) uint8) matches ``gray`` ((H, W) uint8) best,
    (2,) px, searched within ± ``reach`` px of ``centre`` (x, y) px; None where the window does
    not hold the template or the best correlation is below ``min_match``."""
    th, tw = template.shape
    x0 = max(int(round(centre[0] - (tw - 1) / 2.0 - reach)), 0)
    y0 = max(int(round(centre[1] - (th - 1) / 2.0 - reach)), 0)
    x1 = min(int(round(centre[0] + (tw - 1) / 2.0 + reach)) + 1, gray.shape[1])
    y1 = min(int(round(centre[1] + (th - 1) / 2.0 + reach)) + 1, gray.shape[0])
    if x1 - x0 < tw or y1 - y0 < th:
        return None
    scores = cv2.matchTemplate(gray[y0:y1, x0:x1], template, cv2.TM_CCOEFF_NORMED)
    _, best, _, (bx, by) = cv2.minMaxLoc(scores)
    if not best >= min_match:
        return None
    return np.array([x0 + bx + (tw - 1) / 2.0, y0 + by + (th - 1) / 2.0])
