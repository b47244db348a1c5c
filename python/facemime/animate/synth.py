"""Synthesising a frame: the actor's textured model, deformed and posed, over a background, with
a mouth interior (a dark cavity with upper and lower teeth) behind the lips so that an open mouth
never shows the background (the paper's Figure 9h shortcoming).

Images are (H, W, 3) uint8 RGB; points are (x, y) pixels, y down.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import cv2
import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.eyes import LookPainter
from facemime.animate.samples import SamplePainter, interior_strip
from facemime.errors import InvalidInputError
from facemime.render.raster import fill, render_mesh_into
from facemime.render.scene import SceneMesh
from facemime.shared_constants import (
    BACKGROUND,
    CAVITY,
    GAPS,
    LOWER_SHARE,
    LOWER_TEETH,
    SEAL,
    SHIFT,
    TEETH,
    TEETH_FROM,
    TEETH_SPAN,
    TEETH_SPREAD,
    UPPER_MIN,
    UPPER_SHARE,
    UPPER_TEETH,
)
from facemime.types.actor import Actor
from facemime.types.head import model_iod, mouth_width
from facemime.types.look import Look
from facemime.types.pose import Pose, project


def teeth_uncovered(spread: float) -> float:
    """How much of the teeth the lips uncover (:data:`TEETH_SPREAD`).

    Parameters
    ----------
    spread
        The mouth corners' distance apart, a factor on their rest distance.

    Returns
    -------
    float
        0..1: the share of the teeth's height shown.
    """
    lo, hi = TEETH_SPREAD
    return float(np.clip((spread - lo) / (hi - lo), 0.0, 1.0))


@functools.cache
def _teeth_span(knots: int) -> np.ndarray:
    """Which of a lip curve's ``knots`` (evenly spread from corner to corner) the teeth span
    (:data:`TEETH_SPAN`); all of them when that leaves fewer than two."""
    keep = np.abs(np.linspace(-1.0, 1.0, knots)) <= TEETH_SPAN
    keep = keep if keep.sum() >= 2 else np.ones(knots, bool)
    keep.flags.writeable = False
    return keep


def draw_mouth_interior(out: np.ndarray, upper: np.ndarray, lower: np.ndarray, uncovered: float = 1.0) -> None:
    """Paint the mouth opening bounded by the inner-lip curves into an image in place: the cavity,
    and the teeth hanging from the upper lip and rising from the lower one.

    Parameters
    ----------
    out
        (H, W, 3) uint8 RGB: the image, painted in place.
    upper
        (K, 2) float array: the upper inner lip's (x, y) pixels, corner to corner.
    lower
        (K, 2) float array: the lower inner lip's (x, y) pixels, corner to corner, sharing the
        corners with ``upper``.
    uncovered
        0..1: the share of the teeth's height shown (the upper row at least :data:`UPPER_MIN`).
    """
    poly = np.concatenate([upper, lower[::-1]])
    lo = np.floor(poly.min(axis=0)).astype(int) - 1
    hi = np.ceil(poly.max(axis=0)).astype(int) + 2
    x0, y0 = np.maximum(lo, 0)
    x1, y1 = np.minimum(hi, [out.shape[1], out.shape[0]])
    if x1 - x0 < 2 or y1 - y0 < 2:
        return
    fix = lambda p: np.round((p - [x0, y0]) * (1 << SHIFT)).astype(np.int32).reshape(-1, 1, 2)  # noqa: E731
    mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
    cv2.fillPoly(mask, [fix(poly)], 255, cv2.LINE_AA, SHIFT)
    if not mask.any():
        return
    paint = fill(np.empty((y1 - y0, x1 - x0, 3), np.uint8), CAVITY)
    along = upper[-1] - upper[0]
    width = math.hypot(*along)
    down = np.array([-along[1], along[0]]) / max(width, 1e-9)
    keep = _teeth_span(len(upper)) if len(upper) == len(lower) else slice(None)
    opening = (lower - upper) @ down if len(upper) == len(lower) else np.full(len(upper), width)
    # teeth grow from nothing at TEETH_FROM to their full share of the opening at twice it
    opening = (opening * np.clip(opening / (TEETH_FROM * width) - 1.0, 0.0, 1.0))[keep]
    rows = (
        (upper, UPPER_TEETH, UPPER_SHARE, max(uncovered, UPPER_MIN), 1.0),
        (lower, LOWER_TEETH, LOWER_SHARE, uncovered, -1.0),
    )
    for curve, height, share, shown, sign in rows:
        edge = curve[keep]
        reach = shown * np.minimum(height * width, share * opening)[:, None]
        if reach.max() < 0.5:  # an anti-aliased outline of teeth with no height would still show
            continue
        tips = edge + sign * reach * down
        cv2.fillPoly(paint, [fix(np.concatenate([edge, tips[::-1]]))], TEETH, cv2.LINE_AA, SHIFT)
        for a, b in zip(fix(edge[1:-1]).reshape(-1, 2).tolist(), fix(tips[1:-1]).reshape(-1, 2).tolist()):
            cv2.line(paint, a, b, GAPS, 1, cv2.LINE_AA, SHIFT)  # gaps between the teeth
    # shade the far corners of the cavity and the teeth towards dark
    cx = (np.arange(x0, x1, dtype=np.float32) - (upper[0, 0] + upper[-1, 0]) / 2.0) / max(width / 2.0, 1.0)
    shade = np.clip(1.15 - 0.6 * cx**2, 0.35, 1.0).astype(np.float32)[None, :, None]
    alpha = (mask * np.float32(1.0 / 255.0))[:, :, None]
    roi = out[y0:y1, x0:x1]
    roi[:] = roi + alpha * (paint * shade - roi)


def scene_mesh(actor: Actor) -> SceneMesh | None:
    """The warp mesh of an actor's scene.

    Parameters
    ----------
    actor
        The actor, whose face outline is placed by its pose on its source picture.

    Returns
    -------
    SceneMesh or None
        The mesh of its source picture, at that picture's size (``source`` width and height,
        pixels); None when the actor has no scene.
    """
    if actor.scene is None:
        return None
    anchors = actor.model.groups["face_outline"]
    outline = project(actor.model.vertices[anchors], actor.pose)[0]
    return SceneMesh.build((actor.source["width"], actor.source["height"]), anchors, outline)


def key_frame(actor: Actor, scene: SceneMesh) -> np.ndarray:
    """An actor's scene image at the size of its scene mesh (the image is stored smaller when
    large).

    Parameters
    ----------
    actor
        The actor, which has a scene.
    scene
        Its :func:`scene_mesh`.

    Returns
    -------
    (H, W, 3) uint8 array
        RGB, ``scene.size``: the actor's own scene image where it is that size, else a resized
        copy.
    """
    w, h = scene.size
    if actor.scene.shape[:2] == (h, w):
        return actor.scene
    return cv2.resize(actor.scene, (w, h), interpolation=cv2.INTER_LINEAR)


def synthesize(
    actor: Actor,
    vertices: np.ndarray,
    pose: Pose,
    size: tuple[int, int],
    background: np.ndarray | tuple[int, int, int] = BACKGROUND,
    out: np.ndarray | None = None,
    scene: SceneMesh | None = None,
    key: np.ndarray | None = None,
    texture: np.ndarray | None = None,
    interior: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """The actor's textured model, deformed and posed, over a background, with the mouth interior.

    Parameters
    ----------
    actor
        The actor drawn.
    vertices
        (N, 3) float array: its model's vertices, deformed, model units.
    pose
        The pose they are seen in.
    size
        (width, height) of the image, pixels.
    background
        An (R, G, B) colour, 0-255 levels, or an (H, W, 3) uint8 RGB image of ``size``; not used
        with ``out`` (what it holds is the background) or ``scene``.
    out
        (H, W, 3) uint8 RGB of ``size`` to draw into; None: a new image.
    scene
        The actor's :func:`scene_mesh`, of this ``size``: with ``key``, the face is drawn in the
        actor's scene, warped to follow it.
    key
        (H, W, 3) uint8 RGB: the actor's scene image at ``size`` (:func:`key_frame`); needed with
        ``scene``.
    texture
        (Ht, Wt, 3) uint8 RGB, the size of the actor's texture: drawn instead of it (its eyes
        repainted, :class:`~facemime.animate.eyes.LookPainter`); None: the actor's own.
    interior
        The mouth's opening as a sample showed it: (h, w, 3) uint8 RGB image, (N, 2) its texture
        coordinates per vertex and (M, 3) the triangles between the inner lips
        (:func:`~facemime.animate.samples.interior_strip`), drawn there instead of the painted
        cavity and teeth; None: painted.

    Returns
    -------
    (H, W, 3) uint8 array
        RGB, the synthesised frame: ``out`` when given.
    """
    w, h = size
    if out is None:
        out = np.empty((h, w, 3), np.uint8)
        if scene is None and np.ndim(background) == 1:
            fill(out, background)
        elif scene is None:
            out[...] = background
    points, depth = project(vertices, pose)
    if scene is not None:
        scene.draw(out, key, points[scene.anchors])
    if interior is None:
        g = actor.model.groups
        spread = mouth_width(actor.model, vertices) / max(mouth_width(actor.model, actor.model.vertices), 1e-9)
        upper, lower = points[g["mouth_inner_upper"]], points[g["mouth_inner_lower"]]
        draw_mouth_interior(out, upper, lower, teeth_uncovered(spread))
    else:
        image, uv, strip = interior
        render_mesh_into(out, image, uv, points, depth, strip, cull=False)
    render_mesh_into(
        out, actor.texture if texture is None else texture, actor.model.uv, points, depth, actor.model.triangles
    )
    return out


@dataclass(frozen=True)
class UserMotion:
    """Motion the user adds on top of the measured one: extra ``yaw``, ``pitch``, ``roll``
    (degrees), ``zoom`` (factor on the face's size, about the model origin between the eyes) and
    ``gain`` (exaggeration: factor on the local deformation; 0 freezes the face)."""

    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    zoom: float = 1.0
    gain: float = 1.0

    def __post_init__(self) -> None:
        for name in ("yaw", "pitch", "roll"):
            v = getattr(self, name)
            if not (np.isfinite(v) and -180.0 <= v <= 180.0):
                raise InvalidInputError(f"{name} must be degrees in [-180, 180], got {v}")
        if not (np.isfinite(self.zoom) and 0.1 <= self.zoom <= 10.0):
            raise InvalidInputError(f"zoom must be in [0.1, 10], got {self.zoom}")
        if not (np.isfinite(self.gain) and 0.0 <= self.gain <= 10.0):
            raise InvalidInputError(f"exaggeration must be in [0, 10], got {self.gain}")

    def changed(self, **deltas: float) -> UserMotion:
        """A copy with changes applied, kept in range.

        Parameters
        ----------
        **deltas
            By field name: degrees added to ``yaw``, ``pitch`` or ``roll``, factors multiplying
            ``zoom`` or ``gain``.

        Returns
        -------
        UserMotion
            The changed motion, each field clipped to its range.
        """
        v = {k: getattr(self, k) for k in ("yaw", "pitch", "roll", "zoom", "gain")}
        for k, d in deltas.items():
            v[k] = v[k] * d if k in ("zoom", "gain") else v[k] + d
        v.update(
            yaw=float(np.clip(v["yaw"], -180, 180)),
            pitch=float(np.clip(v["pitch"], -180, 180)),
            roll=float(np.clip(v["roll"], -180, 180)),
            zoom=float(np.clip(v["zoom"], 0.1, 10)),
            gain=float(np.clip(v["gain"], 0.0, 10.0)),
        )
        return replace(self, **v)


class Puppet:
    """An actor driven by motion measured on a face (its own or another person's).

    Offsets are scaled per feature by the ratio of the two faces' feature sizes.

    In its scene (the actor has one and ``mask_only`` is False) the actor appears in its own
    picture, moved from where it sits there by the measured motion relative to ``source_pose``:
    turns and tilts add, shifts and zoom scale with the two faces' sizes on screen. Otherwise the
    face is shown alone where the measured face is, the measured pose's scale multiplied by the
    ratio of the eye distances so that it keeps the measured face's size on screen.

    Parameters
    ----------
    actor
        The actor driven.
    source_sizes
        (K,) float array: the feature size of each knot on the measured face (see
        :meth:`Deformer.feature_sizes`), model units; K must be the actor's knot count (else
        :class:`~facemime.errors.InvalidInputError`).
    source_iod
        The measured face's eye-corner distance, model units.
    source_pose
        The measured face's pose on its key frame; None: the actor is posed as without a scene
        (where the measured face is).
    mask_only
        Show the face alone even where the actor has a scene.
    """

    def __init__(
        self,
        actor: Actor,
        source_sizes: np.ndarray,
        source_iod: float,
        source_pose: Pose | None = None,
        mask_only: bool = False,
    ):
        self.actor = actor
        self.source_pose = source_pose
        self.scene = None if mask_only else scene_mesh(actor)
        self._picture = None if self.scene is None else np.empty((self.scene.size[1], self.scene.size[0], 3), np.uint8)
        self._key = None if self.scene is None else key_frame(actor, self.scene)
        self.shown: tuple[np.ndarray, Pose] | None = None
        self.deformer = Deformer(actor.model)
        self.painter = LookPainter(actor)
        self.samples = (
            None if actor.samples is None else SamplePainter(actor.samples, actor.model.groups, self.deformer.knots)
        )
        self._strip = interior_strip(actor.model)
        sizes = np.asarray(source_sizes, np.float64)
        if sizes.shape != (len(self.deformer.knots),) or not np.isfinite(sizes).all() or (sizes <= 0).any():
            raise InvalidInputError(
                f"the motion has {len(sizes)} knots but actor {actor.model.name!r} has {len(self.deformer.knots)}"
            )
        self._ratio = (self.deformer.feature_sizes() / sizes)[:, None]
        self._scale = float(source_iod) / model_iod(actor.model)

    def retexture(self, texture: np.ndarray) -> None:
        """Draw the actor with a new texture from now on.

        Parameters
        ----------
        texture
            (H, W, 3) uint8 RGB: the actor's texture as updated, the same size.
        """
        self.actor = replace(self.actor, texture=texture)
        self.painter = LookPainter(self.actor)

    def pose(self, measured: Pose, user: UserMotion = UserMotion()) -> Pose:
        """The pose to show the actor in.

        Parameters
        ----------
        measured
            The source face's measured pose.
        user
            The motion the user adds (turns added, ``zoom`` multiplying the scale).

        Returns
        -------
        Pose
            The actor's pose: in its scene's picture (given a scene and ``source_pose``), else
            where the measured face is.
        """
        if self.scene is None or self.source_pose is None:
            shown = replace(measured, scale=measured.scale * self._scale)
        else:
            rest, key = self.actor.pose, self.source_pose
            ratio = rest.scale / self._scale / key.scale  # target pixels per source pixel
            shown = Pose(
                yaw=rest.yaw + measured.yaw - key.yaw,
                pitch=rest.pitch + measured.pitch - key.pitch,
                roll=rest.roll + measured.roll - key.roll,
                scale=rest.scale * measured.scale / key.scale,
                tx=rest.tx + ratio * (measured.tx - key.tx),
                ty=rest.ty + ratio * (measured.ty - key.ty),
            )
        return replace(
            shown,
            yaw=shown.yaw + user.yaw,
            pitch=shown.pitch + user.pitch,
            roll=shown.roll + user.roll,
            scale=shown.scale * user.zoom,
        )

    def vertices(self, offsets: np.ndarray, user: UserMotion = UserMotion(), look: Look = Look()) -> np.ndarray:
        """The actor's vertices moved by the source's knot offsets, lips all but touching shown
        closed (:data:`SEAL`), lids closed by the look.

        Parameters
        ----------
        offsets
            (K, 2) float array: the knot (x, y) offsets measured on the source face, its model
            units.
        user
            The motion the user adds: its ``gain`` multiplies the offsets and the lid closures.
        look
            The look whose ``closure`` closes the lids.

        Returns
        -------
        (N, 3) float64 array
            The actor's model vertices, deformed, model units.
        """
        vertices = self.deformer.sealed(self.deformer.vertices(offsets * self._ratio, user.gain), SEAL)
        return self.painter.vertices(vertices, Look(look.closure * user.gain))

    def render(
        self,
        measured: Pose,
        offsets: np.ndarray,
        size: tuple[int, int],
        user: UserMotion = UserMotion(),
        out: np.ndarray | None = None,
        look: Look = Look(),
        samples: tuple[int | None, ...] | None = None,
    ) -> np.ndarray:
        """The synthesised frame. A scene of another size is drawn at its own and fitted into
        ``size`` (its aspect kept, the rest :data:`BACKGROUND`); without a scene the face is drawn
        over what ``out`` holds (or :data:`BACKGROUND`). The vertices and pose drawn are left in
        :attr:`shown`.

        Parameters
        ----------
        measured
            The source face's measured pose.
        offsets
            (K, 2) float array: the knot (x, y) offsets measured on the source face, its model
            units.
        size
            (width, height) of the frame, pixels.
        user
            The motion the user adds (:meth:`pose`, :meth:`vertices`; its ``gain`` also scales the
            irises' shifts).
        out
            (H, W, 3) uint8 RGB of ``size`` to draw into; None: a new image.
        look
            The eyes: lid closures and iris shifts.
        samples
            The actor's samples a stream chose for the frame, per group (eyes, mouth; None: the
            key frame's own); None: chosen by the shapes
            (:meth:`~facemime.animate.samples.SamplePainter.paint`).

        Returns
        -------
        (H, W, 3) uint8 array
            RGB, the frame: ``out`` when given.
        """
        vertices, pose = self.vertices(offsets, user, look), self.pose(measured, user)
        shown_look = Look(look.closure * user.gain, look.iris * user.gain)
        if self.samples is None:
            texture, inside = self.painter.texture(shown_look), None
        else:
            chosen = self.samples.choose(offsets * self._ratio * user.gain, shown_look, samples)
            # the eyes' sample covers the eyes: their irises are not moved under it
            still = Look(shown_look.closure) if chosen.get("eyes") is not None else shown_look
            texture, inside = self.samples.paint(self.painter.texture(still), chosen)
        interior = None if inside is None else (inside, *self._strip)
        self.shown = (vertices, pose)
        if self.scene is None:
            return synthesize(self.actor, vertices, pose, size, out=out, texture=texture, interior=interior)
        if out is None:
            out = np.empty((size[1], size[0], 3), np.uint8)
        if tuple(size) == self.scene.size:
            return synthesize(
                self.actor,
                vertices,
                pose,
                size,
                out=out,
                scene=self.scene,
                key=self._key,
                texture=texture,
                interior=interior,
            )
        synthesize(
            self.actor,
            vertices,
            pose,
            self.scene.size,
            out=self._picture,
            scene=self.scene,
            key=self._key,
            texture=texture,
            interior=interior,
        )
        return letterbox(self._picture, out)


def letterbox(image: np.ndarray, out: np.ndarray) -> np.ndarray:
    """An image scaled to fit another whole and centred, the margins :data:`BACKGROUND`.

    Parameters
    ----------
    image
        (h, w, 3) uint8 RGB: the image scaled.
    out
        (H, W, 3) uint8 RGB: drawn into, in place.

    Returns
    -------
    (H, W, 3) uint8 array
        ``out``.
    """
    h, w = out.shape[:2]
    f = min(w / image.shape[1], h / image.shape[0])
    sw, sh = max(1, round(image.shape[1] * f)), max(1, round(image.shape[0] * f))
    x0, y0 = (w - sw) // 2, (h - sh) // 2
    fill(out, BACKGROUND)
    shrink = cv2.INTER_AREA if f < 1 else cv2.INTER_LINEAR
    out[y0 : y0 + sh, x0 : x0 + sw] = cv2.resize(image, (sw, sh), interpolation=shrink)
    return out
