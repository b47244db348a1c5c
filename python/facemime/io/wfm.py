"""Loader for CANDIDE ``.wfm`` wire-frame models (CANDIDE-3, J. Ahlberg, Linköping University).

A ``.wfm`` file is text: ``# VERTEX LIST:`` (count, then x y z per line), ``# FACE LIST:``
(count, then three vertex indices), ``# ANIMATION UNITS LIST:`` and ``# SHAPE UNITS LIST:``
(count, then per unit a ``# name`` line, a count and ``vertex dx dy dz`` lines),
``# ANIMATION PARAMETERS:`` / ``# SHAPE PARAMETERS:`` (one value per unit) and ``# TEXTURE:``
(u v per vertex, v from the top). Other ``#`` lines are comments.

CANDIDE's x axis points to the image's left (the subject's right); the loader mirrors x so that
the model follows facemime's right-handed convention (x to the subject's left, y up, z towards
the camera). The mirror also turns CANDIDE's face order (clockwise seen from outside) into
facemime's outward, counter-clockwise winding. The unit stays CANDIDE's own (about 1 = half
the face height).

Models over the input limits (vertices, triangles, file bytes; ``FACEMIME_MAX_VERTICES``,
``FACEMIME_MAX_TRIANGLES``, ``FACEMIME_MAX_MODEL_BYTES``, see :mod:`facemime.io.head_file`) are
refused: a too-large file before it is read, a too-large vertex or face count as soon as its
count line is read, before the rest of the file is split into lines.
"""

from __future__ import annotations

import io
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from facemime.errors import InvalidInputError, ModelFormatError
from facemime.io.head_file import check_model_count, read_model_file
from facemime.types.head import HeadModel

_SECTIONS = (
    "VERTEX LIST",
    "FACE LIST",
    "ANIMATION UNITS LIST",
    "SHAPE UNITS LIST",
    "ANIMATION PARAMETERS",
    "SHAPE PARAMETERS",
    "TEXTURE",
    "END OF FILE",
)
_COUNTED = {"VERTEX LIST": "vertices", "FACE LIST": "triangles"}  # sections whose count has a limit


class _Lines:
    """Numbered, non-empty lines of a section, consumed in order, with error context.

    Parameters
    ----------
    where
        What names the file in error messages.
    section
        The section's title, e.g. ``"VERTEX LIST"``.
    lines
        The section's (1-based line number in the file, stripped text) pairs.
    """

    def __init__(self, where: str, section: str, lines: list[tuple[int, str]]):
        self.where, self.section, self.lines, self.pos = where, section, lines, 0

    def fail(self, what: str) -> ModelFormatError:
        """The error to raise for a problem at the current line.

        Parameters
        ----------
        what
            The problem.

        Returns
        -------
        ModelFormatError
            Naming the file, section, line number and ``what``.
        """
        line = self.lines[min(self.pos, len(self.lines) - 1)][0] if self.lines else "?"
        return ModelFormatError(f"{self.where}: {self.section}, line {line}: {what}")

    def next(self) -> str:
        """Take the next line; a section that has none left is an error.

        Returns
        -------
        str
            The line's text.
        """
        if self.pos >= len(self.lines):
            raise self.fail("section ends early")
        self.pos += 1
        return self.lines[self.pos - 1][1]

    def numbers(self, count: int, kind: type) -> list[Any]:
        """Take the next line as ``count`` numbers; another count, or a value that is not a
        ``kind`` (or, for ``int``, beyond int64), is an error naming that line.

        Parameters
        ----------
        count
            How many numbers the line must hold.
        kind
            ``int`` or ``float``.

        Returns
        -------
        list
            The ``count`` values, of type ``kind``.
        """
        parts = self.next().split()
        try:
            if len(parts) != count:
                raise ValueError
            values = [kind(p) for p in parts]
            if kind is int and any(abs(v) >= 1 << 63 for v in values):  # beyond int64: no index or count
                raise ValueError
            return values
        except ValueError:
            self.pos -= 1
            raise self.fail(
                f"expected {count} {'integers' if kind is int else 'numbers'}, got {' '.join(parts)!r}"
            ) from None

    def table(self, rows: int, columns: int, kind: type) -> np.ndarray:
        """Take the next ``rows`` lines as a table: numpy's parser first, then line by line,
        naming the first bad line, if that fails.

        Parameters
        ----------
        rows
            How many lines to take.
        columns
            How many numbers each line must hold.
        kind
            ``float`` or ``int``.

        Returns
        -------
        (rows, columns) float64 or int64 array
            float64 for ``kind`` float, int64 for int.
        """
        dtype = np.int64 if kind is int else np.float64
        chunk = [line for _, line in self.lines[self.pos : self.pos + rows]]
        if rows and len(chunk) == rows:
            try:
                with warnings.catch_warnings():
                    # older numpy (2.0.0 among them) reads an integer written as a float ("2.0")
                    # with a DeprecationWarning, newer ones refuse it: refused here by any
                    warnings.simplefilter("error", DeprecationWarning)
                    table = np.loadtxt(io.StringIO("\n".join(chunk)), dtype=dtype, comments=None, ndmin=2)
            except (ValueError, OverflowError, DeprecationWarning):
                table = None
            if table is not None and table.shape == (rows, columns):
                self.pos += rows
                return table
        return np.array([self.numbers(columns, kind) for _ in range(rows)], dtype=dtype).reshape(-1, columns)

    def count(self) -> int:
        """Take the next line as a count; a negative one is an error.

        Returns
        -------
        int
            The count, 0 or more.
        """
        n = int(self.numbers(1, int)[0])
        if n < 0:
            raise self.fail(f"negative count {n}")
        return n


def load_wfm(path: str | Path) -> HeadModel:
    """Load a CANDIDE ``.wfm`` file as a :class:`HeadModel` in facemime's axes.

    Raises :class:`InputFileError` or :class:`ModelFormatError` naming the file, section and line;
    a model over an input limit (see the module docstring) is a :class:`ModelFormatError` too.

    Parameters
    ----------
    path
        The ``.wfm`` file.

    Returns
    -------
    HeadModel
        The model, x mirrored into facemime's axes, in CANDIDE's units (``unit`` "CANDIDE units")
        and named after the file's stem. Animation units become ``units``, shape units
        ``shape_units`` (each named as in the file); the file's texture coordinates become ``uv``.
        The model has no named vertex groups.
    """
    path = Path(path)
    data = read_model_file(path)
    if b"\n" not in data:
        data = data.replace(b"\r", b"\n")  # classic Mac line ends
    where = str(path)
    # Split at known section titles only: unit names are "# ..." lines inside their section. The
    # lines are taken one by one from the file's bytes (shared, not copied) so that a too-large
    # count is refused before the rest is split.
    sections: dict[str, list[tuple[int, str]]] = {}
    current: list[tuple[int, str]] | None = None
    for lineno, raw in enumerate(io.BytesIO(data), 1):
        line = raw.decode("latin-1").strip()
        if not line:
            continue
        head = line.lstrip("#").strip().rstrip(":").upper()
        if line.startswith("#") and head in _SECTIONS:
            section, current = head, sections.setdefault(head, [])
        elif current is not None:
            current.append((lineno, line))
            if len(current) == 1 and section in _COUNTED:  # the count line: refuse a too-large model now
                try:
                    declared = int(line)
                except ValueError:
                    declared = 0  # not a count: the section's parser names the problem
                check_model_count(f"{where}: {section}, line {lineno}", _COUNTED[section], declared)
    for required in ("VERTEX LIST", "FACE LIST"):
        if required not in sections:
            raise ModelFormatError(f"{where}: no '# {required}:' section; is this a CANDIDE .wfm file?")

    s = _Lines(where, "VERTEX LIST", sections["VERTEX LIST"])
    vertices = s.table(s.count(), 3, float)
    n = len(vertices)
    s = _Lines(where, "FACE LIST", sections["FACE LIST"])
    faces = s.table(s.count(), 3, int)
    if faces.size and (faces.min() < 0 or faces.max() >= n):
        raise ModelFormatError(
            f"{where}: FACE LIST uses vertex {int(faces.max() if faces.max() >= n else faces.min())}, but "
            f"there are {n} vertices"
        )

    total = [0]  # deformation units so far, both sections

    def units(section: str) -> dict[str, np.ndarray]:
        s = _Lines(where, section, sections.get(section, []))
        if not s.lines:
            return {}
        out: dict[str, np.ndarray] = {}
        count = s.count()
        total[0] += count
        check_model_count(f"{where}: {section}", "deformation unit values (units x vertices)", total[0] * n)
        for k in range(count):
            name = s.next()
            if not name.startswith("#"):
                s.pos -= 1
                raise s.fail(f"expected '# <unit name>' for unit {k}, got {name!r}")
            name = name.lstrip("#").strip() or f"unit {k}"
            d = np.zeros((n, 3))
            for _ in range(s.count()):
                i, *delta = s.numbers(4, float)
                if not (float(i).is_integer() and 0 <= i < n):
                    s.pos -= 1
                    raise s.fail(f"unit {name!r} names vertex {i:g}, but there are {n} vertices")
                d[int(i)] = delta
            out[name] = d * [-1, 1, 1]
        return out

    uv = None
    if sections.get("TEXTURE"):
        s = _Lines(where, "TEXTURE", sections["TEXTURE"])
        uv = s.table(n, 2, float)
    model_units = units("ANIMATION UNITS LIST")
    shape_units = units("SHAPE UNITS LIST")
    try:  # the model's own validation names what is wrong (degenerate triangle, ...)
        return HeadModel(
            vertices=vertices * [-1, 1, 1],
            triangles=faces,
            uv=uv,
            units=model_units,
            shape_units=shape_units,
            name=path.stem,
            unit="CANDIDE units",
        )
    except InvalidInputError as e:
        raise ModelFormatError(f"{where}: {e}") from None
