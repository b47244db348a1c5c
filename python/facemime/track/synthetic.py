"""A synthetic face with known contours, for tests, examples and demos: skin, two dark brows,
red lips around a dark mouth opening, and fixed freckles on the nose and forehead for the
head-motion estimate. Every shape is analytic, so the true contours are known exactly.

Units are pixels; the face centre sits at the image centre plus ``shift``.
"""

from __future__ import annotations

import cv2
import numpy as np

SKIN = (205, 160, 140)
BROW = (70, 45, 35)
LIP = (175, 70, 75)
OPENING = (45, 15, 20)
SHIFT = 4  # sub-pixel bits for cv2 drawing


def _curve(x0: float, x1: float, y: float, bulge: float, count: int, centre: np.ndarray) -> np.ndarray:
    s = np.linspace(0.0, 1.0, count)
    return np.stack([centre[0] + x0 + (x1 - x0) * s, centre[1] + y - bulge * np.sin(np.pi * s)], axis=1)


def band_face(
    shift: tuple[float, float] = (0.0, 0.0),
    opening: float = 0.0,
    bend: float = 0.0,
    brow_raise: float = 0.0,
    lips: float = 1.0,
    size: tuple[int, int] = (256, 256),
    noise: float = 0.0,
    seed: int = 0,
    parting: float = 0.0,
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Render the synthetic face.

    Parameters
    ----------
    shift
        (dx, dy) pixels: moves the whole face from the image centre.
    opening
        Pixels: opens the mouth in the middle (upper lip up 0.3 of it, lower lip down 0.7).
    bend
        Pixels: raises the middle of all mouth curves (a smile is negative).
    brow_raise
        Pixels: lifts both brows.
    lips
        Scales the lips' thickness (in the middle, 9 px upper and 11 px lower at 1, without
        ``parting``).
    size
        (width, height) of the image, pixels.
    noise
        Standard deviation of added Gaussian noise, 0-255 levels (0: none).
    seed
        Seed of the noise's random generator (the freckles never change).
    parting
        Pixels: moves the line where the lips meet down in the middle, the outer lips staying.

    Returns
    -------
    tuple of (frame, contours)
        frame : (H, W, 3) uint8 array
            The RGB image, H, W from ``size``.
        contours : dict of str to (N, 2) float64 array
            The eight true contours, (x, y) pixels image-left to image-right: 11 points on each
            mouth curve, 5 on each brow curve.

    Examples
    --------
    >>> frame, contours = band_face(opening=4.0)
    >>> frame.shape, contours["mouth_outer_upper"].shape
    ((256, 256, 3), (11, 2))
    """
    w, h = size
    c = np.array([w / 2.0 + shift[0], h / 2.0 + shift[1]])
    my = 40.0
    # The inner curves' middle moves ``parting`` px down, their corners stay.
    contours = {
        "mouth_outer_upper": _curve(-40, 40, my, 9 * lips + 0.3 * opening + bend, 11, c),
        "mouth_outer_lower": _curve(-40, 40, my, -(11 * lips + 0.7 * opening) + bend, 11, c),
        "mouth_inner_upper": _curve(-40, 40, my, 0.3 * opening + bend - parting, 11, c),
        "mouth_inner_lower": _curve(-40, 40, my, -0.7 * opening + bend - parting, 11, c),
    }
    for side, (x0, x1) in (("right", (-68, -18)), ("left", (18, 68))):
        y = -50.0 - brow_raise
        contours[f"brow_{side}_upper"] = _curve(x0, x1, y, 7, 5, c)
        contours[f"brow_{side}_lower"] = _curve(x0, x1, y + 9, 5, 5, c)
    img = np.empty((h, w, 3), np.uint8)
    img[:] = SKIN
    rng = np.random.default_rng(12345)
    spots = np.concatenate([rng.uniform([-28, -32], [28, 22], (40, 2)), rng.uniform([-70, -110], [70, -72], (40, 2))])
    fix = lambda p: np.round(p * (1 << SHIFT)).astype(np.int32)  # noqa: E731
    for k, p in enumerate(spots):
        shade = tuple(int(v * (0.55 + 0.3 * (k % 3) / 2)) for v in SKIN)
        cv2.circle(img, tuple(fix(c + p)), 3 << SHIFT if k % 4 else 4 << SHIFT, shade, -1, cv2.LINE_AA, SHIFT)

    def fill(upper: np.ndarray, lower: np.ndarray, colour: tuple[int, int, int]) -> None:
        poly = np.concatenate([upper, lower[::-1]])
        cv2.fillPoly(img, [fix(poly).reshape(-1, 1, 2)], colour, cv2.LINE_AA, SHIFT)

    for side in ("left", "right"):
        fill(contours[f"brow_{side}_upper"], contours[f"brow_{side}_lower"], BROW)
    fill(contours["mouth_outer_upper"], contours["mouth_outer_lower"], LIP)
    # the dark line where the lips meet, widening into the opening
    lower = contours["mouth_inner_lower"] + [0.0, 1.2]
    fill(contours["mouth_inner_upper"] - [0.0, 1.2], lower, OPENING)
    img = cv2.GaussianBlur(img, (0, 0), 0.8)
    if noise > 0:
        noisy = img + np.random.default_rng(seed).normal(0.0, noise, img.shape)
        img = np.clip(np.round(noisy), 0, 255).astype(np.uint8)
    return img, contours
