"""A minimal binary glTF 2.0 (``.glb``) writer: one JSON chunk and one binary chunk, built with
numpy and :mod:`struct` (the format is a 12-byte header and two length-prefixed chunks, and every
array goes out as one little-endian buffer view, so a library would add a dependency and a copy
of every array without making this clearer).

:class:`Glb` collects the JSON document and the binary buffer; :meth:`Glb.accessor` stores an
array and describes it. Axes and units are the caller's: glTF's are right-handed, metres, +y up,
the asset's front towards +z (see :mod:`facemime.export.performance`).
"""

from __future__ import annotations

import json
import struct
from typing import Any

import numpy as np

GLB_MAGIC = 0x46546C67  # "glTF"
JSON_CHUNK = 0x4E4F534A  # "JSON"
BIN_CHUNK = 0x004E4942  # "BIN\0"
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963
#: glTF component types of the numpy dtypes written.
COMPONENTS: dict[np.dtype[Any], int] = {
    np.dtype("<f4"): 5126,
    np.dtype("<u4"): 5125,
    np.dtype("<u2"): 5123,
    np.dtype("<u1"): 5121,
}
#: glTF accessor types by the number of components per element.
TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}


class Glb:
    """A glTF document being built, with its binary buffer.

    Parameters
    ----------
    generator
        The tool named in the document's ``asset.generator``.

    Examples
    --------
    >>> g = Glb()
    >>> g.accessor(np.zeros((3, 2), np.float32))
    0
    >>> data = g.bytes()
    >>> struct.unpack_from("<III", data) == (GLB_MAGIC, 2, len(data))
    True
    """

    def __init__(self, generator: str = "facemime"):
        self.doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": generator}}
        self._pieces: list[bytes] = []
        self._length = 0

    def add(self, kind: str, entry: dict[str, Any]) -> int:
        """Append an entry to one of the document's top-level lists.

        Parameters
        ----------
        kind
            The list's glTF name (``nodes``, ``meshes``, ...); created when missing.
        entry
            The glTF object appended, as JSON-ready values.

        Returns
        -------
        int
            The entry's index in that list, as other glTF objects refer to it.
        """
        items = self.doc.setdefault(kind, [])
        items.append(entry)
        return len(items) - 1

    def view(self, data: bytes, target: int | None = None) -> int:
        """Store bytes as a buffer view (4-byte aligned, as glTF needs for floats).

        Parameters
        ----------
        data
            The view's bytes.
        target
            The view's glTF ``target`` (:data:`ARRAY_BUFFER` for vertex attributes,
            :data:`ELEMENT_ARRAY_BUFFER` for indices); None: no target written (images,
            animation data).

        Returns
        -------
        int
            The buffer view's index.
        """
        pad = -self._length % 4
        if pad:
            self._pieces.append(b"\0" * pad)
            self._length += pad
        entry: dict[str, Any] = {"buffer": 0, "byteOffset": self._length, "byteLength": len(data)}
        if target is not None:
            entry["target"] = target
        self._pieces.append(data)
        self._length += len(data)
        return self.add("bufferViews", entry)

    def accessor(self, array: np.ndarray, target: int | None = None, bounds: bool = False) -> int:
        """Store an array in its own buffer view and describe it by an accessor.

        Parameters
        ----------
        array
            (count,) or (count, 1-4) array of float32, uint32, uint16 or uint8, in the units the
            glTF property takes (metres for positions, seconds for animation times); written
            little-endian.
        target
            The buffer view's glTF ``target`` (see :meth:`view`); None: none.
        bounds
            Whether to write the per-component ``min`` and ``max`` (glTF needs them on positions
            and animation times).

        Returns
        -------
        int
            The accessor's index.
        """
        a = np.ascontiguousarray(array, dtype=array.dtype.newbyteorder("<"))
        width = 1 if a.ndim == 1 else a.shape[1]
        entry: dict[str, Any] = {
            "bufferView": self.view(a.tobytes(), target),
            "componentType": COMPONENTS[a.dtype],
            "count": int(a.shape[0]),
            "type": TYPES[width],
        }
        if bounds:
            flat = a.reshape(len(a), width)
            cast = float if a.dtype.kind == "f" else int
            entry["min"] = [cast(v) for v in flat.min(axis=0)]
            entry["max"] = [cast(v) for v in flat.max(axis=0)]
        return self.add("accessors", entry)

    def zeros(self, count: int, width: int) -> int:
        """An accessor of float32 zeros that stores nothing (glTF reads an accessor without a buffer
        view as zeros), with its ``min`` and ``max``.

        Parameters
        ----------
        count
            Its number of elements.
        width
            Components per element, 1-4.

        Returns
        -------
        int
            The accessor's index.
        """
        zero = [0.0] * width
        entry = {"componentType": COMPONENTS[np.dtype("<f4")], "count": count, "type": TYPES[width]}
        return self.add("accessors", {**entry, "min": zero, "max": zero})

    def bytes(self) -> bytes:
        """The ``.glb`` file of the document built so far.

        Returns
        -------
        bytes
            The 12-byte header, the JSON chunk (padded with spaces) and, when anything was
            stored, the binary chunk (padded with zeros).
        """
        if self._length:
            self.doc["buffers"] = [{"byteLength": self._length + (-self._length % 4)}]
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        blob = b"".join(self._pieces)
        blob += b"\0" * (-len(blob) % 4)
        chunks = struct.pack("<II", len(text), JSON_CHUNK) + text
        if blob:
            chunks += struct.pack("<II", len(blob), BIN_CHUNK) + blob
        return struct.pack("<III", GLB_MAGIC, 2, 12 + len(chunks)) + chunks


def read_glb(data: bytes) -> tuple[dict[str, Any], bytes]:
    """Split a ``.glb`` file into its JSON document and binary chunk (for checks; no validation
    beyond the header and chunk types).

    Parameters
    ----------
    data
        The whole ``.glb`` file.

    Returns
    -------
    doc : dict
        The parsed JSON document.
    blob : bytes
        The binary chunk; empty when the file has none.

    Examples
    --------
    >>> doc, blob = read_glb(Glb("x").bytes())
    >>> doc["asset"], blob
    ({'version': '2.0', 'generator': 'x'}, b'')
    """
    magic, version, length = struct.unpack_from("<III", data)
    if magic != GLB_MAGIC or version != 2 or length != len(data):
        raise ValueError("not a glTF 2.0 binary file")
    size, kind = struct.unpack_from("<II", data, 12)
    if kind != JSON_CHUNK:
        raise ValueError("the first chunk of a .glb must be JSON")
    doc = json.loads(data[20 : 20 + size])
    rest = 20 + size
    blob = b""
    if rest < len(data):
        size, kind = struct.unpack_from("<II", data, rest)
        blob = data[rest + 8 : rest + 8 + size] if kind == BIN_CHUNK else b""
    return doc, blob


def accessor_array(doc: dict[str, Any], blob: bytes, index: int) -> np.ndarray:
    """The array an accessor describes (tightly packed views only, as :class:`Glb` writes them).

    Parameters
    ----------
    doc
        The glTF JSON document (:func:`read_glb`).
    blob
        The binary chunk the document's buffer views address.
    index
        The accessor's index in ``doc["accessors"]``.

    Returns
    -------
    (count,) or (count, width) array
        Read-only view of ``blob`` in the accessor's dtype (float32, uint32, uint16 or uint8), or
        zeros for an accessor without a buffer view; (count,) for ``SCALAR`` accessors, else
        ``width`` = 2-4 components per row.
    """
    acc = doc["accessors"][index]
    dtype = next(d for d, c in COMPONENTS.items() if c == acc["componentType"])
    width = next(n for n, t in TYPES.items() if t == acc["type"])
    if "bufferView" not in acc:  # zeros (Glb.zeros)
        zero = np.zeros((acc["count"], width), dtype)
        zero.flags.writeable = False
        return zero[:, 0] if width == 1 else zero
    view = doc["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    a = np.frombuffer(blob, dtype, acc["count"] * width, start)
    return a if width == 1 else a.reshape(-1, width)
