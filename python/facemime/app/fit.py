"""Fitting an actor from a file: ``facemime fit`` and the tracker's automatic initialisation."""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from facemime.codec.samples import library_from_clip
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
    source: str | Path,
    out: str | Path,
    frame: int = 0,
    points_file: str | Path | None = None,
    force: bool = False,
    samples_from: str | Path | None = None,
) -> FitRun:
    """Fit an actor to a photo and write its actor file and preview, both or neither.

    Parameters
    ----------
    source
        An image file, or a video (any FFmpeg reads) to take frame ``frame`` of.
    out
        The actor file to write, ``NAME.actor`` (the suffix is required); its preview sheet goes
        beside it as ``NAME.preview.png``. Existing files are refused unless ``force``; an input,
        always.
    frame
        0-based index of the video frame to fit to; must be 0 for an image.
    points_file
        A ``facemime.points/1`` file of reference points marked on the photo, used instead of
        finding them (needed where no face is found); None finds them.
    force
        Write over existing ``out`` and preview files.
    samples_from
        A clip of the same person (first frame frontal and neutral, like the photo) to take a
        library of the person's own mouth and eyes from (:func:`~facemime.codec.samples.library_from_clip`):
        the actor shows them wherever it is drawn; None: none.

    Returns
    -------
    FitRun
        The actor, the two files written, warnings, the seconds spent finding points and fitting,
        and the residual (pixels).
    """
    out = Path(out)
    if out.suffix.lower() != ".actor":
        raise InvalidInputError(f"the actor file name must end in .actor, got {out.name!r}")
    preview = out.with_suffix(".preview.png")
    with Outputs([out, preview], force, inputs=[source, points_file, samples_from]) as outputs:
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
        if samples_from is not None:
            library = library_from_clip(samples_from, actor)
            if library is None:
                warnings.append(
                    f"{samples_from}: the face's mouth and eyes never change there, so no samples were kept"
                )
            actor = replace(actor, samples=library)
        write_bytes(outputs.stage(out), actor_bytes(actor))
        write_image(outputs.stage(preview), preview_sheet(actor, photo))
    return FitRun(actor, [out, preview], warnings, seconds, residual)
