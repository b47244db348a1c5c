"""An actor's sample library (:mod:`facemime.types.samples`) as members of its ``.actor`` file.

- ``samples.json``: ``{"format": "facemime.samples/1", "groups": [{"name": "eyes" | "mouth",
  "boxes": [[x, y, width, height], ...] (texels of the actor's texture), "samples": [{"frame": F,
  "key": [...]}, ...]}, ...]}``;
- ``samples/<group>/<box>.png`` (or ``.webp``, in a stream): the samples' images of one box, RGB,
  stacked top to bottom in the samples' order (sample s in rows s·h to (s + 1)·h − 1, h the box's
  height): one image per box keeps the file small;
- ``samples/mouth/interior.png`` (``.webp``): the openings of the mouth samples marked
  ``"interior": true``, stacked the same way in their order, each the mouth's opening laid out
  between the inner lips (:func:`facemime.animate.samples.interior_uv`), all of one size.

The member is absent from actors without samples; ``actor.json`` does not mention it, so an
actor's id (the SHA-256 of ``actor.json``) is the same with or without its samples.
"""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np

from facemime.errors import InvalidInputError
from facemime.io.image_bytes import decode_rgb
from facemime.limits import image_size, parse_json
from facemime.shared_constants import INTERIOR_SIZE
from facemime.types.samples import GROUPS, MAX_BOXES, MAX_SAMPLES, MAX_TEXELS, SampleGroup, Samples

SAMPLES_FORMAT = "facemime.samples/1"
#: The library's description member.
SAMPLES_JSON = "samples.json"
#: WebP quality of the samples' images in a stream (the library's size is chosen at it).
SAMPLE_QUALITY = 70
#: Names a mouth sample's interior image in place of a box's index.
INTERIOR = "interior"


def image_name(group: str, box: int | str, kind: str) -> str:
    """The member holding a group's samples of one box.

    Parameters
    ----------
    group
        The group's name.
    box
        The box's index in the group, or :data:`INTERIOR`.
    kind
        ``"png"`` or ``"webp"``.

    Returns
    -------
    str
        ``samples/<group>/<box>.<kind>``.
    """
    return f"samples/{group}/{box}.{kind}"


def samples_members(samples: Samples, kind: str, encode: Callable[[np.ndarray], bytes]) -> dict[str, bytes]:
    """The members that store a library.

    Parameters
    ----------
    samples
        The library.
    kind
        How the images are encoded, ``"png"`` or ``"webp"`` (names their members).
    encode
        Encodes one RGB image as ``kind``.

    Returns
    -------
    dict of str -> bytes
        Member name -> content: :data:`SAMPLES_JSON` first, then the images.
    """
    doc = {
        "format": SAMPLES_FORMAT,
        "groups": [
            {
                "name": g.name,
                "boxes": g.boxes.astype(int).tolist(),
                "samples": [
                    {"frame": int(f), "key": [round(float(v), 4) for v in k]}
                    | ({"interior": True} if g.interiors is not None and g.interiors[i] is not None else {})
                    for i, (f, k) in enumerate(zip(g.frames, g.keys))
                ],
            }
            for g in samples.groups
        ],
    }
    out = {SAMPLES_JSON: json.dumps(doc, separators=(",", ":")).encode()}
    for g in samples.groups:
        for b in range(len(g.boxes)):
            out[image_name(g.name, b, kind)] = encode(np.vstack([images[b] for images in g.images]))
        inside = [i for i in g.interiors or [] if i is not None]
        if inside:
            out[image_name(g.name, INTERIOR, kind)] = encode(np.vstack(inside))
    return out


def samples_from_members(text: bytes, read: Callable[[str], bytes | None], where: str) -> Samples:
    """A library from its members.

    Parameters
    ----------
    text
        The content of :data:`SAMPLES_JSON`.
    read
        Reads a member by name (bounded in size); None when the file has no such member.
    where
        Names the file in error messages.

    Returns
    -------
    Samples
        The library. A malformed one raises :class:`~facemime.errors.InvalidInputError` naming
        ``where`` and the problem.
    """
    try:
        doc = parse_json(text, f"{where}: {SAMPLES_JSON}")
    except (UnicodeDecodeError, ValueError) as e:
        raise InvalidInputError(f"{where}: {SAMPLES_JSON} is not valid JSON ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != SAMPLES_FORMAT or not isinstance(doc.get("groups"), list):
        raise InvalidInputError(f"{where}: {SAMPLES_JSON} is not a {SAMPLES_FORMAT!r} document")
    groups = []
    for g in doc["groups"]:
        try:
            if not isinstance(g, dict) or not {"name", "boxes", "samples"} <= g.keys():
                raise ValueError("a group is an object with its name, boxes and samples")
            name, boxes, entries = g["name"], g["boxes"], g["samples"]
            if name not in GROUPS:
                raise ValueError(f"a group is one of {', '.join(GROUPS)}, got {name!r}")
            if not (
                isinstance(boxes, list)
                and 1 <= len(boxes) <= MAX_BOXES
                and all(isinstance(b, list) and len(b) == 4 and all(_integer(v, 1 << 16) for v in b) for b in boxes)
                and all(w >= 1 and h >= 1 for _, _, w, h in boxes)
            ):
                raise ValueError(f"boxes must be 1-{MAX_BOXES} rows of 4 integers 0-65536, width and height ≥ 1")
            if not isinstance(entries, list) or not 1 <= len(entries) <= MAX_SAMPLES:
                raise ValueError(f"a group holds 1-{MAX_SAMPLES} samples")
            if len(entries) * sum(w * h for _, _, w, h in boxes) > MAX_TEXELS:
                raise ValueError(f"its images would hold more than {MAX_TEXELS} texels")
            if not all(isinstance(e, dict) and _integer(e.get("frame"), 1 << 31) for e in entries):
                raise ValueError("each sample needs its frame, an integer ≥ 0")
            if not all(isinstance(e.get("key"), list) and all(_real(v) for v in e["key"]) for e in entries):
                raise ValueError("each sample needs its key, a list of numbers")
            if len({len(e["key"]) for e in entries}) > 1:
                raise ValueError("the samples' keys differ in length")
            if not all(isinstance(e.get("interior", False), bool) for e in entries):
                raise ValueError("a sample's interior is true or false")
            if name != "mouth" and any(e.get("interior") for e in entries):
                raise ValueError("only mouth samples hold an interior")
            keys = np.array([np.asarray(e["key"], np.float64) for e in entries])
            frames = np.array([e["frame"] for e in entries], np.int64)
            inside = [e.get("interior") is True for e in entries]
        except (KeyError, TypeError, ValueError, OverflowError) as e:
            raise InvalidInputError(f"{where}: malformed sample group in {SAMPLES_JSON} ({e})") from None
        atlases = [_atlas(read, name, b, (w, h), len(entries), where) for b, (_, _, w, h) in enumerate(boxes)]
        images = [[atlas[s] for atlas in atlases] for s in range(len(entries))]
        openings = iter(
            _atlas(read, name, INTERIOR, (INTERIOR_SIZE[0], INTERIOR_SIZE[1]), sum(inside), where)
            if any(inside)
            else []
        )
        interiors = [next(openings) if i else None for i in inside]
        try:
            groups.append(
                SampleGroup(name, np.array(boxes, np.int64), images, keys, frames, interiors if any(inside) else None)
            )
        except InvalidInputError as e:
            raise InvalidInputError(f"{where}: {e}") from None
    try:
        return Samples(tuple(groups))
    except InvalidInputError as e:
        raise InvalidInputError(f"{where}: {e}") from None


def _integer(value: object, most: int) -> bool:
    """Whether a JSON value is an integer from 0 to ``most`` (not a boolean)."""
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= most


def _real(value: object) -> bool:
    """Whether a JSON value is a number (not a boolean)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def _atlas(
    read: Callable[[str], bytes | None], group: str, box: int | str, size: tuple[int, int], count: int, where: str
) -> list[np.ndarray]:
    """A group's stacked images of one box (or its interiors), PNG or WebP, cut into ``count``
    RGB images of ``size`` (width, height); its header's size is checked before it is decoded."""
    w, h = size
    for kind in ("png", "webp"):
        name = image_name(group, box, kind)
        data = read(name)
        if data is None:
            continue
        declared = image_size(data) if data else None
        if declared is None:
            raise InvalidInputError(f"{where}: sample image {name} is not a {kind.upper()} image")
        if declared != (w, h * count):
            raise InvalidInputError(
                f"{where}: sample image {name} is {declared[0]}x{declared[1]}, not {count} images of {w}x{h}"
            )
        image = decode_rgb(data)
        if image is None or image.shape[:2] != (h * count, w):
            raise InvalidInputError(f"{where}: sample image {name} does not decode")
        return np.split(image, count)
    what = "its interiors" if box == INTERIOR else f"box {box}"
    raise InvalidInputError(f"{where}: group {group!r} has no image of {what}")
