"""Pasting an image into a texture with its edges faded in (``docs/bitstream.md``, "Appearance
(version 2)": the appearance updates and the actor's mouth and eye samples use the same rule).

Texels: (x, y) with x the column to the right and y the row down, (0, 0) the top-left texel.
"""

from __future__ import annotations

import numpy as np

#: Texels over which a pasted image's edges fade into the texture (the spec's B).
BLEND = 8


def paste_faded(texture: np.ndarray, image: np.ndarray, x: int, y: int) -> bool:
    """Paste an image into a texture, its edges blended into what the texture holds.

    A texel at distance d (texels) from the nearest edge of the image that is not on or beyond
    the texture's border weighs k / 8, k = min(8, d + 1), and becomes
    ``(k * u + (8 - k) * t + 4) // 8``; the image's texels beyond the texture are ignored.

    Parameters
    ----------
    texture
        (H, W, 3) uint8 RGB texture, changed in place.
    image
        (h, w, 3) uint8 RGB image pasted.
    x
        The column where the image's left column goes, texels from the left (≥ 0).
    y
        The row where the image's top row goes, texels from the top (≥ 0).

    Returns
    -------
    bool
        False (texture untouched) when the image lies wholly outside the texture, else True.
    """
    h, w = texture.shape[:2]
    uh, uw = image.shape[:2]
    x1, y1 = min(x + uw, w), min(y + uh, h)
    if x >= w or y >= h:
        return False
    far = np.full(max(uw, uh), BLEND)
    i, j = np.arange(uw), np.arange(uh)
    d = np.minimum(
        np.minimum(j if y > 0 else far[:uh], uh - 1 - j if y + uh < h else far[:uh])[:, None],
        np.minimum(i if x > 0 else far[:uw], uw - 1 - i if x + uw < w else far[:uw])[None, :],
    )
    k = np.minimum(BLEND, d + 1)[: y1 - y, : x1 - x, None].astype(np.int32)
    u = image[: y1 - y, : x1 - x].astype(np.int32)
    t = texture[y:y1, x:x1].astype(np.int32)
    texture[y:y1, x:x1] = ((k * u + (BLEND - k) * t + BLEND // 2) // BLEND).astype(np.uint8)
    return True
