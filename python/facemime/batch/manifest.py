"""A batch's record: the manifest (``manifest.jsonl`` in the output folder, JSON Lines, one
object per video and attempt, appended as results come; the last line of a video is its state),
where each video's results go, and the check that a result is complete.

A manifest line has ``video`` (the item's name), ``path`` (the video file), ``what`` (track, run
or encode), ``status`` (``done``, ``failed`` or ``timed out``), ``frames`` (tracked or encoded),
``seconds`` (the task's wall time on its worker, s), ``mean_confidence`` (0-1 over the frames and
features; null for encode), ``lost_frames`` (frames with a lost feature), ``error`` (one line;
null when done), ``source`` (the video's ``bytes`` and ``mtime_ns`` when it was read),
``results`` (bytes of each result file, when done), ``warnings`` (when there were any) and
``finished`` (UTC, ISO 8601)."""

from __future__ import annotations

import json
import os
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from facemime.errors import FacemimeError
from facemime.io.outputs import OutputFileError

MANIFEST = "manifest.jsonl"
#: What a batch can make of each video, and the suffixes of its results (beside ``NAME``).
RESULTS = {"track": (".json",), "run": (".json", ".run.mp4"), "encode": (".fmstream",)}


def result_paths(out_dir: Path, name: str, what: str) -> list[Path]:
    """The result files of one video.

    Parameters
    ----------
    out_dir
        The batch's output folder.
    name
        The video's name (:attr:`facemime.batch.inputs.Item.name`: may contain ``/``).
    what
        What the batch makes: ``track``, ``run`` or ``encode`` (a key of :data:`RESULTS`).

    Returns
    -------
    list of Path
        ``out_dir/NAME`` with each suffix of ``RESULTS[what]``: the track JSON first, where there
        is one (``NAME.json``, then ``NAME.run.mp4`` for run; ``NAME.fmstream`` for encode).
    """
    return [out_dir / f"{name}{suffix}" for suffix in RESULTS[what]]


def source_stamp(path: Path) -> dict[str, int] | None:
    """The video file's size and modification time, recorded as ``source``: a changed video is
    redone.

    Parameters
    ----------
    path
        The video file.

    Returns
    -------
    dict or None
        ``{"bytes": size in bytes, "mtime_ns": modification time, ns since the epoch}``; None
        when the file cannot be read.
    """
    try:
        st = path.stat()
    except OSError:
        return None
    return {"bytes": st.st_size, "mtime_ns": st.st_mtime_ns}


def result_sizes(paths: list[Path]) -> dict[str, int] | None:
    """Bytes of each result file, recorded as ``results``: a result cut short or replaced after
    its batch is redone.

    Parameters
    ----------
    paths
        The video's result files (:func:`result_paths`).

    Returns
    -------
    dict or None
        File name (without the folder) to size in bytes; None when one is missing or unreadable.
    """
    try:
        return {p.name: p.stat().st_size for p in paths}
    except OSError:
        return None


def summarise(paths: list[Path], what: str) -> dict[str, Any]:
    """Parse and check the results of one video. Raises :class:`FacemimeError` when a result is
    missing, unreadable or incomplete: a track file whose frames do not run, one by one, to the
    video's last frame, a side-by-side video without that many frames, a stream that does not
    decode to its end.

    Parameters
    ----------
    paths
        The video's result files, in the order of :func:`result_paths`.
    what
        ``track``, ``run`` or ``encode``: what made them.

    Returns
    -------
    dict
        The manifest fields ``frames`` (int: frames tracked or decoded), ``mean_confidence``
        (float 0-1 over the frames and features, 4 decimals; None for encode or without
        confidences) and ``lost_frames`` (int: frames with a lost feature).
    """
    if what == "encode":
        return _summarise_stream(paths[0])
    from facemime.io.contours_json import load_document

    doc = load_document(paths[0], "track", "facemime.track/1")
    frames, video = doc.get("frames"), doc.get("video")
    if not isinstance(frames, list) or not frames or not isinstance(video, dict):
        raise FacemimeError(f"{paths[0]} has no frames")
    indices = [f.get("index") if isinstance(f, dict) else None for f in frames]
    first = indices[0] if isinstance(indices[0], int) else 0
    if indices != list(range(first, first + len(frames))) or first + len(frames) != video.get("frames"):
        raise FacemimeError(f"{paths[0]} is incomplete: frames {indices[0]}-{indices[-1]} of {video.get('frames')}")
    conf = [float(v) for f in frames for v in (f.get("confidence") or {}).values()]
    lost = sum(bool(f.get("lost")) for f in frames)
    if what == "run":
        _check_video(paths[1], len(frames))
    return {
        "frames": len(frames),
        "mean_confidence": round(sum(conf) / len(conf), 4) if conf else None,
        "lost_frames": lost,
    }


def _check_video(path: Path, frames: int) -> None:
    """Refuse a video that is not readable to its end with ``frames`` frames (its container's
    count; the file is written whole or not at all)."""
    import av

    try:
        with av.open(str(path)) as c:
            declared = c.streams.video[0].frames
    except (av.FFmpegError, OSError, IndexError) as e:
        raise FacemimeError(f"cannot read {path}: {e}") from None
    if declared != frames:
        raise FacemimeError(f"{path} has {declared} frames, expected {frames}")


def _summarise_stream(path: Path) -> dict[str, Any]:
    """Frames and frames with a lost feature of a ``.fmstream`` decoded to its end (the motion
    only: nothing is drawn)."""
    from facemime.codec.clip import read_stream
    from facemime.codec.decoder import MotionDecoder

    decoder = MotionDecoder(name=str(path))
    frames = decoder.push(read_stream(path)) + decoder.finish()
    if not frames or decoder.stats["concealed"] or decoder.stats["damaged_bytes"]:
        raise FacemimeError(f"{path} is damaged or incomplete")
    return {"frames": len(frames), "mean_confidence": None, "lost_frames": sum(bool(f.lost) for f in frames)}


class Manifest:
    """The manifest file of an output folder: :meth:`read` the last line of each video,
    :meth:`append` a line (flushed to disk at once: a batch killed at any moment loses at most the
    line being written, which a later read skips).

    Parameters
    ----------
    out_dir
        The batch's output folder; the manifest is ``out_dir/manifest.jsonl`` (:data:`MANIFEST`),
        its :attr:`path`.
    """

    def __init__(self, out_dir: Path):
        self.path = Path(out_dir) / MANIFEST

    def read(self) -> dict[str, dict[str, Any]]:
        """The last line of each video; unparsable lines are skipped. Raises
        :class:`~facemime.io.outputs.OutputFileError` when the file exists but cannot be read.

        Returns
        -------
        dict of str to dict
            Each video's name to its last manifest line (a JSON object); empty when there is no
            manifest yet.
        """
        last: dict[str, dict[str, Any]] = {}
        try:
            with open(self.path, encoding="utf-8") as f:
                for line in f:
                    try:
                        record = json.loads(line)
                    except ValueError:
                        continue
                    if isinstance(record, dict) and isinstance(record.get("video"), str):
                        last[record["video"]] = record
        except FileNotFoundError:
            pass
        except OSError as e:
            raise OutputFileError(f"cannot read {self.path}: {e.strerror or e}") from None
        return last

    def append(self, record: dict[str, Any]) -> None:
        """Append one line, creating the folder and file as needed; raises
        :class:`~facemime.io.outputs.OutputFileError` when it cannot be written.

        Parameters
        ----------
        record
            The video's manifest line (see the module); written with ``finished`` set to now (UTC,
            ISO 8601, seconds), ``record`` itself unchanged.
        """
        record = {**record, "finished": datetime.now(UTC).isoformat(timespec="seconds")}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "a", encoding="utf-8") as f:
                f.write(json.dumps(record, separators=(",", ":")) + "\n")
                f.flush()
                os.fsync(f.fileno())
        except OSError as e:
            raise OutputFileError(f"cannot write {self.path}: {e.strerror or e}") from None


def is_complete(record: dict[str, Any] | None, path: Path, paths: list[Path], what: str) -> bool:
    """Whether a video needs no new run.

    Parameters
    ----------
    record
        The video's last manifest line (:meth:`Manifest.read`); None when it has none.
    path
        The video file.
    paths
        Its result files (:func:`result_paths`).
    what
        ``track``, ``run`` or ``encode``: what the batch makes now.

    Returns
    -------
    bool
        True when ``record`` says done, for the same ``what`` and the same video file (size,
        modification time), the result files have the sizes it records, and they parse and check
        (:func:`summarise`) with as many frames as it records.
    """
    if not record or record.get("status") != "done" or record.get("what") != what:
        return False
    if record.get("source") != source_stamp(path) or record.get("results") != result_sizes(paths):
        return False
    try:
        return summarise(paths, what)["frames"] == record.get("frames")
    except (FacemimeError, OSError, ValueError):
        return False
