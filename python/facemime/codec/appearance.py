"""Appearance updates: the actor's texture sent again, a rectangle at a time, where the face has
come to look different from it (light, skin, wrinkles), under a bit budget
(``docs/bitstream.md``, "Appearance").

An update is a payload of an appearance chunk: ``u32`` F, the first frame drawn with it; ``u16``
X, ``u16`` Y, where its top-left texel goes in the texture; then a WebP image, pasted there with
its edges blended over :data:`BLEND` texels (:func:`paste`).

The sender (:class:`AppearanceSender`) looks every :data:`CHECK` frames: the real frame is laid
back onto the texture through the geometry the receiver draws (each triangle facing the camera
drawn from the frame into texture space), and only its change at low frequencies is kept (the
receiver's texture plus the smoothed difference, :data:`SMOOTH`): where the geometry errs by a
few texels, the frame's details land beside the texture's, and sending them made the face worse
(lp_d3, 8 kbit/s: 23.2 dB against 23.5 without updates; smoothed, 23.7). The blocks of
:data:`BLOCK` texels it covers whole are compared with the receiver's texture (mean absolute grey
difference). The eyes are left out (their look moves them), and so is a mouth opening the actor's
mesh closes (:func:`facemime.fit.actor.mouth_cap`: its teeth and tongue move with the lips).
The rectangle around the blocks that differ by more than
:data:`THRESHOLD` levels is sent when the bits saved for it allow (a bucket filled at the budget,
holding at most :data:`WINDOW` seconds of it); otherwise the rectangle around the worst half of
them is tried, and so on. Texture pixels: (x, y), (0, 0) the centre of the top-left texel.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import cv2
import numpy as np

from facemime.io.image_bytes import decode_rgb
from facemime.render.paste import BLEND, paste_faded
from facemime.render.raster import render_mesh_into
from facemime.shared_constants import EYES
from facemime.types.head import HeadModel
from facemime.types.pose import Pose, project, rotation_matrix

#: Frames between two looks at the face, texels per side of a compared block, the mean grey
#: difference (levels) above which a block is sent again, seconds of budget the bucket holds,
#: WebP quality of an update, and halvings of the block set tried before giving up for now.
CHECK = 5
BLOCK = 16
THRESHOLD = 8.0
WINDOW = 4.0
QUALITY = 40
TRIES = 4
#: The change sent is smoothed over this many texels (Gaussian sigma).
SMOOTH = 4.0
#: A triangle is laid back onto the texture only when it faces the camera this much (its
#: normal's z, unit length): a triangle seen edge-on smears few pixels over many texels.
FACING = 0.3
HEAD = struct.Struct("<IHH")
#: A chunk's bytes beside its payload, at most (tag, sequence number, length, CRC-32): counted in
#: the budget.
FRAMING = 11


@dataclass(frozen=True)
class Update:
    """One appearance update: from ``frame`` on, ``image`` (H, W, 3) uint8 RGB goes at texel
    (``x``, ``y``) of the texture."""

    frame: int
    x: int
    y: int
    image: np.ndarray

    def payload(self, quality: int = QUALITY) -> bytes:
        """The appearance chunk's payload (``docs/bitstream.md``, "Appearance (version 2)").

        Parameters
        ----------
        quality
            WebP quality of the image, 1-100 (lossy).

        Returns
        -------
        bytes
            ``u32`` F, ``u16`` X, ``u16`` Y, then the image as WebP.
        """
        ok, data = cv2.imencode(
            ".webp", cv2.cvtColor(self.image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_WEBP_QUALITY, quality]
        )
        if not ok:
            raise ValueError("WebP encoding failed")
        return HEAD.pack(self.frame, self.x, self.y) + data.tobytes()


def parse(payload: bytes) -> Update | None:
    """The update in an appearance chunk's payload (``docs/bitstream.md``, "Appearance (version
    2)").

    Parameters
    ----------
    payload
        The chunk's payload: ``u32`` F, ``u16`` X, ``u16`` Y, a WebP image.

    Returns
    -------
    Update or None
        The update, its image RGB; None when the payload has no image (8 bytes or fewer) or its
        image does not decode.
    """
    if len(payload) <= HEAD.size:
        return None
    frame, x, y = HEAD.unpack_from(payload)
    image = decode_rgb(payload[HEAD.size :])
    return None if image is None else Update(frame, x, y, image)


def paste(texture: np.ndarray, update: Update) -> bool:
    """Paste an update into a texture, its edges blended as the spec says (``docs/bitstream.md``,
    "Appearance (version 2)"; :func:`facemime.render.paste.paste_faded`).

    Parameters
    ----------
    texture
        (H, W, 3) uint8 RGB texture, changed in place.
    update
        The update: its image goes at texel (``x``, ``y``), x right, y down.

    Returns
    -------
    bool
        False (texture untouched) when the update lies wholly outside the texture, else True.
    """
    return paste_faded(texture, update.image, update.x, update.y)


def lay_back(
    frame: np.ndarray,
    model_uv: np.ndarray,
    triangles: np.ndarray,
    points: np.ndarray,
    facing: np.ndarray,
    size: tuple[int, int],
) -> tuple[np.ndarray, np.ndarray]:
    """A frame laid back onto the texture through a mesh: each triangle drawn from the frame into
    texture space.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB image.
    model_uv
        (N, 2) float array: each vertex's texture coordinates (u, v) in [0, 1] from the texture's
        top-left corner (v down).
    triangles
        (F, 3) int array of vertex indices.
    points
        (N, 2) float array: each vertex's place in ``frame``, (x, y) pixels, y down, origin at
        the centre of the top-left pixel.
    facing
        (F,) bool mask (or indices) of the triangles to lay back.
    size
        (width, height) of the texture, texels.

    Returns
    -------
    texture : (height, width, 3) uint8 array
        RGB: the frame's pixels where the triangles cover the texture, 0 elsewhere.
    coverage : (height, width) uint8 array
        255 where a triangle covers the texel, 0 elsewhere.
    """
    w, h = size
    out = np.zeros((h, w, 3), np.uint8)
    cover = np.zeros((h, w), np.uint8)
    tris = triangles[facing]
    tex_px = model_uv * [w, h] - 0.5
    uv = (points + 0.5) / [frame.shape[1], frame.shape[0]]
    zero = np.zeros(len(points))
    render_mesh_into(out, frame, uv, tex_px, zero, tris, cull=False)
    render_mesh_into(cover, np.full((2, 2), 255, np.uint8), uv, tex_px, zero, tris, filter="nearest", cull=False)
    return out, cover


class AppearanceSender:
    """Chooses appearance updates for one actor's texture under a bit budget.

    :attr:`texture` is the receiver's copy of the texture, kept up to date here; :attr:`updates`
    counts the updates sent.

    Parameters
    ----------
    model
        The actor's head model (its ``uv`` address the texture).
    texture
        (H, W, 3) uint8 RGB: the actor's texture as the receiver holds it (copied).
    budget
        The updates' rate, at most, kbit/s (chunk framing included).
    fps
        The video's frame rate, frames/s.
    keep_out
        (R, 4) rectangles never sent (x, y, width, height, texels): the actor's sample boxes,
        which the receiver paints over; None: none.
    """

    def __init__(
        self, model: HeadModel, texture: np.ndarray, budget: float, fps: float, keep_out: np.ndarray | None = None
    ):
        self.model, self.texture = model, texture.copy()
        self._per_frame = budget * 1000.0 / fps
        self._cap = budget * 1000.0 * WINDOW
        self._bits = 0.0
        tri = np.asarray(model.triangles)
        eye = np.zeros(len(model.vertices), bool)
        for e in EYES:
            eye[model.groups[e]] = True
        mouth = np.zeros(len(model.vertices), bool)
        mouth[np.concatenate([model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]])] = True
        # the eye openings (the look moves them) and a mouth opening the mesh closes (the lips move it)
        self._triangles = tri[~eye[tri].all(axis=1) & ~mouth[tri].all(axis=1)]
        v = model.vertices
        n = np.cross(
            v[self._triangles[:, 1]] - v[self._triangles[:, 0]], v[self._triangles[:, 2]] - v[self._triangles[:, 0]]
        )
        self._normals = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
        h, w = texture.shape[:2]
        self._eyes = np.zeros((h, w), np.uint8)  # the eyes and a margin: never sent
        for e in EYES:
            ring = np.round((model.uv[model.groups[e]] * [w, h] - 0.5) * 16).astype(np.int32)
            cv2.fillPoly(self._eyes, [ring], 255, cv2.LINE_AA, 4)
        grow = 2 * BLEND + 1
        for x, y, bw, bh in () if keep_out is None else keep_out:
            self._eyes[y : y + bh, x : x + bw] = 255
        self._eyes = cv2.dilate(self._eyes, np.ones((grow, grow), np.uint8))
        self.updates = 0

    def update(self, index: int, frame: np.ndarray, vertices: np.ndarray, pose: Pose) -> bytes | None:
        """Take a frame's share of the budget and, on every :data:`CHECK`-th frame, look at it for
        an update.

        Parameters
        ----------
        index
            The frame's index from the stream's start (the update's F).
        frame
            (H, W, 3) uint8 RGB: the real frame.
        vertices
            (N, 3) float array: the model's vertices as the receiver draws this frame, model units
            (x to the subject's left, y up, z towards the camera).
        pose
            The pose the receiver draws them in.

        Returns
        -------
        bytes or None
            An appearance chunk's payload to send before the frame's packet (already applied to
            :attr:`texture`), or None.
        """
        self._bits = min(self._cap, self._bits + self._per_frame)
        if index % CHECK:
            return None
        facing = (self._normals @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T)[:, 2] >= FACING
        if not facing.any():
            return None
        points = project(vertices, pose)[0]
        h, w = self.texture.shape[:2]
        laid, cover = lay_back(frame, self.model.uv, self._triangles, points, facing, (w, h))
        cover[self._eyes > 0] = 0
        bh, bw = h // BLOCK, w // BLOCK
        if bh == 0 or bw == 0:
            return None
        crop = (slice(0, bh * BLOCK), slice(0, bw * BLOCK))
        # the change at low frequencies only: where the geometry errs by a few texels the
        # texture's details land beside themselves, but their local means stay
        covered = (cover == 255).astype(np.float32)
        weight = np.maximum(cv2.GaussianBlur(covered, (0, 0), SMOOTH), 1e-3)
        change = (laid.astype(np.float32) - self.texture) * covered[:, :, None]
        change = cv2.GaussianBlur(change, (0, 0), SMOOTH) / weight[:, :, None]
        laid = np.clip(self.texture + change + 0.5, 0, 255).astype(np.uint8)
        grey = lambda t: t[crop].astype(np.float32) @ np.float32([0.299, 0.587, 0.114])  # noqa: E731
        diff = np.abs(grey(laid) - grey(self.texture)).reshape(bh, BLOCK, bw, BLOCK).mean(axis=(1, 3))
        whole = cover[crop].reshape(bh, BLOCK, bw, BLOCK).min(axis=(1, 3)) == 255
        rows, cols = np.nonzero(whole & (diff > THRESHOLD))
        if not len(rows):
            return None
        order = np.argsort(-diff[rows, cols])
        rows, cols = rows[order], cols[order]
        for _ in range(TRIES):
            y0, y1 = rows.min() * BLOCK, (rows.max() + 1) * BLOCK
            x0, x1 = cols.min() * BLOCK, (cols.max() + 1) * BLOCK
            # texels the frame does not cover keep the receiver's
            region = np.where(cover[y0:y1, x0:x1, None] == 255, laid[y0:y1, x0:x1], self.texture[y0:y1, x0:x1])
            payload = Update(index, int(x0), int(y0), np.ascontiguousarray(region)).payload()
            cost = 8 * (len(payload) + FRAMING)
            if cost <= self._bits:
                self._bits -= cost
                paste(self.texture, parse(payload))
                self.updates += 1
                return payload
            keep = max(1, len(rows) // 2)
            rows, cols = rows[:keep], cols[:keep]
        return None


class Appearance:
    """The receiver's side: the actor's texture as the stream's appearance updates change it,
    frame by frame.

    An update applies from its frame F, or from the first frame output after it when it comes
    late. :attr:`texture` is the texture now; :attr:`applied` and :attr:`refused` count the
    updates pasted and those whose image did not decode or that lay outside the texture.

    Parameters
    ----------
    texture
        (H, W, 3) uint8 RGB: the actor's texture (copied).
    payloads
        The appearance chunks' payloads, in stream order
        (:attr:`~facemime.codec.decoder.MotionDecoder.appearance`).
    after
        For each payload, how many frames the decoder had output before it
        (:attr:`~facemime.codec.decoder.MotionDecoder.appearance_after`).
    """

    def __init__(self, texture: np.ndarray, payloads: list[bytes], after: list[int]):
        self.texture = texture.copy()
        parsed = [(parse(p), a) for p, a in zip(payloads, after)]
        self.refused = sum(u is None for u, _ in parsed)
        self._pending = [(max(u.frame, a), u) for u, a in parsed if u is not None]
        self.applied = 0

    def due(self, frame: int) -> bool:
        """Apply, in stream order, the updates due by a frame.

        Parameters
        ----------
        frame
            The frame's index from the stream's start: the updates that apply from it or before
            are pasted.

        Returns
        -------
        bool
            Whether :attr:`texture` changed.
        """
        changed = False
        while self._pending and self._pending[0][0] <= frame:
            if paste(self.texture, self._pending.pop(0)[1]):
                self.applied += 1
                changed = True
            else:
                self.refused += 1
        return changed
