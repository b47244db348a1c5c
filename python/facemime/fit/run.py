"""Fitting an actor from a file: ``facemime fit`` and the tracker's automatic initialisation."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facemime.errors import InvalidInputError, NoFaceError
from facemime.fit.actor import smear_texture
from facemime.fit.auto import AutoPoints, auto_points
from facemime.fit.placement import fit_model
from facemime.fit.preview import preview_sheet
from facemime.head.generic import generic_head
from facemime.io.actor_file import actor_bytes
from facemime.io.outputs import Outputs, write_bytes, write_image
from facemime.io.photo import read_photo
from facemime.io.points_json import read_points
from facemime.types.actor import Actor
from facemime.types.contours import CONTOUR_NAMES
from facemime.types.head import HeadModel
from facemime.types.pose import project


@dataclass
class FitRun:
    """What :func:`fit_file` made: the actor, the files written, warnings for the user, the
    seconds spent finding points and fitting (reading and writing excluded), and how far the
    adjusted model's contours still are from the points (pixels)."""

    actor: Actor
    files: list[Path]
    warnings: list[str] = field(default_factory=list)
    seconds: float = 0.0
    residual: float = 0.0


def find_points(photo: np.ndarray, name: str) -> tuple[AutoPoints, list[str]]:
    """The reference points of the largest face of ``photo`` ((H, W, 3) uint8 RGB) and warnings
    (several faces); ``name`` names the photo in them and in the
    :class:`~facemime.errors.NoFaceError` raised where there is no face."""
    try:
        found = auto_points(photo)
    except NoFaceError:
        raise NoFaceError(f"no face found in {name}") from None
    faces = found.face.faces
    return found, [f"{faces} faces found in {name}; fitting the largest"] if faces > 1 else []


def fit_actor(
    photo: np.ndarray, name: str, points: dict | None = None, frame: int = 0, model: HeadModel | None = None
) -> tuple[Actor, list[str], float]:
    """Fit ``model`` (default: the generic head) to ``photo`` ((H, W, 3) uint8 RGB) on the given
    validated reference ``points`` or, without them, on points found automatically. ``name`` is
    the photo's file name, for messages and the actor's metadata. Returns the actor, warnings
    (several faces) and the final contour residual (pixels)."""
    model = model or generic_head()
    warnings: list[str] = []
    if points is None:
        found, warnings = find_points(photo, name)
        points = found.points
    fit = fit_model(model, points)
    source = {"file": Path(name).name, "frame": int(frame), "width": int(photo.shape[1]), "height": int(photo.shape[0])}
    return smear_texture(model, photo, fit, points, source), warnings, float(fit.residuals[-1])


def fit_file(
    source: str | Path, out: str | Path, frame: int = 0, points_file: str | Path | None = None, force: bool = False
) -> FitRun:
    """Fit an actor to ``source`` (an image, or frame ``frame`` of a video) and write ``out``
    (``NAME.actor``) and its preview ``NAME.preview.png``, both or neither; existing files are
    refused unless ``force``, an input always."""
    out = Path(out)
    if out.suffix.lower() != ".actor":
        raise InvalidInputError(f"the actor file name must end in .actor, got {out.name!r}")
    preview = out.with_suffix(".preview.png")
    with Outputs([out, preview], force, inputs=[source, points_file]) as outputs:
        photo = read_photo(source, frame)
        points = read_points(points_file, (photo.shape[1], photo.shape[0])) if points_file is not None else None
        t0 = time.perf_counter()
        try:
            actor, warnings, residual = fit_actor(photo, str(source), points, frame)
        except NoFaceError as e:
            raise NoFaceError(
                f"{e}; mark the face by hand and pass the points with --points POINTS.json (format facemime.points/1)"
            ) from None
        seconds = time.perf_counter() - t0
        write_bytes(outputs.stage(out), actor_bytes(actor))
        write_image(outputs.stage(preview), preview_sheet(actor, photo))
    return FitRun(actor, [out, preview], warnings, seconds, residual)


def init_contours(actor: Actor) -> dict[str, np.ndarray]:
    """The eight tracker contours of ``actor``: its mouth and brow vertices projected onto its
    source photo, name -> (K, 2) float64 pixels."""
    points = project(actor.model.vertices, actor.pose)[0]
    return {n: points[actor.model.groups[n]] for n in CONTOUR_NAMES}
