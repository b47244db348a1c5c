"""The videos of a batch: every video file under a folder (its subfolders included), or the
paths listed in a text file, each with the name its results are written under."""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

from facemime.errors import InputFileError, InvalidInputError

#: File name endings taken for videos when a folder is given (any case).
VIDEO_SUFFIXES = (".mp4", ".mov", ".m4v", ".mkv", ".webm", ".avi", ".mpg", ".mpeg", ".ts", ".flv", ".wmv")


@dataclass(frozen=True)
class Item:
    """One video of a batch: ``name``, the results' path inside the output folder without a
    suffix (the video's path relative to the input folder, or its stem for a list), and
    ``path``, the video file."""

    name: str
    path: Path


def list_videos(source: str | Path) -> list[Item]:
    """The videos of a batch. One-line errors (:class:`~facemime.errors.InputFileError`,
    :class:`~facemime.errors.InvalidInputError`) for a missing or unreadable source and for one
    with no videos.

    Parameters
    ----------
    source
        A folder (the video files found in it and below, by their ending, see
        :data:`VIDEO_SUFFIXES`; names starting with ``.`` skipped) or a text file with one video
        path a line (relative to the file's folder; blank lines and lines starting with ``#``
        skipped; listed files need not exist: a missing one fails alone).

    Returns
    -------
    list of Item
        For a folder, sorted by path and named by the path relative to ``source`` without its
        suffix; for a list, in its order (repeats dropped) and named by the file's stem (with 8 hex
        digits of a hash of its absolute path where several files share a stem).
    """
    source = Path(source)
    if not source.exists():
        raise InputFileError(f"input {source} does not exist")
    if source.is_dir():
        items = [Item(p.relative_to(source).with_suffix("").as_posix(), p) for p in _walk(source)]
        if not items:
            raise InvalidInputError(f"no videos in {source} (looked for files ending in {', '.join(VIDEO_SUFFIXES)})")
        return items
    try:
        text = source.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InvalidInputError(f"{source} is neither a folder nor a text file listing videos") from None
    except OSError as e:
        raise InputFileError(f"cannot read {source}: {e.strerror or e}") from None
    paths = [Path(line.strip()) for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    if not paths:
        raise InvalidInputError(f"no videos listed in {source}")
    paths = [p if p.is_absolute() else source.parent / p for p in paths]
    return _named(list(dict.fromkeys(paths)))


def _walk(folder: Path) -> list[Path]:
    """Video files under ``folder``, sorted; an unreadable folder raises :class:`InputFileError`."""

    def fail(e: OSError) -> None:
        raise InputFileError(f"cannot read folder {e.filename or folder}: {e.strerror or e}") from None

    found = []
    for root, dirs, files in os.walk(folder, onerror=fail):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        found += [Path(root) / f for f in files if not f.startswith(".") and f.lower().endswith(VIDEO_SUFFIXES)]
    return sorted(found)


def _named(paths: list[Path]) -> list[Item]:
    """Items named by the files' stems; stems that several files share get 8 hex digits of a
    hash of the file's absolute path, so that a name does not depend on the list's order."""
    stems: dict[str, int] = {}
    for p in paths:
        stems[p.stem] = stems.get(p.stem, 0) + 1
    return [
        Item(
            p.stem if stems[p.stem] == 1 else f"{p.stem}-{hashlib.sha1(str(p.absolute()).encode()).hexdigest()[:8]}", p
        )
        for p in paths
    ]
