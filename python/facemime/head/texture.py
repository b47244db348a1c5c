"""A painted texture for a head model that has no photograph yet: skin, brows, eyes, lips and
nostrils drawn at the model's texture coordinates, so the generic head renders as a face."""

from __future__ import annotations

import cv2
import numpy as np

from facemime.errors import InvalidInputError
from facemime.types.head import HeadModel

SKIN = (224, 172, 142)
BROW = (78, 52, 38)
LIP = (176, 78, 78)
MOUTH_LINE = (96, 36, 40)
SCLERA = (236, 232, 226)
IRIS = (70, 96, 120)
LID_RIM = (60, 40, 36)
LASHES = (40, 28, 26)


def painted_texture(model: HeadModel, size: int = 512) -> np.ndarray:
    """A texture painted at the model's texture coordinates from its vertex groups: skin, brows,
    eyes, lips and nostrils.

    Parameters
    ----------
    model
        The head; it needs ``uv`` and a facemime head's brow, eye, mouth and nose groups
        (:data:`facemime.types.head.REQUIRED_GROUPS`); the nostrils are painted where the nose
        has a facemime head's layout (at least ten vertices, the ninth and tenth the alae).
    size
        Side of the square texture, pixels, 16 to 4096.

    Returns
    -------
    (size, size, 3) uint8 array
        RGB, addressed by ``model.uv`` from its top-left corner.

    Examples
    --------
    >>> from facemime.head import generic_head
    >>> painted_texture(generic_head(), 64).shape
    (64, 64, 3)
    """
    if model.uv is None:
        raise InvalidInputError(f"head model {model.name!r} has no texture coordinates (uv)")
    if not 16 <= size <= 4096:
        raise InvalidInputError(f"texture size must be in 16..4096, got {size}")
    px = model.uv * size - 0.5
    scale = size / 512.0

    def poly(*names: str, reverse_last: bool = True) -> np.ndarray:
        pts = [px[model.groups[n]] for n in names]
        if reverse_last and len(pts) > 1:
            pts[-1] = pts[-1][::-1]
        return np.round(np.concatenate(pts) * 16).astype(np.int32)

    # Skin with soft shading: lighter at the centre of the face, darker towards the outline.
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float32) / size
    centre = px[model.groups["nose"]].mean(axis=0) / size
    shade = 1.0 - 0.35 * np.clip(np.hypot((xx - centre[0]) * 1.3, yy - centre[1]) * 1.6, 0, 1) ** 2
    img = np.clip(np.array(SKIN, np.float32) * shade[..., None], 0, 255).astype(np.uint8)

    draw = {"lineType": cv2.LINE_AA, "shift": 4}
    for side in ("left", "right"):
        cv2.fillPoly(img, [poly(f"brow_{side}_upper", f"brow_{side}_lower")], BROW, **draw)
        eye = np.round(px[model.groups[f"eye_{side}"]] * 16).astype(np.int32)
        ring = px[model.groups[f"eye_{side}"]]
        c = ring.mean(axis=0)
        r = 0.21 * np.hypot(*(ring[4] - ring[0]))  # a human iris: 0.21 of the eye's width
        ball = np.full_like(img, SCLERA)  # the eyeball, seen through the opening only
        cv2.circle(ball, tuple(np.round(c * 16).astype(int)), int(r * 16), IRIS, -1, **draw)
        cv2.circle(ball, tuple(np.round(c * 16).astype(int)), int(r * 7), (20, 16, 16), -1, **draw)
        opening = np.zeros(img.shape[:2], np.uint8)
        cv2.fillPoly(opening, [eye], 255, **draw)
        alpha = opening[..., None].astype(np.float32) / 255.0
        img[:] = (img + alpha * (ball.astype(np.float32) - img) + 0.5).astype(np.uint8)
        cv2.polylines(img, [eye], True, LID_RIM, max(1, round(2 * scale)), **draw)
        cv2.polylines(img, [eye[:5]], False, LASHES, max(1, round(3 * scale)), **draw)  # the upper lid's lashes
    cv2.fillPoly(img, [poly("mouth_outer_upper", "mouth_outer_lower")], LIP, **draw)
    cv2.polylines(img, [poly("mouth_inner_upper")], False, MOUTH_LINE, max(1, round(3 * scale)), **draw)
    nose = px[model.groups["nose"]]
    alae = (8, 9) if len(nose) >= 10 else ()  # a shorter nose (a head of its own) has no nostrils painted
    for k in alae:  # the two alae: nostrils just inside them, towards the nose tip
        c = 0.6 * nose[k] + 0.4 * nose[7]
        cv2.ellipse(
            img,
            tuple(np.round(c * 16).astype(int)),
            (int(7 * scale * 16), int(4 * scale * 16)),
            0,
            0,
            360,
            (120, 70, 60),
            -1,
            **draw,
        )
    return cv2.GaussianBlur(img, (0, 0), 0.8 * scale)
