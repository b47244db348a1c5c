"""The project's contour interchange files (see the shared data README):

- ``facemime.init/1``: the eight contours of one frame that start a tracker;
- ``facemime.track/1``: every frame's contours written by a tracker.

Points are (x, y) pixels, origin at the centre of the top-left pixel, y down. ``facemime``
extends ``facemime.track/1`` compatibly with per-frame keys:

- ``confidence``: feature -> 0..1; ``lost``: features whose contours collapsed in that frame;
- ``face`` (``facemime run``): false in frames where the face was not found (it left the frame
  or turned away); their contours repeat the last good ones;
- ``pose``: the head pose, ``yaw``, ``pitch``, ``roll`` in degrees (rotations of the model about
  its own y, x, z axes, applied yaw first), ``scale`` in pixels per model unit and ``tx``, ``ty``
  the pixel position of the model origin (orthographic, see
  :mod:`facemime.types.pose`);
- ``offsets``: (K, 2) displacements of the model's contour vertices (the knots) in the head's own
  frame, model units, relative to the first frame: the local motion that drives synthesis;
- ``look``: the eyes, relative to the first frame (names and units in
  :mod:`facemime.types.look`: ``eye_right_closure``, ``iris_right_u``, ...); a name left
  out is 0;
- ``weights``: named expression weights, name -> 0..1 (the non-zero ones, 4 decimals; names and
  what they do in :mod:`facemime.animate.expressions`), solved from the offsets and the look. A
  frame with ``weights`` and no ``offsets`` is played from its weights (a performance written by
  hand); the file then needs no ``model`` block (the generic head's knots are assumed);
- ``arkit`` (``facemime run``): ARKit's 52 blendshapes as ``facemime live`` sends them, name ->
  0..1 (the non-zero ones, 4 decimals; :mod:`facemime.animate.arkit`): what ``facemime export``
  animates;

and a top-level ``model``: ``unit`` (of the offsets and of the model), ``knots`` (the K model
vertex indices the offsets belong to), ``feature_sizes`` (K widths of each knot's feature,
model units) and ``iod`` (distance between the outer eye corners, model units): what carrying
the motion to another face needs. ``facemime run`` adds, when it synthesises the face in its
own scene, per frame ``scene_departure`` (0..1: the share of pixels around the face, or inside
it, that differ from the synthesis, :mod:`facemime.animate.departure`) and ``scene_departs``
(bool: reported), and a top-level ``scene_departs``: the [first, last] ranges of reported
frames.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from facemime.errors import FacemimeError
from facemime.io.outputs import OutputFileError, write_text
from facemime.limits import parse_json, read_json_text
from facemime.types.contours import CONTOUR_NAMES

INIT_FORMAT = "facemime.init/1"
POSE_KEYS = ("yaw", "pitch", "roll", "scale", "tx", "ty")
#: Largest magnitude of a knot offset a track file may hold, model units (a face is ~150 wide).
MAX_OFFSET = 1e4
#: Largest magnitude of a look value a track file may hold (closures, eye widths).
LOOK_LIMIT = 10.0
TRACK_FORMAT = "facemime.track/1"

Contours = dict[str, np.ndarray]


class ContourFileError(FacemimeError, ValueError):
    """An init or track JSON file is malformed."""


def load_json(path: str | Path, what: str) -> Any:
    """The JSON document in a file, read within the input policy's size (:mod:`facemime.limits`).

    Parameters
    ----------
    path
        The JSON file.
    what
        The kind of file (``"init"``, ``"track"``, ``"points"``), named in error messages.

    Returns
    -------
    Any
        The parsed document; a file that is not UTF-8 JSON raises :class:`ContourFileError`.
    """
    p = Path(path)
    data = read_json_text(p, what)
    try:
        return parse_json(data.decode("utf-8"), str(p))
    except UnicodeDecodeError:
        raise ContourFileError(f"{p} is not a JSON text file") from None
    except json.JSONDecodeError as e:
        raise ContourFileError(f"{p} is not valid JSON: {e.msg} at line {e.lineno} column {e.colno}") from None
    except ValueError as e:
        raise ContourFileError(str(e)) from None


def load_document(path: str | Path, what: str, fmt: str) -> dict[str, Any]:
    """Read a JSON file and check that it is a document of the expected format.

    Parameters
    ----------
    path
        The JSON file.
    what
        The kind of file (``"init"``, ``"track"``, ``"points"``), named in error messages.
    fmt
        The format name its ``"format"`` must hold, e.g. ``"facemime.init/1"``.

    Returns
    -------
    dict
        The document; another format raises :class:`ContourFileError`.
    """
    doc = load_json(path, what)
    if not isinstance(doc, dict) or doc.get("format") != fmt:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise ContourFileError(f"{path}: expected format {fmt!r}, found {found!r}")
    return doc


def _contours(doc: Mapping[str, Any], where: str, size: tuple[int, int] | None, require_all: bool) -> Contours:
    raw = doc.get("contours")
    if not isinstance(raw, dict):
        raise ContourFileError(f"{where}: 'contours' must be an object of named point lists")
    missing = [n for n in CONTOUR_NAMES if n not in raw]
    if require_all and missing:
        raise ContourFileError(f"{where}: missing contour {', '.join(missing)}")
    out: Contours = {}
    for name, pts in raw.items():
        try:
            arr = np.asarray(pts, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            raise ContourFileError(f"{where}: contour {name} must be a list of [x, y] numbers") from None
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 2:
            raise ContourFileError(f"{where}: contour {name} must have at least 2 [x, y] points, got shape {arr.shape}")
        if not np.isfinite(arr).all():
            raise ContourFileError(f"{where}: contour {name} has a non-finite coordinate")
        if size is not None:
            w, h = size
            outside = (arr[:, 0] < -0.5) | (arr[:, 0] > w - 0.5) | (arr[:, 1] < -0.5) | (arr[:, 1] > h - 0.5)
            if outside.any():
                x, y = arr[np.argmax(outside)]
                raise ContourFileError(f"{where}: contour {name} point ({x:g}, {y:g}) is outside the {w}x{h} image")
        out[name] = arr
    return out


def read_init(path: str | Path, size: tuple[int, int] | None = None) -> tuple[int, Contours]:
    """Read a ``facemime.init/1`` file.

    Parameters
    ----------
    path
        The init file.
    size
        (width, height) of the video, pixels: every point must then lie inside the image (within
        half a pixel of the outer pixels' centres). None checks no bounds.

    Returns
    -------
    frame : int
        The 0-based index of the frame the contours are on (0 when the file has no ``frame``).
    contours : dict of str -> (N, 2) float64 array
        The eight contours by name, (x, y) pixels.
    """
    doc = load_document(path, "init", INIT_FORMAT)
    where = str(path)
    frame = doc.get("frame", 0)
    if not isinstance(frame, int) or isinstance(frame, bool) or frame < 0:
        raise ContourFileError(f"{where}: 'frame' must be a non-negative integer, got {frame!r}")
    return frame, _contours(doc, where, size, require_all=True)


def init_document(frame: int, contours: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """A ``facemime.init/1`` document.

    Parameters
    ----------
    frame
        0-based index of the frame the contours are on.
    contours
        The eight contours by name (:data:`facemime.types.contours.CONTOUR_NAMES`, all required),
        each (N, 2) (x, y) pixels; other names are left out.

    Returns
    -------
    dict
        The JSON-ready document, coordinates rounded to 0.001 pixel.
    """
    return {
        "format": INIT_FORMAT,
        "frame": int(frame),
        "contours": {n: np.round(np.asarray(contours[n], float), 3).tolist() for n in CONTOUR_NAMES},
    }


def track_document(
    video: Mapping[str, Any],
    frames: Sequence[Mapping[str, Any]],
    timing: Mapping[str, float] | None = None,
    model: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """A ``facemime.track/1`` document.

    Parameters
    ----------
    video
        The video's ``width``, ``height`` (pixels), ``fps`` (frames/s) and ``frames`` (count);
        other keys are left out.
    frames
        One mapping per frame, as :func:`track_entry` takes: ``index``, ``contours`` (name -> (N, 2)
        (x, y) pixels) and optionally ``confidence`` (feature -> 0..1), ``lost`` (list of
        features), ``redetected`` (bool: the face landmark model put the contours right on this
        frame), ``face`` (bool), ``pose`` (key -> value, degrees and pixels), ``offsets`` ((K, 2)
        model units), ``look``, ``weights``, ``arkit`` and ``scene_departure`` with ``scene_departs``.
    timing
        The top-level ``timing`` entry (``processing_seconds``, ``frames_processed``); None leaves
        it out.
    model
        The top-level ``model`` entry: ``unit``, ``knots``, ``feature_sizes``, ``iod``, what the
        offsets belong to (see the module docstring); None leaves it out.

    Returns
    -------
    dict
        The JSON-ready document.
    """
    doc: dict[str, Any] = {"format": TRACK_FORMAT, "frames": [track_entry(f) for f in frames]}
    return {**doc, **_closing(video, timing, model)}


def _closing(
    video: Mapping[str, Any],
    timing: Mapping[str, float] | None,
    model: Mapping[str, Any] | None,
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """A track document's entries after its frames (``extra``: more top-level entries)."""
    out: dict[str, Any] = {"video": {k: video[k] for k in ("width", "height", "fps", "frames")}, **(extra or {})}
    if model is not None:
        out["model"] = dict(model)
    if timing is not None:
        out["timing"] = dict(timing)
    return out


def track_entry(f: Mapping[str, Any]) -> dict[str, Any]:
    """One frame's entry of a track document, rounded to what the format keeps.

    Parameters
    ----------
    f
        The frame: ``index``, ``contours`` and the optional keys that :func:`track_document`
        lists; other keys are left out.

    Returns
    -------
    dict
        The JSON-ready entry: coordinates and offsets to 0.001, confidences, pose values, look,
        weights, ARKit values and scene departure to 4 decimals.
    """
    entry: dict[str, Any] = {
        "index": int(f["index"]),
        "contours": {n: np.round(np.asarray(c, float), 3).tolist() for n, c in f["contours"].items()},
    }
    if "confidence" in f:
        entry["confidence"] = {k: round(float(v), 4) for k, v in f["confidence"].items()}
    if "lost" in f:
        entry["lost"] = list(f["lost"])
    if "redetected" in f:
        entry["redetected"] = bool(f["redetected"])
    if "face" in f:
        entry["face"] = bool(f["face"])
    if "pose" in f:
        entry["pose"] = {k: round(float(v), 4) for k, v in f["pose"].items()}
    if "offsets" in f:
        entry["offsets"] = np.round(np.asarray(f["offsets"], float), 3).tolist()
    if "look" in f:
        entry["look"] = {k: round(float(v), 4) for k, v in f["look"].items()}
    for key in ("weights", "arkit"):
        if key in f:
            entry[key] = {k: round(float(v), 4) for k, v in f[key].items()}
    if "scene_departure" in f:
        entry["scene_departure"] = round(float(f["scene_departure"]), 4)
        entry["scene_departs"] = bool(f["scene_departs"])
    return entry


class TrackWriter:
    """Writes a ``facemime.track/1`` document frame by frame to ``path`` (a file that the caller
    puts in place when complete, :class:`facemime.io.outputs.Outputs`), so that a long video's
    track is not held in memory: :meth:`append` each frame (as for :func:`track_document`), then
    :meth:`close` with what comes after the frames.

    Parameters
    ----------
    path
        The file to write, opened (and truncated) at once.
    """

    def __init__(self, path: Path):
        self._path = path
        self._file = self._io(lambda: open(path, "w", encoding="utf-8"))  # noqa: SIM115 (open until close())
        self._write(f'{{"format": {json.dumps(TRACK_FORMAT)}, "frames": [')
        self.frames = 0

    def _io(self, act: Any) -> Any:
        try:
            return act()
        except OSError as e:  # a full disk, a file too large: one line
            raise OutputFileError(f"cannot write {self._path}: {e.strerror or e}") from None

    def _write(self, text: str) -> None:
        self._io(lambda: self._file.write(text))

    def append(self, frame: Mapping[str, Any]) -> None:
        """Write one frame's entry.

        Parameters
        ----------
        frame
            The frame, as :func:`track_document` takes it (see :func:`track_entry`).
        """
        self._write(("," if self.frames else "") + "\n" + json.dumps(track_entry(frame)))
        self.frames += 1

    def close(
        self,
        video: Mapping[str, Any],
        timing: Mapping[str, float] | None = None,
        model: Mapping[str, Any] | None = None,
        extra: Mapping[str, Any] | None = None,
    ) -> None:
        """Write the entries after the frames and close the file.

        Parameters
        ----------
        video
            The video's ``width``, ``height`` (pixels), ``fps`` (frames/s) and ``frames`` (count).
        timing
            The top-level ``timing`` entry; None leaves it out.
        model
            The top-level ``model`` entry (see :func:`track_document`); None leaves it out.
        extra
            More top-level entries (``scene_departs``); None for none.
        """
        self._write("\n], " + json.dumps(_closing(video, timing, model, extra))[1:])
        self._io(self._file.close)

    def __enter__(self) -> TrackWriter:
        return self

    def __exit__(self, exc_type: type | None, *exc: object) -> None:
        try:
            self._io(self._file.close)
        except OutputFileError:
            if exc_type is None:
                raise


def write_json(path: str | Path, doc: Mapping[str, Any]) -> Path:
    """Write a JSON document atomically, compact, on one line.

    Parameters
    ----------
    path
        The file to write (an init or track file); its folder is created if missing.
    doc
        The document, as :func:`init_document` or :func:`track_document` make it.

    Returns
    -------
    Path
        ``path``.
    """
    return write_text(path, json.dumps(doc, separators=(",", ":")) + "\n")


def read_track(path: str | Path) -> tuple[dict[str, Any], dict[int, Contours]]:
    """Read a ``facemime.track/1`` file's contours.

    Parameters
    ----------
    path
        The track file.

    Returns
    -------
    video : dict
        The file's ``video`` entry (``width``, ``height``, ``fps``, ``frames``), ``{}`` when it
        has none.
    contours : dict of int -> dict of str -> (N, 2) float64 array
        Frame index -> the contours of that frame by name, (x, y) pixels.
    """
    doc = load_document(path, "track", TRACK_FORMAT)
    where = str(path)
    frames = doc.get("frames")
    if not isinstance(frames, list):
        raise ContourFileError(f"{where}: 'frames' must be a list")
    out: dict[int, Contours] = {}
    for k, f in enumerate(frames):
        if not isinstance(f, dict) or not isinstance(f.get("index"), int):
            raise ContourFileError(f"{where}: frame entry {k} must be an object with an integer 'index'")
        out[f["index"]] = _contours(f, f"{where} frame {f['index']}", None, require_all=False)
    return doc.get("video", {}), out
