"""Fitting an actor from a file: ``facemime fit`` and the tracker's automatic initialisation."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from facemime.errors import InvalidInputError, NoFaceError
from facemime.fit.actor import fit_actor
from facemime.fit.preview import preview_sheet
from facemime.io.actor_file import actor_bytes
from facemime.io.outputs import Outputs, write_bytes, write_image
from facemime.io.photo import read_photo
from facemime.io.points_json import read_points
from facemime.types.actor import Actor


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
