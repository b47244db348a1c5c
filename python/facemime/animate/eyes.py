"""Eyes in the synthesis: lids that close and irises that move.

- Lids: the upper-lid vertices of each eye ring (:mod:`facemime.track.eyes` says the ring's
  order) move towards the lower-lid vertices below them by the look's closure.
- Irises: the actor's texture is the key frame, iris and all. On it, each eye's iris is found
  (:func:`facemime.track.eyes.find_iris` in the texture's own eye frame); a copy of the eye with
  the iris painted out (``cv2.inpaint``) is kept, and each frame the iris disc is pasted back,
  shifted by the look (:mod:`facemime.render.bilinear`, which the browser receiver follows),
  inside the eye's opening.

Texture pixels: (x, y) with (0, 0) the centre of the top-left texel (uv 0..1 from its corner).
"""

from __future__ import annotations

import cv2
import numpy as np

from facemime.render.bilinear import shift_offset, shifted
from facemime.shared_constants import (
    EYES,
    IRIS_RADIUS,
    IRIS_REACH,
    LID_EDGE,
    LOWER_LID,
    PASTE_STILL,
    SPAN_U,
    SPAN_V,
    UPPER_LID,
)
from facemime.track.eyes import EyeFrame, find_iris
from facemime.types.actor import Actor
from facemime.types.look import Look


def close_lids(vertices: np.ndarray, rings: list[np.ndarray], closure: np.ndarray) -> np.ndarray:
    """The vertices with each eye's upper lid moved part of the way to its lower lid.

    Parameters
    ----------
    vertices
        (N, 3) float array: the model's vertices, model units.
    rings
        The eye rings' (8,) vertex indices (:mod:`facemime.track.eyes` says their order), one per
        eye in the order of ``closure``.
    closure
        (2,) float array: per eye, the share of the way its upper-lid vertices move to the lower
        lid's below them (1: onto them; negative: away from them).

    Returns
    -------
    (N, 3) float array
        A copy of ``vertices`` with the lids moved, model units.
    """
    out = vertices.copy()
    for ring, c in zip(rings, closure):
        if c:
            up, low = ring[list(UPPER_LID)], ring[list(LOWER_LID)]
            out[up] = vertices[up] + float(c) * (vertices[low] - vertices[up])
    return out


class _Eye:
    """One eye of the texture: its region, the region with the iris painted out, the iris patch,
    its alpha, and the opening's mask.

    Parameters
    ----------
    texture
        (H, W, 3) uint8 RGB: the actor's texture (the key frame's face, iris and all).
    ring_px
        (8, 2) float array: the eye ring's vertices (corner, 3 upper, corner, 3 lower) in texture
        pixels, (x, y) with (0, 0) the centre of the top-left texel.
    """

    def __init__(self, texture: np.ndarray, ring_px: np.ndarray):
        frame = EyeFrame.of(ring_px)
        self.frame = frame
        w = frame.width
        corners = frame.to_image(np.array([[u, v] for u in SPAN_U for v in SPAN_V]))  # the patch's, texture px
        lo, hi = np.floor(corners.min(axis=0)), np.ceil(corners.max(axis=0))
        x0, y0 = np.maximum(lo.astype(int), 0)
        x1, y1 = np.minimum(hi.astype(int) + 1, [texture.shape[1], texture.shape[0]])
        self.box = (x0, y0, x1, y1)
        region = texture[y0:y1, x0:x1]
        self.iris_uv = find_iris(frame.patch(texture))[0]
        centre = frame.to_image(self.iris_uv) - [x0, y0]
        self.radius = IRIS_RADIUS * w * IRIS_REACH
        shape = region.shape[:2]
        yy, xx = np.mgrid[0 : shape[0], 0 : shape[1]].astype(np.float32)
        self.disc = np.clip(self.radius + 0.5 - np.hypot(xx - centre[0], yy - centre[1]), 0.0, 1.0)
        opening = np.zeros(shape, np.uint8)
        cv2.fillPoly(opening, [np.round((ring_px - [x0, y0]) * 16).astype(np.int32)], 255, cv2.LINE_AA, 4)
        self.opening = opening.astype(np.float32) / 255.0
        # only what the key frame's opening showed of the iris moves, not the lid's edge
        k = 2 * max(1, int(round(LID_EDGE * w))) + 1
        inner = cv2.erode(self.opening, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k)))
        self.disc *= inner
        hole = self.disc > 0
        inside = inner > 0.5
        # the sclera: the brightest quarter of the opening's pixels beside the iris
        beside = region[inside & ~hole].reshape(-1, 3)
        if len(beside) == 0:
            beside = region[inside].reshape(-1, 3) if inside.any() else region.reshape(-1, 3)
        grey = beside.astype(np.float64) @ (0.299, 0.587, 0.114)
        sclera = np.median(beside[grey >= np.percentile(grey, 75)], axis=0)
        # the hole is filled from the sclera beside it and from sclera colour at and beyond the
        # lids, smoothed, and blended in over a few texels so that no outline shows
        source = region.copy()
        source[~inside] = np.round(sclera).astype(np.uint8)
        fill = cv2.inpaint(
            source,
            cv2.dilate(hole.astype(np.uint8) * 255, np.ones((3, 3), np.uint8)),
            max(2.0, self.radius / 3),
            cv2.INPAINT_TELEA,
        ).astype(np.float32)
        fill = cv2.GaussianBlur(fill, (0, 0), max(1.0, self.radius / 4))
        blend = cv2.GaussianBlur(hole.astype(np.float32), (0, 0), max(1.0, self.radius / 8)) * self.opening
        blend = np.maximum(blend, hole)[:, :, None]
        self.iris = region.astype(np.float32)
        self.clean = self.iris + blend * (fill - self.iris)

    def paint(self, out: np.ndarray, shift: np.ndarray) -> None:
        """Paint the eye into the texture's working copy, with the iris shifted.

        Parameters
        ----------
        out
            (H, W, 3) uint8 RGB: the texture's working copy, painted in place (the eye's box whole).
        shift
            (2,) float array: the iris's shift (u, v), eye widths (:mod:`facemime.types.look`).
        """
        x0, y0, x1, y1 = self.box
        d = np.asarray(shift, np.float64) @ self.frame.axes  # texture px
        if np.abs(d).max() < PASTE_STILL:
            out[y0:y1, x0:x1] = self.iris  # the key frame's eye as it was
            return
        offset = shift_offset(d)
        iris = shifted(self.iris, offset, replicate=True).astype(np.float32)
        alpha = shifted(self.disc, offset, replicate=False) * self.opening
        out[y0:y1, x0:x1] = np.clip(self.clean + alpha[:, :, None] * (iris - self.clean) + 0.5, 0, 255)


class LookPainter:
    """Paints a :class:`~facemime.types.look.Look` on an actor: :meth:`vertices` closes the lids,
    :meth:`texture` moves the irises.

    Parameters
    ----------
    actor
        The actor whose eye rings and texture are painted.
    """

    def __init__(self, actor: Actor):
        self.actor = actor
        model = actor.model
        self.rings = [model.groups[e] for e in EYES]
        size = np.array([actor.texture.shape[1], actor.texture.shape[0]], np.float64)
        self._eyes = [_Eye(actor.texture, model.uv[r] * size - 0.5) for r in self.rings]
        self._work = actor.texture.copy()

    @property
    def eye_boxes(self) -> list[tuple[int, int, int, int]]:
        """Each eye's region of the texture that :meth:`texture` repaints: (x0, y0, x1, y1)
        texels, x1 and y1 exclusive, the rings' order."""
        return [tuple(int(c) for c in e.box) for e in self._eyes]  # type: ignore[misc]

    def vertices(self, vertices: np.ndarray, look: Look) -> np.ndarray:
        """The vertices with the lids closed by a look's closure.

        Parameters
        ----------
        vertices
            (N, 3) float array: the actor's model vertices, as deformed, model units.
        look
            The look whose ``closure`` closes the lids.

        Returns
        -------
        (N, 3) float array
            A copy with the lids moved (:func:`close_lids`), model units.
        """
        return close_lids(vertices, self.rings, look.closure)

    def texture(self, look: Look) -> np.ndarray:
        """The actor's texture with the irises shifted by a look.

        Parameters
        ----------
        look
            The look whose ``iris`` shifts the irises.

        Returns
        -------
        (H, W, 3) uint8 array
            RGB, the actor's texture's size: a working copy, valid until the next call.
        """
        out = self._work  # each eye's box is painted whole: the rest stays the actor's texture
        for eye, shift in zip(self._eyes, look.iris):
            eye.paint(out, shift)
        return out
