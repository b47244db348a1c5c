"""How far a real frame departs from its synthesis: the honest limit of a scene synthesised from
one key frame (:mod:`facemime.render.scene`). A hand or an object passing in front of the face,
a body or a camera that moves more than one key frame can show, or someone walking through the
room cannot be synthesised; such frames are found by comparing the two pictures.

Both pictures are shrunk by :data:`SHRINK`. A pixel departs when one picture's colour lies more
than :data:`STEP` levels (0..255, in any of R, G, B) outside the range of the other picture's
colours within :data:`REACH` pixels around it, either way: hair or a background misplaced by a
few pixels is forgiven, a hand that appears (or features that it hides) is not. The share of
departed pixels is taken in two regions, around the face (outside its outline's hull grown by
:data:`FACE_GROWTH`) and inside it (the hull shrunk to :data:`FACE_CORE`, where a hand over the
face hides the eyes, nose and mouth the synthesis shows); a frame's departure is the larger
share, and the frame departs above :data:`DEPARTS_AT`.

Set on the ten shared videos and a hand of the face's own skin colour composited over two of
them (lp_d0, vr_2; ``tests/animate/test_departure.py``): of the 23 frames with the hand 18
depart on each, all 8 with it held over the face, none without it; the five videos whose body
and camera stay put (lp_d0, vr_1, vr_2, mt_sun, mt_yongen) have no frame that departs; the
others, where the body sways or the camera moves, lp_d6 55%, lp_d3 75%, st_kh 92%, lp_d12 94%
and st_aoc 96% of their frames (``benchmarks/synthesis.py``).
"""

from __future__ import annotations

import cv2
import numpy as np

#: Pictures are compared at 1/SHRINK of their size.
SHRINK = 4
#: Colour levels (0..255) outside the other picture's range near a pixel from which it departs,
#: and how near, in pixels of the shrunk pictures.
STEP = 40
REACH = 2
#: The region around the face starts at its outline's hull grown about its centre by twice
#: FACE_GROWTH; the region inside is the hull shrunk to FACE_CORE of its size.
FACE_GROWTH = 0.04
FACE_CORE = 0.85
#: Share of a region's pixels departed from which the frame is reported.
DEPARTS_AT = 0.04


def _shrunk(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``image`` shrunk to ``size`` = (width, height) = its own over SHRINK: halved twice, each a
    2x2 average (INTER_AREA in one step costs four times as much)."""
    half = cv2.resize(image, (size[0] * SHRINK // 2, size[1] * SHRINK // 2), interpolation=cv2.INTER_LINEAR)
    return cv2.resize(half, size, interpolation=cv2.INTER_LINEAR)


def _outside(a: np.ndarray, b: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Per pixel and channel, how far ``a`` lies outside the range of ``b`` within ``near``."""
    return cv2.max(cv2.subtract(cv2.erode(b, near), a), cv2.subtract(a, cv2.dilate(b, near)))


def _hull(outline: np.ndarray, factor: float, shape: tuple[int, int]) -> np.ndarray:
    """A mask ((H, W) bool) of ``outline``'s convex hull scaled by ``factor`` about its centre."""
    centre = outline.mean(axis=0)
    mask = np.zeros(shape, np.uint8)
    hull = cv2.convexHull((centre + factor * (outline - centre)).astype(np.float32))
    cv2.fillConvexPoly(mask, np.round(hull).astype(np.int32), 1)
    return mask.view(bool)


def departure(real: np.ndarray, synth: np.ndarray, outline: np.ndarray) -> float:
    """How much a real frame departs from its synthesis.

    Parameters
    ----------
    real
        (H, W, 3) uint8 RGB: the frame.
    synth
        (H, W, 3) uint8 RGB: its synthesis, the same size.
    outline
        (A, 2) float array: the face outline's (x, y) pixels on this frame.

    Returns
    -------
    float
        0..1: the larger share of departed pixels of the two regions (around the face and inside
        it, see the module docstring).
    """
    h, w = real.shape[:2]
    size = (max(1, w // SHRINK), max(1, h // SHRINK))
    seen, made = _shrunk(real, size), _shrunk(synth, size)
    near = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * REACH + 1, 2 * REACH + 1))
    apart = cv2.max(_outside(seen, made, near), _outside(made, seen, near))
    far = np.maximum(np.maximum(apart[..., 0], apart[..., 1]), apart[..., 2]) > STEP  # (.max(axis=2) is 25x slower)
    face = np.asarray(outline, np.float64) * (size[0] / w, size[1] / h)
    shares = []
    for region in (~_hull(face, 1.0 + 2.0 * FACE_GROWTH, far.shape), _hull(face, FACE_CORE, far.shape)):
        total = np.count_nonzero(region)  # (ndarray.sum of a bool array is 10x slower)
        shares.append(np.count_nonzero(far & region) / total if total else 0.0)
    return float(max(shares))
