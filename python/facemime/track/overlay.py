"""Drawing tracked contours over video frames (RGB uint8, pixel coordinates as everywhere)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import cv2
import numpy as np

from facemime.types.contours import FEATURES

#: Feature -> RGB colour of its curves.
COLOURS = {
    "mouth_outer": (255, 64, 64),
    "mouth_inner": (255, 220, 40),
    "brow_left": (60, 200, 255),
    "brow_right": (60, 255, 120),
}
LOST_COLOUR = (255, 0, 255)
SHIFT = 4  # sub-pixel bits for cv2 drawing


def draw_contours(
    frame: np.ndarray,
    contours: Mapping[str, np.ndarray],
    lost: Iterable[str] = (),
    thickness: int | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """``frame`` with the contours drawn as anti-aliased polylines in their feature's colour
    (:data:`COLOURS`), knots as dots; curves of lost features in magenta (:data:`LOST_COLOUR`).

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the frame drawn on (left unchanged).
    contours
        Contour name -> (N, 2) float array, (x, y) pixels; contours missing from it are skipped.
    lost
        Feature names (``mouth_outer``, ``mouth_inner``, ``brow_left``, ``brow_right``) whose
        curves are drawn in magenta.
    thickness
        Line thickness, pixels (dots of radius thickness + 1); None: min(H, W) / 400 rounded, at
        least 1.
    out
        (H, W, 3) uint8 array or view (e.g. half of a side-by-side canvas) to draw on, after
        ``frame`` is copied into it; None: a new copy of ``frame``.

    Returns
    -------
    (H, W, 3) uint8 array
        The drawing: ``out`` itself when given.
    """
    if out is None:
        out = np.ascontiguousarray(frame).copy()
    else:
        out[...] = frame
    lost = set(lost)
    t = thickness or max(1, round(min(frame.shape[:2]) / 400))
    for feature, names in FEATURES.items():
        colour = LOST_COLOUR if feature in lost else COLOURS[feature]
        for name in names:
            if name not in contours:
                continue
            pts = np.round(np.asarray(contours[name], float) * (1 << SHIFT)).astype(np.int32)
            cv2.polylines(out, [pts.reshape(-1, 1, 2)], False, colour, t, cv2.LINE_AA, SHIFT)
            for p in pts.tolist():
                cv2.circle(out, p, (t + 1) << SHIFT, colour, -1, cv2.LINE_AA, SHIFT)
    return out
