"""`facemime export`: the performance of a track file on an actor, written as binary glTF
(``.glb``, :mod:`facemime.export.performance`) or as a VRM 1.0 avatar of the actor's head
(``.vrm``, :mod:`facemime.export.vrm`), chosen by the output's suffix."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from facemime.errors import InputFileError, InvalidInputError
from facemime.export.performance import glb_bytes, load_performance
from facemime.export.vrm import vrm_bytes
from facemime.io.outputs import check_outputs, write_bytes
from facemime.types.actor import Actor


@dataclass(frozen=True)
class ExportResult:
    """What an export wrote: ``path``, ``frames``, ``controls`` (morph targets), ``bytes`` and
    ``seconds`` (wall time, reading the track to writing the file)."""

    path: Path
    frames: int
    controls: int
    bytes: int
    seconds: float


def export_track(
    track: str | Path, out: str | Path, actor: str | Path | Actor | None = None, force: bool = False
) -> ExportResult:
    """Write the performance of a track file on an actor as binary glTF: the head mesh with a
    morph target per expression control, animated by their weights and the head's pose; or, for
    a ``.vrm`` output, the head as a VRM 1.0 avatar with an expression per control.

    Parameters
    ----------
    track
        A ``facemime.track/1`` file from ``facemime run`` (or written by hand with weights).
    out
        The file to write; its name must end in ``.glb`` (binary glTF) or ``.vrm`` (VRM 1.0).
        Refused when it exists (unless ``force``) or is one of the inputs.
    actor
        The head that plays the track: an ``.actor`` file or an :class:`Actor`; None: the generic
        painted head (see :func:`~facemime.export.performance.load_performance`).
    force
        Write over an existing ``out``.

    Returns
    -------
    ExportResult
        The file written, its frames, controls (morph targets) and bytes, and the seconds taken.
    """
    from facemime.io.actor_file import load_actor

    t0 = time.perf_counter()
    out = Path(out)
    writer = {".glb": glb_bytes, ".vrm": vrm_bytes}.get(out.suffix.lower())
    if writer is None:
        raise InvalidInputError(f"the output must end in .glb or .vrm, got {out.name!r}")
    actor_path = actor if isinstance(actor, (str, Path)) else None
    check_outputs([out], force, inputs=[track, actor_path])
    if not Path(track).is_file():
        raise InputFileError(
            f"track file {track} does not exist" if not Path(track).exists() else f"track file {track} is not a file"
        )
    chosen = load_actor(actor) if isinstance(actor, (str, Path)) else actor
    perf = load_performance(track, chosen)
    data = writer(perf)
    write_bytes(out, data)
    return ExportResult(out, len(perf.times), len(perf.names), len(data), time.perf_counter() - t0)
