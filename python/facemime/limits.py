"""The input policy: the largest inputs facemime reads, each refused with one line before it
is decoded or parsed. Every limit is generous for real use and can be raised by an environment
variable (a whole number):

- ``FACEMIME_MAX_IMAGE_PIXELS`` (default 100,000,000: a 12,000 × 8,000 photo): a still image's
  width × height, read from its header before decoding (PNG, JPEG, WebP, BMP; OpenCV's own
  guard, set to the same value, covers other types);
- ``FACEMIME_MAX_JSON_BYTES`` (default 64 MiB): a JSON file (init, points, track, head model);
  documents nested deeper than the parser's stack are refused too;
- ``FACEMIME_MAX_VERTICES`` (200,000), ``FACEMIME_MAX_TRIANGLES`` (400,000),
  ``FACEMIME_MAX_MODEL_BYTES`` (256 MiB) and ``FACEMIME_MAX_UNIT_VALUES`` (20,000,000:
  deformation units × vertices): a head model (``.json``, ``.wfm``, the model inside an actor),
  checked as its counts are read (:mod:`facemime.io.head_file`).

Head poses read from a file (an actor's, a track's frames, a stream's starting pose) must lie within
:func:`pose_in_range`'s fixed bounds, far beyond any real picture's.
"""

from __future__ import annotations

import json
import math
import os
import struct
from pathlib import Path
from typing import Any

from facemime.errors import InputFileError, InvalidInputError

#: The head poses facemime reads (an actor's, a stream's starting pose, a track's): the largest
#: angle (degrees), the range of the scale (pixels per model unit) and the largest position of the
#: model origin (pixels, far beyond any picture).
MAX_POSE_ANGLE, POSE_SCALES, MAX_POSE_POSITION = 360.0, (1e-3, 1e4), 1e6


def pose_in_range(yaw: float, pitch: float, roll: float, scale: float, tx: float, ty: float) -> bool:
    """Whether a head pose's values are finite and within the limits above.

    Parameters
    ----------
    yaw
        Degrees, at most :data:`MAX_POSE_ANGLE` either way.
    pitch
        Degrees, at most :data:`MAX_POSE_ANGLE` either way.
    roll
        Degrees, at most :data:`MAX_POSE_ANGLE` either way.
    scale
        Pixels per model unit, within :data:`POSE_SCALES`.
    tx
        Image x of the model origin, pixels, at most :data:`MAX_POSE_POSITION` either way.
    ty
        Image y of the model origin, pixels, at most :data:`MAX_POSE_POSITION` either way.

    Returns
    -------
    bool
        True when every value is finite and within its limit.

    Examples
    --------
    >>> pose_in_range(10.0, 0.0, 2.0, 1.9, 250.0, 240.0), pose_in_range(0.0, 0.0, 0.0, 1e300, 0.0, 0.0)
    (True, False)
    """
    angles, position = (yaw, pitch, roll), (tx, ty)
    return (
        all(math.isfinite(a) and abs(a) <= MAX_POSE_ANGLE for a in angles)
        and math.isfinite(scale)
        and POSE_SCALES[0] <= scale <= POSE_SCALES[1]
        and all(math.isfinite(p) and abs(p) <= MAX_POSE_POSITION for p in position)
    )


DEFAULTS = {
    "FACEMIME_MAX_IMAGE_PIXELS": 100_000_000,
    "FACEMIME_MAX_JSON_BYTES": 64 << 20,
    "FACEMIME_MAX_VERTICES": 200_000,
    "FACEMIME_MAX_TRIANGLES": 400_000,
    "FACEMIME_MAX_MODEL_BYTES": 256 << 20,
    "FACEMIME_MAX_UNIT_VALUES": 20_000_000,
}


def limit(name: str) -> int:
    """An input limit, from the environment when set there.

    Parameters
    ----------
    name
        The limit's environment variable, a key of :data:`DEFAULTS`.

    Returns
    -------
    int
        The variable's value (a positive whole number), else the default.
    """
    value = os.environ.get(name)
    if value is None:
        return DEFAULTS[name]
    try:
        n = int(value)
        if n <= 0:
            raise ValueError
    except ValueError:
        raise InvalidInputError(f"{name} must be a positive integer, got {value!r}") from None
    return n


# OpenCV's decoders check the same pixel limit for every image type (read once, at first use).
os.environ.setdefault("OPENCV_IO_MAX_IMAGE_PIXELS", str(limit("FACEMIME_MAX_IMAGE_PIXELS")))


def image_size(data: bytes) -> tuple[int, int] | None:
    """The size an image file's header declares, for PNG, JPEG, WebP and BMP files.

    Parameters
    ----------
    data
        The file's first bytes (a JPEG's size may sit after its metadata, up to the first
        256 KiB).

    Returns
    -------
    tuple of (int, int) or None
        (width, height) pixels; None for other data, or a JPEG whose frame header lies beyond
        ``data``.
    """
    if len(data) >= 24 and data[:8] == b"\x89PNG\r\n\x1a\n":
        return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")  # the IHDR size
    if len(data) >= 30 and data[:4] == b"RIFF" and data[8:12] == b"WEBP":
        chunk = data[12:16]
        if chunk == b"VP8X":  # 24-bit width - 1, height - 1
            return int.from_bytes(data[24:27], "little") + 1, int.from_bytes(data[27:30], "little") + 1
        if chunk == b"VP8 " and data[23:26] == b"\x9d\x01\x2a":  # lossy: 14-bit sizes after the start code
            return int.from_bytes(data[26:28], "little") & 0x3FFF, int.from_bytes(data[28:30], "little") & 0x3FFF
        if chunk == b"VP8L" and data[20] == 0x2F:  # lossless: 14-bit width - 1, height - 1
            bits = int.from_bytes(data[21:25], "little")
            return (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1
        return None
    if len(data) >= 26 and data[:2] == b"BM":
        w, h = struct.unpack_from("<ii", data, 18)
        return abs(w), abs(h)
    if data[:2] == b"\xff\xd8":
        at = 2
        while at + 9 <= len(data):
            if data[at] != 0xFF:
                return None
            marker = data[at + 1]
            if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:  # markers without a length
                at += 2
                continue
            if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):  # a start of frame
                h, w = struct.unpack_from(">HH", data, at + 5)
                return w, h
            at += 2 + int.from_bytes(data[at + 2 : at + 4], "big")
    return None


def check_image_file(path: Path) -> None:
    """Refuse an image file whose header declares more pixels than the policy allows.

    Parameters
    ----------
    path
        The image file; its first 256 KiB are read.
    """
    try:
        with open(path, "rb") as f:
            head = f.read(256 << 10)
    except OSError as e:
        raise InputFileError(f"cannot read {path}: {e.strerror or e}") from None
    size = image_size(head)
    most = limit("FACEMIME_MAX_IMAGE_PIXELS")
    if size is not None and size[0] * size[1] > most:
        raise InvalidInputError(
            f"{path} is {size[0]}x{size[1]} pixels, more than the {most} allowed "
            "(set FACEMIME_MAX_IMAGE_PIXELS to allow more)"
        )


def parse_json(text: str | bytes, where: str) -> Any:
    """Parse JSON text; a document nested too deeply for the parser is refused in one line
    (``ValueError`` with the reason, like a malformed one).

    Parameters
    ----------
    text
        The JSON document.
    where
        Names the document (its file) in the refusal of one nested too deeply.

    Returns
    -------
    Any
        The parsed document.
    """
    try:
        return json.loads(text)
    except RecursionError:
        raise ValueError(f"{where} is nested too deeply") from None


def read_json_text(path: Path, what: str) -> bytes:
    """The bytes of a JSON file, refused when larger than the policy allows
    (``FACEMIME_MAX_JSON_BYTES``).

    Parameters
    ----------
    path
        The file.
    what
        The kind of file (``"init"``, ``"track"``, ``"points"``), named in error messages.

    Returns
    -------
    bytes
        The whole file.
    """
    if not path.is_file():
        raise InputFileError(
            f"{what} file {path} does not exist" if not path.exists() else f"{what} file {path} is not a file"
        )
    size, most = path.stat().st_size, limit("FACEMIME_MAX_JSON_BYTES")
    if size > most:
        raise InvalidInputError(
            f"{what} file {path} is {size} bytes, more than the {most} allowed "
            "(set FACEMIME_MAX_JSON_BYTES to allow more)"
        )
    try:
        return path.read_bytes()
    except OSError as e:
        raise InputFileError(f"cannot read {path}: {e.strerror or e}") from None
