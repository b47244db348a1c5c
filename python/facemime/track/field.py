"""The image field the snakes read in one frame: for a region of interest, the luma L and a
lip-sensitive colour channel C = R − G, both Gaussian-smoothed, their x and y derivatives, and the
previous frame's smoothed luma on the same pixels. Stacked as float32 (h, w, 6) in the channel
order of ``facemime._core.FIELD_CHANNELS``: ∂L/∂x, ∂L/∂y, ∂C/∂x, ∂C/∂y, L, L_prev. Units: 0..255
levels and levels per pixel.
"""

from __future__ import annotations

import cv2
import numpy as np

LUMA = np.array([0.299, 0.587, 0.114], np.float32)


def region(points: np.ndarray, margin: float, width: int, height: int) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) integer box around ``points`` (N, 2) grown by ``margin`` px, inside the
    image, at least 4×4."""
    lo = np.floor(points.min(axis=0) - margin).astype(int)
    hi = np.ceil(points.max(axis=0) + margin).astype(int) + 1
    x0, y0 = max(int(lo[0]), 0), max(int(lo[1]), 0)
    x1, y1 = min(int(hi[0]), width), min(int(hi[1]), height)
    return min(x0, width - 4), min(y0, height - 4), max(x1, min(x0, width - 4) + 4), max(y1, min(y0, height - 4) + 4)


def smoothed_luma(rgb: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian-smoothed luma (float32) of an RGB uint8 crop."""
    luma = cv2.transform(rgb.astype(np.float32), LUMA[None, :])
    return cv2.GaussianBlur(luma, (0, 0), sigma)


def build_field(frame: np.ndarray, prev: np.ndarray | None, box: tuple[int, int, int, int], sigma: float) -> np.ndarray:
    """The (h, w, 6) float32 field of ``frame`` (H, W, 3) uint8 RGB over ``box``; ``prev`` is the
    previous frame (or None: L_prev = L)."""
    x0, y0, x1, y1 = box
    crop = frame[y0:y1, x0:x1]
    lum = smoothed_luma(crop, sigma)
    red_green = np.subtract(crop[..., 0], crop[..., 1], dtype=np.float32)
    chroma = cv2.GaussianBlur(red_green, (0, 0), sigma)
    d = lambda img, dx, dy: cv2.Sobel(img, cv2.CV_32F, dx, dy, ksize=1, scale=0.5)  # noqa: E731  central difference
    lp = lum if prev is None else smoothed_luma(prev[y0:y1, x0:x1], sigma)
    return cv2.merge([d(lum, 1, 0), d(lum, 0, 1), d(chroma, 1, 0), d(chroma, 0, 1), lum, lp])
