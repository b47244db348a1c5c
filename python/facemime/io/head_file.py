"""Head models: vertices, triangles, named vertex groups and deformation units.

Coordinates are model space: right-handed, x to the subject's left, y up, z towards the camera.
The generic head is in millimetres with its origin between the outer eye corners, which are
90 mm apart. Triangles wind counter-clockwise seen from outside (normals point out of the face).

Input policy (:mod:`facemime.limits`): every model loaded (``load_head``, ``load_wfm``, the
model inside an actor file) may have at most 200,000 vertices, 400,000 triangles and 20,000,000
deformation-unit values (units × vertices), and a model file at most 256 MiB; the variables
``FACEMIME_MAX_VERTICES``, ``FACEMIME_MAX_TRIANGLES``, ``FACEMIME_MAX_UNIT_VALUES`` and
``FACEMIME_MAX_MODEL_BYTES`` change them. A larger model is refused with
:class:`ModelFormatError` before its arrays are built, a larger file before it is read.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from facemime.errors import InputFileError, ModelFormatError
from facemime.limits import limit, parse_json
from facemime.types.head import MIN_GROUP_SIZES, REQUIRED_GROUPS, HeadModel, first_problem

HEAD_FORMAT = "facemime.head/1"

_COUNT_LIMITS = {
    "vertices": "FACEMIME_MAX_VERTICES",
    "triangles": "FACEMIME_MAX_TRIANGLES",
    "deformation unit values (units x vertices)": "FACEMIME_MAX_UNIT_VALUES",
}


def check_model_count(where: str, what: str, count: int) -> None:
    """Refuse a model of more vertices, triangles or unit values than the input policy allows.

    The refusal (:mod:`facemime.limits`) is a :class:`ModelFormatError` naming ``where``, the limit
    and how to raise it.

    Parameters
    ----------
    where
        What names the model (its file, section, line) in the message.
    what
        What is counted, a key of ``_COUNT_LIMITS``: ``"vertices"``, ``"triangles"`` or
        ``"deformation unit values (units x vertices)"``.
    count
        How many the model has.
    """
    variable = _COUNT_LIMITS[what]
    most = limit(variable)
    if count > most:
        raise ModelFormatError(
            f"{where}: the model has {count} {what}, more than the limit of {most}; set {variable} to allow more"
        )


def read_model_file(path: Path) -> bytes:
    """The bytes of a model file, within the input policy's size.

    Parameters
    ----------
    path
        The model file (``facemime.head/1`` JSON or CANDIDE ``.wfm``).

    Returns
    -------
    bytes
        The whole file. A file over the byte limit (``FACEMIME_MAX_MODEL_BYTES``) is refused with
        :class:`ModelFormatError` before it is read (or, when its size is unknown, after one byte
        more than the limit); a missing or unreadable one with :class:`InputFileError`.
    """
    most = limit("FACEMIME_MAX_MODEL_BYTES")
    too_big = f"more than the limit of {most} bytes; set FACEMIME_MAX_MODEL_BYTES to allow more"
    try:
        with path.open("rb") as f:
            size = os.fstat(f.fileno()).st_size
            if size > most:
                raise ModelFormatError(f"{path}: the model file has {size} bytes, {too_big}")
            data = f.read(most + 1)
    except FileNotFoundError:
        raise InputFileError(f"{path}: no such model file") from None
    except IsADirectoryError:
        raise InputFileError(f"{path}: is a folder, expected a model file") from None
    except OSError as e:
        raise InputFileError(f"{path}: cannot read model file ({e.strerror})") from None
    if len(data) > most:
        raise ModelFormatError(f"{path}: the model file has {too_big}")
    return data


def load_head(path: str | Path) -> HeadModel:
    """Load and validate a ``facemime.head/1`` JSON model file.

    Raises :class:`InputFileError` if it cannot be read and :class:`ModelFormatError`, naming the
    file and the problem, if it is not a valid model or is over a limit (see the module docstring).

    Parameters
    ----------
    path
        The model file.

    Returns
    -------
    HeadModel
        The model, in the file's ``unit`` (model space, see the module docstring).
    """
    path = Path(path)
    try:
        text = read_model_file(path).decode("utf-8")
    except UnicodeDecodeError:
        raise ModelFormatError(f"{path}: not a text file; expected a {HEAD_FORMAT} JSON model") from None
    return parse_head(text, str(path))


def parse_head(text: str, where: str) -> HeadModel:
    """Parse and validate the text of a ``facemime.head/1`` JSON model.

    Parameters
    ----------
    text
        The JSON text.
    where
        What names the model (its file) in error messages.

    Returns
    -------
    HeadModel
        The model; text that is not valid JSON or not a valid model raises
        :class:`ModelFormatError`.
    """
    try:
        doc = parse_json(text, where)
    except json.JSONDecodeError as e:
        raise ModelFormatError(f"{where}: not valid JSON ({e.msg} at line {e.lineno})") from None
    except ValueError as e:
        raise ModelFormatError(str(e)) from None
    return head_from_document(doc, where)


def head_document(model: HeadModel) -> dict[str, Any]:
    """``model`` as a ``facemime.head/1`` document.

    Parameters
    ----------
    model
        The model to store; its shape units are not stored.

    Returns
    -------
    dict
        The JSON-ready document, floats kept exactly; each deformation unit lists only the
        vertices it moves.
    """
    units = {
        name: {
            "description": model.descriptions.get(name, ""),
            "displacements": [[int(i), *d[i].tolist()] for i in np.flatnonzero(np.abs(d).max(axis=1) > 0)],
        }
        for name, d in model.units.items()
    }
    return {
        "format": HEAD_FORMAT,
        "name": model.name,
        "unit": model.unit,
        "vertices": model.vertices.tolist(),
        "triangles": model.triangles.tolist(),
        "uv": None if model.uv is None else model.uv.tolist(),
        "groups": {k: g.tolist() for k, g in model.groups.items()},
        "deformation_units": units,
    }


def _indices(value: object, where: str, what: str) -> np.ndarray:
    """Vertex indices as an int64 array; JSON numbers that are not integers (2.5, "2", true) are
    refused rather than rounded into another vertex."""
    raw = np.asarray(value)
    if raw.size and raw.dtype.kind not in "iu":
        raise ModelFormatError(f"{where}: {what} must list vertex indices as integers (of 64 bits at most)")
    return raw.astype(np.int64)


def head_from_document(doc: object, where: str) -> HeadModel:
    """Validate a parsed ``facemime.head/1`` document and build the model.

    Parameters
    ----------
    doc
        The parsed JSON document (anything: it is checked).
    where
        What names the document (its file, or the actor file holding it) in error messages.

    Returns
    -------
    HeadModel
        The model; an invalid document raises a :class:`ModelFormatError` naming ``where`` and
        the problem (also for a model over the vertex, triangle or deformation-unit-value limit,
        checked on the lists' lengths before any array is built).
    """
    if not isinstance(doc, dict) or doc.get("format") != HEAD_FORMAT:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise ModelFormatError(f"{where}: expected format {HEAD_FORMAT!r}, got {found!r}")
    for what in ("vertices", "triangles"):
        if isinstance(doc.get(what), list):
            check_model_count(where, what, len(doc[what]))
    if isinstance(doc.get("vertices"), list) and isinstance(doc.get("deformation_units"), dict):
        check_model_count(
            where, "deformation unit values (units x vertices)", len(doc["vertices"]) * len(doc["deformation_units"])
        )
    try:
        vertices = np.asarray(doc["vertices"], dtype=np.float64)
        n = len(vertices)
        triangles = _indices(doc["triangles"], where, "triangles")
        uv = np.asarray(doc["uv"], dtype=np.float64) if doc.get("uv") is not None else None
        groups = {str(k): _indices(g, where, f"group {k!r}") for k, g in doc["groups"].items()}
        units, descriptions = {}, {}
        for name, u in doc.get("deformation_units", {}).items():
            dense = np.zeros((n, 3))
            for row in u["displacements"]:
                i, dx, dy, dz = row
                if not (isinstance(i, int) and 0 <= i < n):
                    raise ModelFormatError(
                        f"{where}: deformation unit {name!r} names vertex {i!r}, but there are {n} vertices"
                    )
                dense[i] = (dx, dy, dz)
            units[str(name)] = dense
            descriptions[str(name)] = str(u.get("description", ""))
    except ModelFormatError:
        raise
    except KeyError as e:
        raise ModelFormatError(f"{where}: missing field {e.args[0]!r}") from None
    except (TypeError, ValueError, AttributeError, OverflowError) as e:
        raise ModelFormatError(f"{where}: malformed model ({e})") from None
    missing = [g for g in REQUIRED_GROUPS if g not in groups]
    if missing:
        raise ModelFormatError(f"{where}: missing vertex groups {', '.join(missing)}")
    problem = first_problem(vertices, triangles, uv, groups, (units,))
    if problem:
        raise ModelFormatError(f"{where}: {problem}")
    short = [f"{g} has {len(groups[g])} (needs {n})" for g, n in MIN_GROUP_SIZES.items() if len(groups[g]) < n]
    if short:
        raise ModelFormatError(f"{where}: vertex groups too short: {'; '.join(short)}")
    for lips in ("mouth_outer", "mouth_inner"):  # drawn and sealed pairwise, corner to corner
        upper, lower = len(groups[f"{lips}_upper"]), len(groups[f"{lips}_lower"])
        if upper != lower:
            raise ModelFormatError(
                f"{where}: {lips}_upper and {lips}_lower must have the same number of vertices, got {upper} and {lower}"
            )
    return HeadModel(
        vertices,
        triangles,
        uv,
        groups,
        units,
        {},
        descriptions,
        str(doc.get("name", where)),
        str(doc.get("unit", "mm")),
    )
