"""Finding a patch or a shape again near where it is expected.

:func:`find`: the normalised cross-correlation (TM_CCOEFF_NORMED, searched coarse to fine by
``facemime._core.best_match``) of a gray template over a window around the expected position;
it finds a lost brow again (:mod:`facemime.track.brows`) and follows the whole mouth when the
optical flow loses its knots (:mod:`facemime.track.mouth`). :func:`locate`: a feature's outline
(the lips' here), expected to differ from a band of skin around it, slid and scaled over a
search window to where the mean of a channel inside minus the mean in the band is largest; it
finds a mouth the tracker lost again (:func:`facemime.track.mouth.relocate`). Coordinates are
(x, y) pixels, origin at the centre of the top-left pixel, y down; polygons are (K, 2) float
arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from facemime import _core


def crop_box(points: np.ndarray, margin: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """The box of some points grown by a margin, inside the image.

    Parameters
    ----------
    points
        (N, 2) float array, (x, y) pixels.
    margin
        Pixels added on every side.
    width
        Width of the image, pixels.
    height
        Height of the image, pixels.

    Returns
    -------
    tuple of (lo, hi)
        lo : (2,) int array
            (x0, y0), the floor of the grown box's least coordinates, at least 0.
        hi : (2,) int array
            (x1, y1), exclusive: one past the ceiling of its largest, at most (width, height).
    """
    lo = np.floor(points.min(axis=0) - margin).astype(int)
    hi = np.ceil(points.max(axis=0) + margin).astype(int) + 1
    return np.maximum(lo, 0), np.minimum(hi, [width, height])


def gray_crop(image: np.ndarray, lo: np.ndarray | tuple[int, int], hi: np.ndarray | tuple[int, int]) -> np.ndarray:
    """The grey levels of a box of an image (``facemime._core.grey_area``).

    Parameters
    ----------
    image
        (H, W) uint8 grey, or (H, W, 3) uint8 RGB (converted as OpenCV's ``RGB2GRAY``).
    lo
        (x0, y0), integer pixels: the box's first column and row.
    hi
        (x1, y1), integer pixels, exclusive: the box ends there, inside the image and beyond
        ``lo`` (an empty box or one outside the image is an error).

    Returns
    -------
    (y1 − y0, x1 − x0) uint8 array
        The box's grey levels, 0-255.
    """
    return _core.grey_area(np.ascontiguousarray(image), (int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])))


def find(
    image: np.ndarray, template: np.ndarray, centre: np.ndarray, reach: float, min_match: float
) -> np.ndarray | None:
    """Where the centre of ``template`` matches ``image`` best by normalised cross-correlation,
    searched within ± ``reach`` px of ``centre``.

    Parameters
    ----------
    image
        (H, W) grey or (H, W, 3) RGB uint8 (see :func:`gray_crop`): the image searched.
    template
        (h, w) uint8 grey: the patch looked for.
    centre
        (2,) float array, (x, y) pixels: where the template's centre is expected.
    reach
        Pixels: the largest shift of the centre searched in x and y (the window is clipped to
        the image).
    min_match
        Lowest correlation accepted (TM_CCOEFF_NORMED, -1 to 1).

    Returns
    -------
    (2,) float64 array or None
        (x, y) pixels of the template's centre at the best match (on the pixel grid, or half
        a pixel off it for an even side); None where the window does not hold the template or
        the best correlation is below ``min_match``.
    """
    th, tw = template.shape
    x0 = max(int(round(centre[0] - (tw - 1) / 2.0 - reach)), 0)
    y0 = max(int(round(centre[1] - (th - 1) / 2.0 - reach)), 0)
    x1 = min(int(round(centre[0] + (tw - 1) / 2.0 + reach)) + 1, image.shape[1])
    y1 = min(int(round(centre[1] + (th - 1) / 2.0 + reach)) + 1, image.shape[0])
    if x1 - x0 < tw or y1 - y0 < th:
        return None
    (bx, by), best = _core.best_match(gray_crop(image, (x0, y0), (x1, y1)), template)
    if not best >= min_match:
        return None
    return np.array([x0 + bx + (tw - 1) / 2.0, y0 + by + (th - 1) / 2.0])


@dataclass(frozen=True)
class Placement:
    """Where :func:`locate` put a polygon: ``scale`` about its centroid, then ``shift`` pixels."""

    shift: np.ndarray
    scale: float
    contrast: float

    def apply(self, points: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """Move points like the polygon that was placed.

        Parameters
        ----------
        points
            (K, 2) float array, (x, y) pixels.
        centre
            (2,) float array, (x, y) pixels: the centroid of the polygon that was placed, about
            which it was scaled.

        Returns
        -------
        (K, 2) float64 array
            The points scaled by ``scale`` about ``centre``, then shifted by ``shift``, pixels.
        """
        return centre + self.scale * (points - centre) + self.shift


def locate(
    channel: np.ndarray,
    polygon: np.ndarray,
    reach: tuple[float, float],
    band: float,
    scales: tuple[float, ...] = (1.0,),
) -> Placement:
    """Best placement of ``polygon`` on ``channel``: the scale and whole-pixel shift where the
    mean of ``channel`` inside the polygon minus its mean in a ring around it is largest (beyond
    the channel's edges its border values are repeated).

    Parameters
    ----------
    channel
        (H, W) float array: a score per pixel, larger = more feature-like.
    polygon
        (K, 2) float array, (x, y) pixels of ``channel``: the outline placed.
    reach
        (rx, ry) pixels: the largest shift searched in x and y (rounded up to whole pixels).
    band
        Width of the surrounding ring, pixels (its whole part is used).
    scales
        The sizes tried, factors about the polygon's centroid.

    Returns
    -------
    Placement
        ``scale``, then ``shift`` ((2,) float64, whole pixels), and the ``contrast`` reached, in
        ``channel``'s units (-inf, with no shift and scale 1, where no scale left a polygon and
        a ring of pixels).
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
            window = padded[y0 + pad : y1 + pad, x0 + pad : x1 + pad]
        else:
            window = channel[y0:y1, x0:x1]
        score = cv2.matchTemplate(np.ascontiguousarray(window, np.float32), kernel.astype(np.float32), cv2.TM_CCORR)
        dy, dx = np.unravel_index(int(np.argmax(score)), score.shape)
        value = float(score[dy, dx])
        if value > best.contrast:
            best = Placement(np.array([dx - rx, dy - ry], float), float(s), value)
    return best
