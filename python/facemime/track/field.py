"""The image field the snakes read in one frame: for a region of interest, the luma
L = 0.299 R + 0.587 G + 0.114 B and a lip-sensitive colour channel C = R − G, both smoothed by a
Gaussian, their x and y central differences, and the previous frame's smoothed luma on the same
pixels. Stacked as float32 (h, w, 6) in the channel order of ``facemime._core.FIELD_CHANNELS``:
∂L/∂x, ∂L/∂y, ∂C/∂x, ∂C/∂y, L, L_prev. Units: 0..255 levels and levels per pixel. Built in the
Rust core; it equals OpenCV's GaussianBlur and Sobel(ksize=1, scale=0.5) on the region's crop
(borders mirrored) to float rounding.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from facemime import _core


def regions(
    knots: np.ndarray, bands: list[tuple[np.ndarray, float]], width: int, height: int, sigma: float
) -> tuple[tuple[int, int, int, int], list[tuple[int, int, int, int]]]:
    """The field's regions for ``knots`` (K, 2) px in a ``width`` × ``height`` frame, smoothed
    by ``sigma`` px: each of ``bands``, (knot indices as np.uintp, margin px: how far around
    them the field is read), gives the integer box (x0, y0, x1, y1), exclusive ends, around its
    knots grown by its margin, inside the frame, at least 4×4, where the field is computed;
    returns (the field's box, those boxes). The box holds them all grown by the smoothing's
    radius, so that every pixel read holds the values it would in a field of the whole frame."""
    box, boxes = _core.field_regions(np.ascontiguousarray(knots, np.float64), bands, width, height, sigma)
    return _box(box), [_box(b) for b in boxes]


def _box(b: Sequence[int]) -> tuple[int, int, int, int]:
    return int(b[0]), int(b[1]), int(b[2]), int(b[3])


def build_field(
    frame: np.ndarray,
    prev: np.ndarray | None,
    box: tuple[int, int, int, int],
    sigma: float,
    bands: list[tuple[int, int, int, int]] | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """The (h, w, 6) float32 field of ``frame`` (H, W, 3) uint8 RGB over ``box``
    (x0, y0, x1, y1), exclusive ends, smoothed by a Gaussian of ``sigma`` px; ``prev`` is the
    previous frame (or None: L_prev = L). With ``bands``, (x0, y0, x1, y1) frame rectangles,
    exclusive ends, only the box's pixels inside a band are computed (the same values) and the
    others are 0 (in a row that two bands share, all from the one's left to the other's right
    are computed). Written into ``out`` when given (a C-contiguous float32 array of that
    shape; its values are replaced)."""
    before = None if prev is None else np.ascontiguousarray(prev)
    return _core.frame_field(np.ascontiguousarray(frame), before, box, sigma, bands, out)
