"""``.actor`` files: one fitted, textured head in one file that is safe to open from anywhere.

The file is a ZIP archive of two or three members and nothing executable:

- ``actor.json``: ``{"format": "facemime.actor/1", "model": <a facemime.head/1 document: the
  adjusted vertices, triangles, uv, groups, deformation units>, "pose": {"yaw", "pitch", "roll",
  "scale", "tx", "ty"} (the frontal pose onto the source photo), "source": {"file", "frame",
  "width", "height"}, "points": {name: [[x, y], ...]}, "texture": {"width", "height"}}``;
- ``texture.png`` (or ``texture.webp``: the smaller form a stream carries, see
  :func:`actor_bytes`): the RGB texture;
- optionally ``scene.png`` (or ``scene.webp``), with ``"scene": {"width", "height"}`` in
  ``actor.json``: the whole source picture the face is synthesised in
  (:mod:`facemime.render.scene`). Files written before scenes existed have none, and their face
  is shown alone.
- optionally the actor's sample library of its own mouth and eyes: ``samples.json`` and
  ``samples/...`` (:mod:`facemime.io.samples_file`).

Loading reads only those members, refuses oversized ones before reading them, parses JSON
and PNG (no pickle, no code) and validates every array, so a corrupt, truncated, foreign or
hostile file gives an :class:`ActorFileError` naming the file and the problem.
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
import zlib
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from facemime.errors import FacemimeError, InputFileError, InvalidInputError, ModelFormatError
from facemime.io.head_file import head_document, head_from_document
from facemime.io.image_bytes import decode_rgb
from facemime.io.outputs import OutputFileError, check_outputs, write_bytes
from facemime.io.samples_file import SAMPLE_QUALITY, SAMPLES_JSON, samples_from_members, samples_members
from facemime.limits import image_size, limit, parse_json, pose_in_range
from facemime.types.actor import Actor
from facemime.types.pose import Pose

ACTOR_FORMAT = "facemime.actor/1"
#: Largest member sizes accepted when loading, bytes (uncompressed).
MAX_JSON_BYTES = 32 << 20
MAX_TEXTURE_BYTES = 64 << 20
MAX_TEXTURE_SIDE = 4096


class ActorFileError(FacemimeError, ValueError):
    """An ``.actor`` file is corrupt, truncated, foreign or of an unknown version."""


#: Texture members a file may hold, and how each is written.
TEXTURES = {"png": ("texture.png", []), "webp": ("texture.webp", [cv2.IMWRITE_WEBP_QUALITY])}
#: The scene member's names, in the order looked for.
SCENES = ("scene.png", "scene.webp")


def actor_json(actor: Actor) -> bytes:
    """The ``actor.json`` member of ``actor``'s file.

    The bytes are deterministic: their SHA-256 names the actor in a stream (see
    ``docs/bitstream.md``, and :func:`actor_id`).

    Parameters
    ----------
    actor
        The actor to describe.

    Returns
    -------
    bytes
        The ``facemime.actor/1`` JSON document (model, pose, source, reference points, texture and
        scene sizes), UTF-8.
    """
    doc = {
        "format": ACTOR_FORMAT,
        "model": head_document(actor.model),
        "pose": {k: float(getattr(actor.pose, k)) for k in ("yaw", "pitch", "roll", "scale", "tx", "ty")},
        "source": actor.source,
        "points": {k: np.asarray(v).tolist() for k, v in actor.points.items()},
        "texture": {"width": int(actor.texture.shape[1]), "height": int(actor.texture.shape[0])},
    }
    if actor.scene is not None:
        doc["scene"] = {"width": int(actor.scene.shape[1]), "height": int(actor.scene.shape[0])}
    return json.dumps(doc).encode()


def actor_bytes(actor: Actor, texture: str = "png", quality: int = 90, sample_quality: int = SAMPLE_QUALITY) -> bytes:
    """``actor`` as the bytes of an actor file (a ZIP archive, see the module docstring).

    Parameters
    ----------
    actor
        The actor to store.
    texture
        How the texture and the scene are encoded: ``"png"`` (what a file on disk holds) or
        ``"webp"`` (the smaller form a stream carries).
    quality
        WebP quality, 1-100; PNG is lossless and ignores it.
    sample_quality
        WebP quality of the sample library's images (the texture's ``"webp"`` form only).

    Returns
    -------
    bytes
        The ``.actor`` file's content; the same actor gives the same bytes.
    """
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        # ZipInfo entries are dated 1980-01-01: the same actor gives the same bytes, whenever written
        z.writestr(zipfile.ZipInfo("actor.json"), actor_json(actor), zipfile.ZIP_DEFLATED)
        for what, image in (("texture", actor.texture), ("scene", actor.scene)):
            if image is not None:
                data = _encoded(image, what, texture, quality)
                z.writestr(zipfile.ZipInfo(f"{what}.{texture}"), data, zipfile.ZIP_STORED)
        if actor.samples is not None:
            members = samples_members(
                actor.samples, texture, lambda im: _encoded(im, "samples", texture, sample_quality)
            )
            for name, data in members.items():
                z.writestr(
                    zipfile.ZipInfo(name), data, zipfile.ZIP_DEFLATED if name == SAMPLES_JSON else zipfile.ZIP_STORED
                )
    return buf.getvalue()


def _encoded(image: np.ndarray, what: str, kind: str, quality: int) -> bytes:
    """The RGB ``image`` encoded as ``kind`` (a key of :data:`TEXTURES`)."""
    ok, data = cv2.imencode(
        "." + kind,
        cv2.cvtColor(image, cv2.COLOR_RGB2BGR),
        [p for flag in TEXTURES[kind][1] for p in (flag, int(quality))],
    )
    if not ok:
        raise OutputFileError(f"cannot encode the {what} as {kind}")
    return data.tobytes()


def save_actor(path: str | Path, actor: Actor, force: bool = False) -> Path:
    """Write ``actor`` to an ``.actor`` file atomically, its texture and scene as PNG.

    Parameters
    ----------
    path
        The file to write; its folder is created if missing.
    actor
        The actor to store.
    force
        Overwrite an existing file; without it one is refused with
        :class:`facemime.io.outputs.OutputExistsError`.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    check_outputs([path], force)
    return write_bytes(path, actor_bytes(actor))


def _member(z: zipfile.ZipFile, name: str, limit: int, where: str) -> bytes:
    """The member ``name``, read in bounded pieces: one that says it is larger than ``limit``
    is refused unread, and one that lies about its size (a bomb) is cut where it says it ends
    (``ZipFile.read`` would inflate it whole first) and fails its checksum."""
    try:
        info = z.getinfo(name)
    except KeyError:
        raise ActorFileError(f"{where}: not a facemime actor (no {name} inside)") from None
    if info.file_size > limit:
        raise ActorFileError(f"{where}: {name} is {info.file_size} bytes, more than the {limit} allowed")
    data = bytearray()
    with z.open(info) as f:
        while piece := f.read(1 << 16):
            data += piece
    return bytes(data)


def load_actor(path: str | Path) -> Actor:
    """Read and validate an ``.actor`` file.

    Parameters
    ----------
    path
        The ``.actor`` file. One that is missing or not a file raises :class:`InputFileError`; a
        corrupt, foreign or hostile one :class:`ActorFileError`.

    Returns
    -------
    Actor
        The actor the file holds.
    """
    path = Path(path)
    if not path.is_file():
        raise InputFileError(
            f"actor file {path} does not exist" if not path.exists() else f"actor file {path} is not a file"
        )
    return actor_from_bytes(path, str(path))


def actor_id(actor: Actor) -> bytes:
    """The SHA-256 of the actor's ``actor.json`` member: what a stream names it by.

    Parameters
    ----------
    actor
        The actor to name.

    Returns
    -------
    bytes
        The 32-byte SHA-256 digest of :func:`actor_json`.
    """
    return hashlib.sha256(actor_json(actor)).digest()


def actor_from_bytes(source: str | Path | bytes, where: str) -> Actor:
    """Read and validate an actor file's content.

    Parameters
    ----------
    source
        The ``.actor`` file's path, or its bytes (as a stream carries them).
    where
        What names the file in error messages.

    Returns
    -------
    Actor
        The actor; a file that is not a valid actor raises :class:`ActorFileError`, one that cannot
        be read :class:`InputFileError`.
    """
    try:
        with zipfile.ZipFile(io.BytesIO(source) if isinstance(source, bytes) else source) as z:
            text = _member(z, "actor.json", MAX_JSON_BYTES, where)
            names = set(z.namelist())
            member = next((name for name, _ in TEXTURES.values() if name in names), "texture.png")
            image = _member(z, member, MAX_TEXTURE_BYTES, where)
            scene_member = next((name for name in SCENES if name in names), None)
            scene = None if scene_member is None else _member(z, scene_member, MAX_TEXTURE_BYTES, where)
            samples = None
            if SAMPLES_JSON in names:
                try:
                    samples = samples_from_members(
                        _member(z, SAMPLES_JSON, MAX_JSON_BYTES, where),
                        lambda name: _member(z, name, MAX_TEXTURE_BYTES, where) if name in names else None,
                        where,
                    )
                except InvalidInputError as e:
                    raise ActorFileError(str(e)) from None
    except (zipfile.BadZipFile, EOFError, zipfile.LargeZipFile, NotImplementedError, zlib.error) as e:
        raise ActorFileError(f"{where}: not a facemime actor file, or truncated ({e})") from None
    except RuntimeError:  # zipfile's word for a member marked encrypted
        raise ActorFileError(f"{where}: not a facemime actor file (an encrypted archive)") from None
    except OSError as e:
        raise InputFileError(f"cannot read {where}: {e.strerror or e}") from None
    try:
        doc = parse_json(text, f"{where}: actor.json")
    except (UnicodeDecodeError, ValueError) as e:
        raise ActorFileError(f"{where}: actor.json is not valid JSON ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != ACTOR_FORMAT:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise ActorFileError(
            f"{where}: expected format {ACTOR_FORMAT!r}, got {found!r}"
            + (
                " (a newer facemime wrote it?)"
                if isinstance(found, str) and found.startswith("facemime.actor/")
                else ""
            )
        )
    texture = _texture(image, member, doc.get("texture"), where)
    if (scene is None) != ("scene" not in doc):
        raise ActorFileError(f"{where}: actor.json and the file's members disagree on whether it has a scene")
    scene_image = None
    if scene is not None and scene_member is not None:
        scene_image = _texture(scene, scene_member, doc["scene"], where, "scene")
    try:
        model = head_from_document(doc.get("model"), f"{where}: model")
    except ModelFormatError as e:
        raise ActorFileError(str(e)) from None
    if model.uv is None:
        raise ActorFileError(f"{where}: model has no texture coordinates")
    eyes = model.uv[np.concatenate([model.groups["eye_left"], model.groups["eye_right"]])]
    if eyes.min() < 0.0 or eyes.max() > 1.0:  # the eyes are repainted from the texture around them
        raise ActorFileError(f"{where}: the eyes' texture coordinates must lie within 0..1")
    try:
        pose = Pose(**{k: float(doc["pose"][k]) for k in ("yaw", "pitch", "roll", "scale", "tx", "ty")})
        source = doc.get("source", {})
        points = {str(k): np.asarray(v, dtype=np.float64).reshape(-1, 2) for k, v in doc.get("points", {}).items()}
        if not isinstance(source, dict):
            raise ValueError("bad source")
        if not pose_in_range(pose.yaw, pose.pitch, pose.roll, pose.scale, pose.tx, pose.ty):
            raise ValueError(f"pose out of range: {pose}")
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as e:
        raise ActorFileError(f"{where}: malformed actor ({e})") from None
    if scene_image is not None:
        _check_scene_source(source, scene_image, where)
    try:
        return Actor(model, texture, pose, source, points, scene_image, samples)
    except InvalidInputError as e:
        raise ActorFileError(f"{where}: malformed actor ({e})") from None


def _check_scene_source(source: dict[str, Any], scene: np.ndarray, where: str) -> None:
    """Refuse a scene whose source picture (what it is drawn at) is larger than the input policy
    allows for an image (:mod:`facemime.limits`), or of another shape than the scene: the
    scene is that picture, at most shrunk."""
    w, h = source.get("width"), source.get("height")
    if not (isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0):
        raise ActorFileError(f"{where}: an actor with a scene needs its source picture's width and height")
    most = limit("FACEMIME_MAX_IMAGE_PIXELS")
    if w * h > most:
        raise ActorFileError(
            f"{where}: its source picture is {w}x{h}, more than {most} pixels; "
            "set FACEMIME_MAX_IMAGE_PIXELS to allow more"
        )
    sh, sw = scene.shape[:2]
    if sw > w or sh > h or abs(sw / sh - w / h) > 2.0 / min(sw, sh):
        raise ActorFileError(f"{where}: its scene is {sw}x{sh}, not its source picture ({w}x{h}) or a shrunk copy")


def _texture(data: bytes, member: str, meta: object, where: str, what: str = "texture") -> np.ndarray:
    """The RGB image of ``member`` (``what``: texture or scene), checked against its size in
    actor.json (``meta``)."""
    size = image_size(data)
    if size is None:
        raise ActorFileError(f"{where}: {member} is not a PNG or WebP image")
    w, h = size
    if not (1 <= w <= MAX_TEXTURE_SIDE and 1 <= h <= MAX_TEXTURE_SIDE):
        raise ActorFileError(f"{where}: {what} is {w}x{h}; at most {MAX_TEXTURE_SIDE} pixels a side are allowed")
    img = decode_rgb(data)
    if img is None or img.shape[:2] != (h, w):
        raise ActorFileError(f"{where}: {member} is corrupt")
    if not isinstance(meta, dict) or [meta.get("width"), meta.get("height")] != [img.shape[1], img.shape[0]]:
        raise ActorFileError(f"{where}: {what} is {img.shape[1]}x{img.shape[0]}, but actor.json says {meta}")
    return img
