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


def band_face_contours(
    shift: tuple[float, float] = (0.0, 0.0),
    opening: float = 0.0,
    bend: float = 0.0,
    brow_raise: float = 0.0,
    lips: float = 1.0,
    size: tuple[int, int] = (256, 256),
    parting: float = 0.0,
) -> dict[str, np.ndarray]:
    """The true contours of :func:`band_face` (same arguments)."""
    c = np.array([size[0] / 2.0 + shift[0], size[1] / 2.0 + shift[1]])
    my = 40.0
    # The inner curves' middle moves ``parting`` px down, their corners stay.
    out = {
        "mouth_outer_upper": _curve(-40, 40, my, 9 * lips + 0.3 * opening + bend, 11, c),
        "mouth_outer_lower": _curve(-40, 40, my, -(11 * lips + 0.7 * opening) + bend, 11, c),
        "mouth_inner_upper": _curve(-40, 40, my, 0.3 * opening + bend - parting, 11, c),
        "mouth_inner_lower": _curve(-40, 40, my, -0.7 * opening + bend - parting, 11, c),
    }
    for side, (x0, x1) in (("right", (-68, -18)), ("left", (18, 68))):
        y = -50.0 - brow_raise
        out[f"brow_{side}_upper"] = _curve(x0, x1, y, 7, 5, c)
        out[f"brow_{side}_lower"] = _curve(x0, x1, y + 9, 5, 5, c)
    return out


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
    """Render the synthetic face; returns ((H, W, 3) uint8 RGB frame, true contours).

    ``shift`` moves the whole face (px); ``opening`` opens the mouth (px); ``bend`` raises the
    middle of all mouth curves (px, a smile is negative); ``brow_raise`` lifts both brows (px);
    ``lips`` scales the lips' thickness; ``parting`` moves the line where the lips meet down in
    the middle (px), the outer lips staying; ``noise`` adds Gaussian noise of that standard
    deviation (levels).

    >>> frame, contours = band_face(opening=4.0)
    >>> frame.shape, contours["mouth_outer_upper"].shape
    ((256, 256, 3), (11, 2))
    """
    w, h = size
    contours = band_face_contours(shift, opening, bend, brow_raise, lips, size, parting)
    img = np.empty((h, w, 3), np.uint8)
    img[:] = SKIN
    c = np.array([w / 2.0 + shift[0], h / 2.0 + shift[1]])
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
