"""``.actor`` files: one fitted, textured head in one file that is safe to open from anywhere.

The file is a ZIP archive with exactly two members and nothing executable:

- ``actor.json``: ``{"format": "facemime.actor/1", "model": <a facemime.head/1 document: the
  adjusted vertices, triangles, uv, groups, deformation units>, "pose": {"yaw", "pitch", "roll",
  "scale", "tx", "ty"} (the frontal pose onto the source photo), "source": {"file", "frame",
  "width", "height"}, "points": {name: [[x, y], ...]}, "texture": {"width", "height"}}``;
- ``texture.png``: the RGB texture.

Loading reads only those two members, refuses oversized ones before reading them, parses JSON
and PNG (no pickle, no code) and validates every array, so a corrupt, truncated, foreign or
hostile file gives an :class:`ActorFileError` naming the file and the problem.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import cv2
import numpy as np

from facemime.errors import FacemimeError, InputFileError, InvalidInputError, ModelFormatError
from facemime.fit.actor import Actor
from facemime.io.outputs import OutputFileError, atomic_file, check_outputs
from facemime.model.head import head_document, head_from_document
from facemime.render.projection import Pose

ACTOR_FORMAT = "facemime.actor/1"
#: Largest member sizes accepted when loading, bytes (uncompressed).
MAX_JSON_BYTES = 32 << 20
MAX_TEXTURE_BYTES = 64 << 20
MAX_TEXTURE_SIDE = 4096


class ActorFileError(FacemimeError, ValueError):
    """An ``.actor`` file is corrupt, truncated, foreign or of an unknown version."""


def save_actor(path: str | Path, actor: Actor, force: bool = False) -> Path:
    """Write ``actor`` to ``path`` atomically; refuses to overwrite unless ``force``."""
    path = Path(path)
    check_outputs([path], force)
    ok, png = cv2.imencode(".png", cv2.cvtColor(actor.texture, cv2.COLOR_RGB2BGR))
    if not ok:
        raise OutputFileError(f"cannot encode the texture of {path}")
    doc = {
        "format": ACTOR_FORMAT,
        "model": head_document(actor.model),
        "pose": {k: float(getattr(actor.pose, k)) for k in ("yaw", "pitch", "roll", "scale", "tx", "ty")},
        "source": actor.source,
        "points": {k: np.asarray(v).tolist() for k, v in actor.points.items()},
        "texture": {"width": int(actor.texture.shape[1]), "height": int(actor.texture.shape[0])},
    }
    with atomic_file(path) as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("actor.json", json.dumps(doc))
        z.writestr(zipfile.ZipInfo("texture.png"), png.tobytes(), zipfile.ZIP_STORED)
    return path


def _member(z: zipfile.ZipFile, name: str, limit: int, where: str) -> bytes:
    try:
        info = z.getinfo(name)
    except KeyError:
        raise ActorFileError(f"{where}: not a facemime actor (no {name} inside)") from None
    if info.file_size > limit:
        raise ActorFileError(f"{where}: {name} is {info.file_size} bytes, more than the {limit} allowed")
    return z.read(info)


def load_actor(path: str | Path) -> Actor:
    """Read and validate an ``.actor`` file."""
    path = Path(path)
    where = str(path)
    if not path.is_file():
        raise InputFileError(f"actor file {path} does not exist" if not path.exists() else f"actor file {path} is not a file")
    try:
        with zipfile.ZipFile(path) as z:
            text = _member(z, "actor.json", MAX_JSON_BYTES, where)
            png = _member(z, "texture.png", MAX_TEXTURE_BYTES, where)
    except (zipfile.BadZipFile, EOFError, zipfile.LargeZipFile, NotImplementedError) as e:
        raise ActorFileError(f"{where}: not a facemime actor file, or truncated ({e})") from None
    except OSError as e:
        raise InputFileError(f"cannot read {where}: {e.strerror or e}") from None
    try:
        doc = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ActorFileError(f"{where}: actor.json is not valid JSON ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != ACTOR_FORMAT:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise ActorFileError(f"{where}: expected format {ACTOR_FORMAT!r}, got {found!r}"
                             + (" (a newer facemime wrote it?)" if isinstance(found, str) and found.startswith("facemime.actor/") else ""))
    texture = _texture(png, doc.get("texture"), where)
    try:
        model = head_from_document(doc.get("model"), f"{where}: model")
    except ModelFormatError as e:
        raise ActorFileError(str(e)) from None
    if model.uv is None:
        raise ActorFileError(f"{where}: model has no texture coordinates")
    try:
        pose = Pose(**{k: float(doc["pose"][k]) for k in ("yaw", "pitch", "roll", "scale", "tx", "ty")})
        source = doc.get("source", {})
        points = {str(k): np.asarray(v, dtype=np.float64).reshape(-1, 2) for k, v in doc.get("points", {}).items()}
        if not isinstance(source, dict) or not np.isfinite(list(pose.__dict__.values())).all() or pose.scale <= 0:
            raise ValueError("bad pose or source")
        return Actor(model, texture, pose, source, points)
    except (KeyError, TypeError, ValueError, AttributeError, InvalidInputError) as e:
        raise ActorFileError(f"{where}: malformed actor ({e})") from None


def _texture(png: bytes, meta: object, where: str) -> np.ndarray:
    if len(png) < 24 or png[:8] != b"\x89PNG\r\n\x1a\n":
        raise ActorFileError(f"{where}: texture.png is not a PNG image")
    w, h = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")  # the IHDR size
    if not (1 <= w <= MAX_TEXTURE_SIDE and 1 <= h <= MAX_TEXTURE_SIDE):
        raise ActorFileError(f"{where}: texture is {w}x{h}; at most {MAX_TEXTURE_SIDE} pixels a side are allowed")
    img = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    if img is None:
        raise ActorFileError(f"{where}: texture.png is corrupt")
    if not isinstance(meta, dict) or [meta.get("width"), meta.get("height")] != [img.shape[1], img.shape[0]]:
        raise ActorFileError(f"{where}: texture is {img.shape[1]}x{img.shape[0]}, but actor.json says {meta}")
    return np.ascontiguousarray(cv2.cvtColor(img, cv2.COLOR_BGR2RGB))
