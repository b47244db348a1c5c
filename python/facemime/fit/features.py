"""Placing a feature's outline where the image contrast says it is.

A feature (an eye, a brow, the lips) is a polygon expected to differ from a band of skin around
it: darker for eyes and brows, redder for lips. :func:`locate` slides and scales the polygon
over a search window and keeps the placement where the mean of ``channel`` inside minus the
mean in the surrounding band is largest; one correlation per scale does all shifts at once.
Polygons are (K, 2) float arrays of (x, y) pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class Placement:
    """Where :func:`locate` put a polygon: ``scale`` about its centroid, then ``shift`` pixels."""

    shift: np.ndarray
    scale: float
    contrast: float

    def apply(self, points: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """Move ``points`` (K, 2) like the polygon whose centroid was ``centre``."""
        return centre + self.scale * (points - centre) + self.shift


def locate(channel: np.ndarray, polygon: np.ndarray, reach: tuple[float, float], band: float,
           scales: tuple[float, ...] = (1.0,)) -> Placement:
    """Best placement of ``polygon`` on ``channel`` (H, W float32, larger = more feature-like).

    ``reach`` = (rx, ry): the largest shift searched in x and y, pixels; ``band``: width of the
    surrounding ring, pixels; ``scales``: the sizes tried, about the polygon's centroid.
    """
    h, w = channel.shape
    centre = polygon.mean(axis=0)
    best = Placement(np.zeros(2), 1.0, -np.inf)
    for s in scales:
        poly = centre + s * (polygon - centre)
        lo = np.floor(poly.min(axis=0) - band - 1).astype(int)
        hi = np.ceil(poly.max(axis=0) + band + 1).astype(int)
        kw, kh = hi - lo + 1
        inside = np.zeros((kh, kw), np.uint8)
        cv2.fillPoly(inside, [np.round((poly - lo) * 16).astype(np.int32)], 1, cv2.LINE_8, 4)
        ring = cv2.dilate(inside, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * int(band) + 1,) * 2)) - inside
        if inside.sum() == 0 or ring.sum() == 0:
            continue
        kernel = inside / inside.sum() - ring / ring.sum()
        # The window of image the kernel's top-left corner visits: lo - reach .. lo + reach.
        rx, ry = int(np.ceil(reach[0])), int(np.ceil(reach[1]))
        x0, y0 = lo[0] - rx, lo[1] - ry
        x1, y1 = lo[0] + rx + kw, lo[1] + ry + kh
        if x0 < 0 or y0 < 0 or x1 > w or y1 > h:
            pad = max(0, -x0, -y0, x1 - w, y1 - h)
            padded = cv2.copyMakeBorder(channel, pad, pad, pad, pad, cv2.BORDER_REPLICATE)
            window = padded[y0 + pad:y1 + pad, x0 + pad:x1 + pad]
        else:
            window = channel[y0:y1, x0:x1]
        score = cv2.matchTemplate(np.ascontiguousarray(window, np.float32), kernel.astype(np.float32), cv2.TM_CCORR)
        dy, dx = np.unravel_index(int(np.argmax(score)), score.shape)
        value = float(score[dy, dx])
        if value > best.contrast:
            best = Placement(np.array([dx - rx, dy - ry], float), float(s), value)
    return best
