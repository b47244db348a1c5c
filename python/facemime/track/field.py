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
    """The field's regions around ``knots``: the field's box and one box per band.

    Each band gives the integer box around its knots grown by its margin, inside the frame, at
    least 4×4, where the field is computed. The field's box holds them all grown by the
    smoothing's radius, so that every pixel read holds the values it would in a field of the
    whole frame.

    Parameters
    ----------
    knots
        (K, 2) float array: the snakes' knots, (x, y) pixels.
    bands
        (knot indices as an np.uintp array, margin) pairs: the knots a band is around and how
        far around them the field is read, pixels.
    width
        Width of the frame, pixels.
    height
        Height of the frame, pixels.
    sigma
        The Gaussian smoothing of the field, pixels.

    Returns
    -------
    box : tuple of int
        The field's box (x0, y0, x1, y1), pixels, exclusive ends, for :func:`build_field`.
    boxes : list of tuple of int
        Each band's box (x0, y0, x1, y1), pixels, exclusive ends, in the order of ``bands``.
    """
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
    """The field of ``frame`` over ``box``, channels as in the module docstring.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB array, the current frame.
    prev
        (H, W, 3) uint8 RGB array, the previous frame, or None (then L_prev = L).
    box
        (x0, y0, x1, y1) pixels of the frame, exclusive ends: the region the field covers.
    sigma
        The Gaussian smoothing, pixels.
    bands
        (x0, y0, x1, y1) frame rectangles, exclusive ends: only the box's pixels inside a band
        are computed (the same values) and the others are 0 (in a row that two bands share, all
        from the one's left to the other's right are computed). None computes the whole box.
    out
        C-contiguous (h, w, 6) float32 array to write into (its values are replaced), or None
        for a new array.

    Returns
    -------
    (h, w, 6) float32 array
        The field, h = y1 − y0 and w = x1 − x0: ∂L/∂x, ∂L/∂y, ∂C/∂x, ∂C/∂y, L, L_prev, in
        0..255 levels and levels per pixel; ``out`` when given.
    """
    before = None if prev is None else np.ascontiguousarray(prev)
    return _core.frame_field(np.ascontiguousarray(frame), before, box, sigma, bands, out)
