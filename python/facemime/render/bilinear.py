"""Bilinear resampling in a fixed arithmetic of facemime's own, for the eyes and the face networks'
crops.

The eye painter runs in Python (``facemime decode``) and in the browser receiver
(``web/src/render/eyes.ts``), which must give the same pixels; the face networks' crops decide
where the tracker starts, and a crop one grey level off on a few pixels ends the track elsewhere.
``cv2.warpAffine`` cannot be that shared definition: its rounding changed between OpenCV 4.x,
5.0 and 5.1 (the same call differs by up to 5 grey levels between 4.14 and 5.0 and by 1 between
5.0 and 5.1; the automatic start's NME on the shared videos moved from 0.0187 to 0.0212 with
it). These functions compute what OpenCV 4 computed, written down here once; the TypeScript side
follows them step for step.

Positions are quantised to 1/:data:`SUB` px. Images: pixel (x, y), x right, y down, (0, 0) the
centre of the top-left pixel.
"""

from __future__ import annotations

import numpy as np

from facemime import _core

#: Sub-pixel steps per pixel of a sampling position.
SUB = 32
#: The fixed-point scale of an affine map's coefficients (1/1024 px).
SCALE = 1024


def sample_affine(image: np.ndarray, m: np.ndarray, size: tuple[int, int], border: str = "replicate") -> np.ndarray:
    """Sample ``image`` bilinearly at ``m @ (col, row, 1)`` for each output pixel (col, row).

    The position is taken in 1/32 px (each coordinate ``rint(m · (col, row, 1) · 1024) + 16``
    shifted down 5 bits, the row and column parts rounded apart), the integer weights sum to 1024,
    the sum is rounded (the Rust core's ``raster::affine``).

    Parameters
    ----------
    image
        (H, W, C) uint8 array, the picture sampled; a channel axis is required.
    m
        (2, 3) float affine map from an output pixel (col, row, 1) to the (x, y) position in
        ``image`` it samples, pixels.
    size
        (cols, rows) = (width, height) of the output, pixels.
    border
        What a sample beyond the picture reads: ``"replicate"``, its border pixels; ``"zero"``, 0.

    Returns
    -------
    (rows, cols, C) uint8 array
        The sampled picture.

    Examples
    --------
    >>> img = np.arange(12, dtype=np.uint8).reshape(2, 2, 3) * 20
    >>> sample_affine(img, np.array([[1.0, 0, 0.5], [0, 1, 0]]), (1, 1))[0, 0].tolist()
    [30, 50, 70]
    """
    cols, rows = size
    return _core.sample_affine(
        np.ascontiguousarray(image, np.uint8), np.asarray(m, np.float64), int(cols), int(rows), border
    )


def shift_offset(d: np.ndarray) -> tuple[int, int]:
    """The sampling offset that moves a picture by ``d``, for :func:`shifted`.

    Each pixel then samples the picture at (x + ox / 32, y + oy / 32).

    Parameters
    ----------
    d
        (2,) float array: the move (dx, dy), pixels, y down. Taken to float32 first, as the
        receiver sends it.

    Returns
    -------
    tuple of (ox, oy)
        The sampling offset, int, 1/32 px: minus ``d``, rounded.

    Examples
    --------
    >>> shift_offset(np.array([1.0, -0.5]))
    (-32, 16)
    """
    d32 = np.asarray(d, np.float32).astype(np.float64)
    ox, oy = ((int(np.rint(-v * SCALE)) + SCALE // SUB // 2) >> 5 for v in d32)
    return ox, oy


def shifted(image: np.ndarray, offset: tuple[int, int], replicate: bool) -> np.ndarray:
    """Sample ``image`` bilinearly at (x + ox / 32, y + oy / 32) for each pixel (x, y).

    The weights are float32, the sum is taken in float64, in the order top-left, top-right,
    bottom-left, bottom-right.

    Parameters
    ----------
    image
        (H, W) or (H, W, C) float array, the picture sampled.
    offset
        (ox, oy) sampling offset, 1/32 px, as from :func:`shift_offset`.
    replicate
        Outside the picture, take its border pixels (True) or 0 (False).

    Returns
    -------
    float64 array
        The sampled picture, of ``image``'s shape.
    """
    ox, oy = offset
    sx, sy = ox >> 5, oy >> 5
    fx, fy = (ox & 31) / SUB, (oy & 31) / SUB
    weights = [float(np.float32(v)) for v in ((1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy)]
    h, w = image.shape[:2]
    src = image.astype(np.float64)
    xs, ys = np.arange(w) + sx, np.arange(h) + sy

    def taps(idx: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        return np.clip(idx, 0, n - 1), (idx >= 0) & (idx < n)

    (xa, in_xa), (xb, in_xb) = taps(xs, w), taps(xs + 1, w)
    (ya, in_ya), (yb, in_yb) = taps(ys, h), taps(ys + 1, h)
    out = np.zeros_like(src)
    for wt, yy, in_y, xx, in_x in (
        (weights[0], ya, in_ya, xa, in_xa),
        (weights[1], ya, in_ya, xb, in_xb),
        (weights[2], yb, in_yb, xa, in_xa),
        (weights[3], yb, in_yb, xb, in_xb),
    ):
        tap = src[np.ix_(yy, xx)]
        if not replicate:
            inside = in_y[:, None] & in_x[None, :]
            tap = tap * (inside[..., None] if tap.ndim == 3 else inside)
        out = out + wt * tap
    return out
