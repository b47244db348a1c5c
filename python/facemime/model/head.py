"""Head models: vertices, triangles, named vertex groups and deformation units.

Coordinates are model space: right-handed, x to the subject's left, y up, z towards the camera.
The generic head is in millimetres with its origin between the outer eye corners, which are
90 mm apart. Triangles wind counter-clockwise seen from outside (normals point out of the face).

Input policy (:mod:`facemime.io.limits`): every model loaded (``load_head``, ``load_wfm``, the
model inside an actor file) may have at most 200,000 vertices, 400,000 triangles and 20,000,000
deformation-unit values (units × vertices), and a model file at most 256 MiB; the variables
``FACEMIME_MAX_VERTICES``, ``FACEMIME_MAX_TRIANGLES``, ``FACEMIME_MAX_UNIT_VALUES`` and
``FACEMIME_MAX_MODEL_BYTES`` change them. A larger model is refused with
:class:`ModelFormatError` before its arrays are built, a larger file before it is read.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from facemime.errors import InputFileError, InvalidInputError, ModelFormatError
from facemime.io.limits import limit, parse_json
from facemime.shared_constants import CONTOUR_GROUPS

HEAD_FORMAT = "facemime.head/1"

#: Groups every facemime head file must have.
REQUIRED_GROUPS = CONTOUR_GROUPS + ("eye_left", "eye_right", "nose", "face_outline")
#: The fewest vertices each required group needs: an eye ring is corner, three upper-lid vertices,
#: corner, three lower-lid ones; the outline's tenth vertex is the chin, the nose's seventh its tip;
#: a contour is a curve.
MIN_GROUP_SIZES = {**dict.fromkeys(CONTOUR_GROUPS, 2), "eye_left": 8, "eye_right": 8, "nose": 7, "face_outline": 10}
#: Default input limits, each overridden by its environment variable (see the module docstring).
#: Largest vertex coordinate, model units (a face is some hundreds of millimetres; a farther vertex
#: is a broken file, and would overflow the pixel arithmetic of previews).
MAX_COORDINATE = 1e6
_COUNT_LIMITS = {
    "vertices": "FACEMIME_MAX_VERTICES",
    "triangles": "FACEMIME_MAX_TRIANGLES",
    "deformation unit values (units x vertices)": "FACEMIME_MAX_UNIT_VALUES",
}


def check_model_count(where: str, what: str, count: int) -> None:
    """Refuse a model of more ``what`` (a key of ``_COUNT_LIMITS``) than the input policy allows
    (:mod:`facemime.io.limits`) with a :class:`ModelFormatError` naming ``where``, the limit and
    how to raise it."""
    variable = _COUNT_LIMITS[what]
    most = limit(variable)
    if count > most:
        raise ModelFormatError(
            f"{where}: the model has {count} {what}, more than the limit of {most}; set {variable} to allow more"
        )


def read_model_file(path: Path) -> bytes:
    """The bytes of a model file. A file over the byte limit is refused with
    :class:`ModelFormatError` before it is read (or, when its size is unknown, after one byte
    more than the limit); a missing or unreadable one with :class:`InputFileError`."""
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


@dataclass(frozen=True, eq=False)
class HeadModel:
    """A wire-frame head.

    Attributes
    ----------
    vertices : (N, 3) float64 array
        Rest positions in model space (see the module docstring), in ``unit``.
    triangles : (F, 3) int64 array
        Vertex indices, outward (counter-clockwise from outside) winding.
    uv : (N, 2) float64 array or None
        Texture coordinates in [0, 1] from the texture's top-left corner.
    groups : dict of str -> (K,) int64 array
        Named, ordered vertex groups.
    units : dict of str -> (N, 3) float64 array
        Deformation (animation) units: displacement of every vertex at activation 1.
    shape_units : dict of str -> (N, 3) float64 array
        Shape units (per-person shape, CANDIDE), same layout.
    descriptions : dict of str -> str
        What each unit does.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray | None = None
    groups: dict[str, np.ndarray] = field(default_factory=dict)
    units: dict[str, np.ndarray] = field(default_factory=dict)
    shape_units: dict[str, np.ndarray] = field(default_factory=dict)
    descriptions: dict[str, str] = field(default_factory=dict)
    name: str = "head"
    unit: str = "mm"

    def __post_init__(self) -> None:
        problem = _first_problem(self.vertices, self.triangles, self.uv, self.groups, (self.units, self.shape_units))
        if problem:
            raise InvalidInputError(f"head model {self.name!r}: {problem}")

    def deform(
        self, weights: Mapping[str, float] | None = None, shape: Mapping[str, float] | None = None
    ) -> np.ndarray:
        """Vertices with deformation units (and shape units) applied: (N, 3) float64.

        >>> head = generic_head()
        >>> moved = head.deform({"jawOpen": 0.5})
        >>> bool(moved[head.groups["mouth_outer_lower"][5], 1] < head.vertices[head.groups["mouth_outer_lower"][5], 1])
        True
        """
        v = self.vertices.copy()
        for table, given, kind in ((self.units, weights, "deformation unit"), (self.shape_units, shape, "shape unit")):
            for name, w in (given or {}).items():
                if name not in table:
                    raise InvalidInputError(f"unknown {kind} {name!r}; this model has: {', '.join(table) or 'none'}")
                v += float(w) * table[name]
        return v


def _first_problem(
    v: np.ndarray,
    t: np.ndarray,
    uv: np.ndarray | None,
    groups: Mapping[str, np.ndarray],
    tables: tuple[Mapping[str, np.ndarray], ...],
) -> str | None:
    """The first thing wrong with a model's arrays, as text, or None."""
    if not (isinstance(v, np.ndarray) and v.ndim == 2 and v.shape[1] == 3 and len(v) >= 3):
        return f"vertices must have shape (N, 3) with N >= 3, got {getattr(v, 'shape', type(v).__name__)}"
    n = len(v)
    if not np.isfinite(v).all():
        return "vertices hold NaN or inf"
    if np.abs(v).max() > MAX_COORDINATE:
        return f"a vertex lies {np.abs(v).max():.3g} from the origin, beyond the {MAX_COORDINATE:g} model units allowed"
    if not (isinstance(t, np.ndarray) and t.ndim == 2 and t.shape[1] == 3 and len(t) >= 1):
        return f"triangles must have shape (F, 3) with F >= 1, got {getattr(t, 'shape', type(t).__name__)}"
    if t.min() < 0 or t.max() >= n:
        bad = int(t.min() if t.min() < 0 else t.max())
        return f"triangle {int(np.argwhere((t < 0) | (t >= n))[0, 0])} uses vertex {bad}, but there are {n} vertices"
    area = np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    scale = max(float(np.ptp(v, axis=0).max()), 1e-12)
    if (area <= 1e-9 * scale**2).any():
        return f"triangle {int(np.argmax(area <= 1e-9 * scale**2))} is degenerate (zero area)"
    if uv is not None and (uv.shape != (n, 2) or not np.isfinite(uv).all()):
        return f"uv must have shape ({n}, 2) and be finite, got {uv.shape}"
    if uv is not None and (uv.min() < -1 or uv.max() > 2):
        return "texture coordinates (uv) must lie near 0..1 (within -1..2)"
    for name, g in groups.items():
        if g.ndim != 1 or len(g) == 0 or g.min() < 0 or g.max() >= n:
            return f"group {name!r} must list vertex indices in 0..{n - 1}"
    for table in tables:
        for name, d in table.items():
            if d.shape != (n, 3) or not np.isfinite(d).all():
                return f"unit {name!r} must have shape ({n}, 3) and be finite"
    return None


def load_head(path: str | Path) -> HeadModel:
    """Load and validate a ``facemime.head/1`` JSON model file.

    Raises :class:`InputFileError` if it cannot be read and :class:`ModelFormatError`, naming the
    file and the problem, if it is not a valid model or is over a limit (see the module docstring).
    """
    path = Path(path)
    try:
        text = read_model_file(path).decode("utf-8")
    except UnicodeDecodeError:
        raise ModelFormatError(f"{path}: not a text file; expected a {HEAD_FORMAT} JSON model") from None
    return _parse_head(text, str(path))


def generic_head() -> HeadModel:
    """The generic head shipped with facemime (about 120 vertices, millimetres)."""
    text = resources.files("facemime.model").joinpath("data/generic_head.json").read_text(encoding="utf-8")
    return _parse_head(text, "generic_head.json")


def _parse_head(text: str, where: str) -> HeadModel:
    try:
        doc = parse_json(text, where)
    except json.JSONDecodeError as e:
        raise ModelFormatError(f"{where}: not valid JSON ({e.msg} at line {e.lineno})") from None
    except ValueError as e:
        raise ModelFormatError(str(e)) from None
    return head_from_document(doc, where)


def head_document(model: HeadModel) -> dict:
    """``model`` as a ``facemime.head/1`` document (JSON-ready; floats kept exactly)."""
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


def head_from_document(doc: object, where: str) -> HeadModel:
    """Validate a parsed ``facemime.head/1`` document and build the model; a
    :class:`ModelFormatError` naming ``where`` and the problem otherwise (also for a model over
    the vertex or triangle limit, checked on the lists' lengths before any array is built)."""
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
        triangles = np.asarray(doc["triangles"], dtype=np.int64)
        uv = np.asarray(doc["uv"], dtype=np.float64) if doc.get("uv") is not None else None
        groups = {str(k): np.asarray(g, dtype=np.int64) for k, g in doc["groups"].items()}
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
    problem = _first_problem(vertices, triangles, uv, groups, (units,))
    if problem:
        raise ModelFormatError(f"{where}: {problem}")
    short = [f"{g} has {len(groups[g])} (needs {n})" for g, n in MIN_GROUP_SIZES.items() if len(groups[g]) < n]
    if short:
        raise ModelFormatError(f"{where}: vertex groups too short: {'; '.join(short)}")
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
