"""How far a real frame departs from its synthesis outside the face: the honest limit of a scene
synthesised from one key frame (:mod:`facemime.render.scene`). A hand or an object passing in
front of the face, a body that moves a lot, or someone walking through the room cannot be
synthesised; such frames are found by comparing the two pictures around the face.

The measure is the share of the surround's pixels (everything outside the face outline, grown
by :data:`FACE_GROWTH` of its size) whose luma lies more than :data:`LUMA_STEP` grey levels
outside that of the synthesis near them (within :data:`REACH`), both pictures first shrunk by
:data:`SHRINK`: hair or a background misplaced by a few pixels is forgiven, a hand is not. A frame departs when that share exceeds
:data:`DEPARTS_AT`; the figures that set it are in ``benchmarks/synthesis.py``.
"""

from __future__ import annotations

import cv2
import numpy as np

#: Pictures are compared at 1/SHRINK of their size.
SHRINK = 4
#: A real pixel departs when its luma lies more than LUMA_STEP grey levels (0..255) outside the
#: range of the synthesised picture's lumas within REACH pixels (of the shrunk pictures) around it.
LUMA_STEP = 40
REACH = 2
#: The face region left out is its outline's hull grown about its centre by twice this fraction.
FACE_GROWTH = 0.12
#: Share of the surround's pixels departed from which the frame is reported.
DEPARTS_AT = 0.06


def _luma(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The luma of ``image`` shrunk to ``size``: halved twice (each a 2x2 average; INTER_AREA in
    one step costs four times as much)."""
    half = cv2.resize(image, ((size[0] * SHRINK) // 2, (size[1] * SHRINK) // 2), interpolation=cv2.INTER_LINEAR)
    return cv2.resize(cv2.cvtColor(half, cv2.COLOR_RGB2GRAY), size, interpolation=cv2.INTER_LINEAR)


def departure(real: np.ndarray, synth: np.ndarray, outline: np.ndarray) -> float:
    """The share (0..1) of the surround's pixels that depart (see the module docstring) between
    ``real`` and ``synth`` ((H, W, 3) uint8 RGB of one size), the face's outline now at
    ``outline`` ((A, 2) pixels)."""
    h, w = real.shape[:2]
    size = (max(1, w // SHRINK), max(1, h // SHRINK))
    seen, made = _luma(real, size), _luma(synth, size)
    near = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * REACH + 1, 2 * REACH + 1))
    # a real pixel is explained by any synthesised one within REACH: misplaced texture is forgiven
    darker = cv2.subtract(cv2.erode(made, near), seen)
    brighter = cv2.subtract(seen, cv2.dilate(made, near))
    diff = cv2.max(darker, brighter)
    face = np.asarray(outline, np.float64) * (size[0] / w, size[1] / h)
    centre = face.mean(axis=0)
    face = centre + (1.0 + 2.0 * FACE_GROWTH) * (face - centre)
    around = np.ones(diff.shape, np.uint8)
    cv2.fillConvexPoly(around, np.round(cv2.convexHull(face.astype(np.float32))).astype(np.int32), 0)
    around = around.view(bool)
    total = int(around.sum())
    return float(((diff > LUMA_STEP) & around).sum() / total) if total else 0.0
