"""The actor: a head model fitted to one person, with that person's face smeared on it as texture.

Model coordinates are the generic head's (right-handed, x to the subject's left, y up, z towards
the camera, millimetres for the built-in head). Texture coordinates are in [0, 1] from the
texture's top-left corner; texel (i, j) has its centre at ((i + 0.5) / W, (j + 0.5) / H).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from facemime.errors import InvalidInputError, NoFaceError
from facemime.fit.adjust import OPEN_LIPS, Fit, fit_model
from facemime.fit.auto import AutoPoints, auto_points
from facemime.head.generic import generic_head
from facemime.head.texture import painted_texture
from facemime.types.actor import Actor
from facemime.types.contours import CONTOUR_NAMES
from facemime.types.head import HeadModel, lip_strip, mouth_up, mouth_width
from facemime.types.points import ReferencePoints
from facemime.types.pose import Pose, project

#: The texture is the photo cropped around the face with this margin (fraction of the face size)
#: and shrunk, if needed, to at most this many pixels on its longer side.
TEXTURE_MARGIN = 0.08
TEXTURE_MAX_SIDE = 1024
#: The scene (the whole source photo) is shrunk, if needed, to at most this many pixels a side.
SCENE_MAX_SIDE = 2048
#: A photo whose inner lips stand further apart than this share of the mouth's width somewhere
#: (the fit's open mouth, :data:`~facemime.fit.adjust.OPEN_LIPS`: twice the gap the synthesis
#: seals, an opening it shows at its full size) has the opening closed in the actor's mesh by
#: triangles between the inner lips (:func:`mouth_cap`), so that the actor shows the photo's own
#: teeth and mouth where the synthesis would otherwise draw an interior over them. Of the shared
#: videos' first frames, st_aoc's, st_kh's, mt_sun's and vr_2's are that open (0.13-0.45 by the
#: landmarks); the others at most 0.044.
CAP_OPENING = OPEN_LIPS


def smear_texture(model: HeadModel, photo: np.ndarray, fit: Fit, points: ReferencePoints, source: dict) -> Actor:
    """Build the actor: the model with the fit's vertices, textured by the photo — each vertex's
    texture coordinate is where it projects in the photo (docs/method.md §2.4).

    Parameters
    ----------
    model
        The head fitted; its triangles, groups and units are kept, its vertices and ``uv``
        replaced.
    photo
        (H, W, 3) uint8 RGB: the photo the model was fitted on.
    fit
        The fit of ``model`` to ``photo``: adjusted vertices (model units) and frontal pose.
    points
        The reference points fitted to, name -> (K, 2) (x, y) pixels of ``photo``.
    source
        Where the photo came from: ``file`` (name only), ``frame``, ``width``, ``height``
        (pixels); copied into the actor.

    Returns
    -------
    Actor
        Its texture the photo cropped around the projected face (margin :data:`TEXTURE_MARGIN`
        of the face's size) and shrunk to at most :data:`TEXTURE_MAX_SIDE` pixels a side, its
        scene the whole photo shrunk to at most :data:`SCENE_MAX_SIDE` pixels a side.
    """
    h, w = photo.shape[:2]
    px = project(fit.vertices, fit.pose)[0]
    lo, hi = px.min(axis=0), px.max(axis=0)
    pad = TEXTURE_MARGIN * (hi - lo).max()
    x0, y0 = (int(np.clip(np.floor(v), 0, n - 1)) for v, n in zip(lo - pad, (w, h)))
    x1, y1 = (int(np.clip(np.ceil(v), 1, n)) for v, n in zip(hi + pad, (w, h)))
    if x1 - x0 < 8 or y1 - y0 < 8:
        raise InvalidInputError(f"the fitted face covers only {x1 - x0}x{y1 - y0} pixels of the image")
    crop = _shrunk(photo[y0:y1, x0:x1], TEXTURE_MAX_SIDE)
    uv = np.clip((px - [x0, y0] + 0.5) / [x1 - x0, y1 - y0], 0.0, 1.0)
    capped = {frozenset(t) for t in lip_strip(model).tolist()}  # a cap of an earlier fit goes
    kept = np.array([frozenset(t) not in capped for t in model.triangles.tolist()], bool)
    triangles = np.concatenate([model.triangles[kept], mouth_cap(model, fit.vertices, px)])
    name = f"{source.get('file', 'photo')} actor"
    adjusted = replace(model, vertices=fit.vertices, uv=uv, name=name, triangles=triangles)
    return Actor(
        adjusted,
        crop,
        fit.pose,
        dict(source),
        {k: np.asarray(v, float) for k, v in points.items()},
        _shrunk(photo, SCENE_MAX_SIDE),
    )


def mouth_cap(model: HeadModel, vertices: np.ndarray, px: np.ndarray) -> np.ndarray:
    """Triangles that close the mouth's opening between the inner lips, where a photo shows it
    open wider than :data:`CAP_OPENING` of the mouth's width.

    The strip between the two inner lips, knot to knot, two triangles a pair of knots (none where
    the lips share a vertex: the corners). Textured at the photo's positions of those vertices,
    they show the photo's own mouth; as the lips close they fold away, and the synthesis's drawn
    interior, behind the mesh, is covered wherever they stand.

    Parameters
    ----------
    model
        The head, with the inner lips' groups.
    vertices
        (N, 3) float array: the model's vertices as fitted to the photo, model units.
    px
        (N, 2) float array: where the vertices project in the photo, (x, y) pixels; sets each
        triangle's winding, front-facing as the renderer culls (clockwise on the image, y down).

    Returns
    -------
    (M, 3) int64 array
        Vertex indices; (0, 3) where the lips are closer, or the inner lips' knot counts differ.
    """
    upper, lower = model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]
    none = np.zeros((0, 3), np.int64)
    up = mouth_up(model, vertices)
    if len(upper) != len(lower) or up is None:
        return none
    gap = (vertices[upper, :2] - vertices[lower, :2]) @ up
    if gap.max() <= CAP_OPENING * mouth_width(model, vertices):
        return none
    out = lip_strip(model)
    e1, e2 = px[out[:, 1]] - px[out[:, 0]], px[out[:, 2]] - px[out[:, 0]]
    back = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0.0  # the renderer's back faces
    out[back] = out[back][:, ::-1]
    return out


def _shrunk(image: np.ndarray, side: int) -> np.ndarray:
    """A contiguous copy of ``image``, shrunk (area average) to at most ``side`` pixels on its
    longer side."""
    f = side / max(image.shape[:2])
    if f >= 1.0:
        return np.ascontiguousarray(image).copy()
    return cv2.resize(
        image, (max(1, round(image.shape[1] * f)), max(1, round(image.shape[0] * f))), interpolation=cv2.INTER_AREA
    )


def generic_actor(size: tuple[int, int] = (512, 512)) -> Actor:
    """The generic head with its painted texture, as an actor framed in a view.

    Parameters
    ----------
    size
        (width, height) of the view, pixels.

    Returns
    -------
    Actor
        The generic head (millimetres) with a 512 x 512 painted texture, frontal, centred and
        filling 0.8 of the view's tighter side; no source, points or scene.
    """
    head = generic_head()
    return Actor(head, painted_texture(head, 512), Pose.framing(head.vertices, size, 0.8))


def find_points(photo: np.ndarray, name: str) -> tuple[AutoPoints, list[str]]:
    """The reference points of the largest face of a photo, and warnings (several faces).

    Parameters
    ----------
    photo
        (H, W, 3) uint8 RGB.
    name
        Names the photo in the warnings and in the :class:`~facemime.errors.NoFaceError`
        raised where there is no face.

    Returns
    -------
    found : AutoPoints
        The points, (x, y) pixels of ``photo``, and the face they were found on.
    warnings : list of str
        One line when there are several faces; else empty.
    """
    try:
        found = auto_points(photo)
    except NoFaceError:
        raise NoFaceError(f"no face found in {name}") from None
    faces = found.face.faces
    return found, [f"{faces} faces found in {name}; fitting the largest"] if faces > 1 else []


def fit_actor(
    photo: np.ndarray, name: str, points: dict | None = None, frame: int = 0, model: HeadModel | None = None
) -> tuple[Actor, list[str], float]:
    """Fit a head model to a photo on given reference points or, without them, on points found
    automatically.

    Parameters
    ----------
    photo
        (H, W, 3) uint8 RGB.
    name
        The photo's file name, for messages and the actor's metadata (its last path component).
    points
        Validated reference points (:func:`facemime.types.points.check_points`), name -> (K, 2)
        (x, y) pixels of ``photo``; None: found automatically on the largest face.
    frame
        The photo's frame index in its video (0 for a still image), for the actor's metadata.
    model
        The head fitted; None: the generic head.

    Returns
    -------
    actor : Actor
        The fitted, textured head (:func:`smear_texture`).
    warnings : list of str
        For the user (several faces found); empty with given ``points``.
    residual : float
        Mean contour disagreement after the elastic adjustment, pixels.
    """
    model = model or generic_head()
    warnings: list[str] = []
    if points is None:
        found, warnings = find_points(photo, name)
        points = found.points
    fit = fit_model(model, points)
    source = {"file": Path(name).name, "frame": int(frame), "width": int(photo.shape[1]), "height": int(photo.shape[0])}
    return smear_texture(model, photo, fit, points, source), warnings, float(fit.residuals[-1])


def init_contours(actor: Actor) -> dict[str, np.ndarray]:
    """The eight tracker contours of an actor: its mouth and brow vertices projected onto its
    source photo.

    Parameters
    ----------
    actor
        A fitted actor; its pose maps its model onto its source photo.

    Returns
    -------
    dict of str -> (K, 2) float64 array
        Contour name (:data:`~facemime.types.contours.CONTOUR_NAMES`) -> (x, y) pixels of the
        source photo, ordered image-left to image-right.
    """
    points = project(actor.model.vertices, actor.pose)[0]
    return {n: points[actor.model.groups[n]] for n in CONTOUR_NAMES}
