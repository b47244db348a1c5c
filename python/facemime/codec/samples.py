"""The sender's side of the actor's own mouth and eyes (:mod:`facemime.types.samples`): a
library chosen from the clip that is coded, sent once inside the stream's actor chunk.

Each frame with a face is laid back onto the texture through the geometry the receiver draws
(:func:`~facemime.codec.appearance.lay_back`, the stream decoded here), and each group's boxes are
cut out of it (texels no facing triangle covers keep the texture's), keyed by the frame's decoded
shape (:mod:`facemime.animate.samples`). The library covers the shapes seen: per group, the
frames' keys are chosen farthest first from the key frame's and from each other's (k-centre), the
frames are put with the nearest chosen key (the key frame's own among them), and each chosen
sample is the frame of its cluster whose boxes look most like the cluster's mean. Samples are
added in that order while the library stays under :data:`BUDGET` bytes as the stream carries it.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.eyes import LookPainter
from facemime.animate.samples import INTERIOR_SIZE, interior_strip, mouth_knots, weigh_eyes
from facemime.animate.synth import Puppet
from facemime.codec.appearance import FACING, lay_back
from facemime.codec.decoder import DecodedFrame
from facemime.io.samples_file import SAMPLE_QUALITY
from facemime.io.video import VideoReader
from facemime.progress import track as progress
from facemime.shared_constants import SEAL
from facemime.types.actor import Actor
from facemime.types.head import HeadModel, model_iod, mouth_up, mouth_width
from facemime.types.pose import Pose, project, rotation_matrix
from facemime.types.samples import SampleGroup, Samples

#: The library's size at most, bytes of WebP images as the stream carries them (issue 64: 30 kB).
BUDGET = 28_000
#: Samples a group at most.
MOST = 16
#: The mouth's box: the outer lips' extent in the texture grown this much about its centre.
MOUTH_GROW = 1.4
#: A frame's mouth is open, and its interior kept, where its decoded inner lips stand further
#: apart than this share of the mouth's width somewhere (where the synthesis shows an opening at
#: its full size: twice the gap it seals, :data:`~facemime.shared_constants.SEAL`).
OPEN = 2 * SEAL
#: Frames laid back at most (evenly spread over the clip): bounds the memory the choice takes.
CANDIDATES = 600


def sample_boxes(actor: Actor) -> dict[str, np.ndarray]:
    """Each group's boxes in an actor's texture.

    Parameters
    ----------
    actor
        The actor.

    Returns
    -------
    dict of str -> (B, 4) int64 array
        ``eyes``: the two eye regions the look repaints (:class:`~facemime.animate.eyes.LookPainter`);
        ``mouth``: the outer lips' extent grown :data:`MOUTH_GROW` times. Rows: x, y, width,
        height, texels.
    """
    h, w = actor.texture.shape[:2]
    eyes = [(x0, y0, x1 - x0, y1 - y0) for x0, y0, x1, y1 in LookPainter(actor).eye_boxes]
    m = actor.model
    assert m.uv is not None  # an actor's model has texture coordinates
    uv = m.uv[np.concatenate([m.groups["mouth_outer_upper"], m.groups["mouth_outer_lower"]])] * [w, h] - 0.5
    centre, half = (uv.min(axis=0) + uv.max(axis=0)) / 2, (uv.max(axis=0) - uv.min(axis=0)) / 2 * MOUTH_GROW
    x0, y0 = np.maximum(np.floor(centre - half).astype(int), 0)
    x1, y1 = np.minimum(np.ceil(centre + half).astype(int) + 1, [w, h])
    return {"eyes": np.array(eyes, np.int64), "mouth": np.array([(x0, y0, x1 - x0, y1 - y0)], np.int64)}


def _webp(image: np.ndarray) -> bytes:
    ok, data = cv2.imencode(".webp", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_WEBP_QUALITY, SAMPLE_QUALITY])
    if not ok:
        raise ValueError("WebP encoding failed")
    return data.tobytes()


def _as_carried(image: np.ndarray) -> np.ndarray:
    """The image as the receiver decodes it from the stream (WebP at :data:`SAMPLE_QUALITY`)."""
    decoded = cv2.imdecode(np.frombuffer(_webp(image), np.uint8), cv2.IMREAD_COLOR)
    assert decoded is not None  # what was just encoded decodes
    return cv2.cvtColor(decoded, cv2.COLOR_BGR2RGB)


def _centres(keys: np.ndarray, most: int) -> list[int]:
    """Up to ``most`` rows of ``keys``, each the farthest from the key frame's (zero) and the
    ones before it, while any is farther than zero."""
    d = np.linalg.norm(keys, axis=1)
    chosen: list[int] = []
    while len(chosen) < most and d.max() > 0:
        j = int(np.argmax(d))
        chosen.append(j)
        d = np.minimum(d, np.linalg.norm(keys - keys[j], axis=1))
    return chosen


def choose_group(
    name: str,
    boxes: np.ndarray,
    crops: list[list[np.ndarray]],
    keys: np.ndarray,
    frames: np.ndarray,
    budget: int,
    interiors: list[np.ndarray | None] | None = None,
) -> tuple[SampleGroup | None, int]:
    """One group's samples, within a byte budget.

    Parameters
    ----------
    name
        The group's name.
    boxes
        (B, 4) its boxes, texels.
    crops
        Per candidate frame, its image of each box (RGB uint8).
    keys
        (N, D) per candidate, its key as weighed for distances.
    frames
        (N,) per candidate, its frame index.
    budget
        Bytes the group's images may take as the stream carries them.
    interiors
        ``mouth`` only: per candidate, its interior image (None: its mouth was closed); None:
        none.

    Returns
    -------
    group : SampleGroup or None
        The samples (keys unweighed: as the actor stores them); None when none fits or the
        clip's shapes never leave the key frame's.
    size : int
        The bytes its images take.
    """
    centres = _centres(keys, MOST)
    if not centres:
        return None, 0
    all_keys = np.vstack([np.zeros(keys.shape[1]), keys[centres]])
    owner = np.argmin(np.linalg.norm(keys[:, None, :] - all_keys[None, :, :], axis=2), axis=1) - 1
    chosen, images, size = [], [], 0
    kept: list[np.ndarray | None] = []
    for c, centre in enumerate(centres):
        members = np.flatnonzero(owner == c)
        flat = np.array([np.concatenate([b.ravel() for b in crops[i]]) for i in members], np.float32)
        best = int(members[np.argmin(((flat - flat.mean(axis=0)) ** 2).sum(axis=1))]) if len(members) else centre
        inside = None if interiors is None else interiors[best]
        cost = sum(len(_webp(b)) for b in crops[best] + ([] if inside is None else [inside]))
        if size + cost > budget:
            break
        size += cost
        chosen.append(best)
        images.append([_as_carried(b) for b in crops[best]])
        kept.append(None if inside is None else _as_carried(inside))
    if not chosen:
        return None, 0
    carried = kept if any(k is not None for k in kept) else None
    return SampleGroup(name, boxes, images, keys[chosen], frames[chosen], carried), size


def _interior(
    frame: np.ndarray,
    vertices: np.ndarray,
    pose: Pose,
    model: HeadModel,
    strip_uv: np.ndarray,
    strip: np.ndarray,
    upper: np.ndarray,
    lower: np.ndarray,
) -> np.ndarray | None:
    """A frame's mouth opening laid out on the interior image (:func:`interior_uv`), or None where
    the decoded inner lips are closer than :data:`OPEN` of the mouth's width. Texels no triangle
    covers take the covered ones' mean colour (the renderer's bilinear lookups reach them)."""
    up = mouth_up(model, vertices)
    if up is None or not len(strip):
        return None
    gap = (vertices[upper, :2] - vertices[lower, :2]) @ up
    if gap.max() <= OPEN * mouth_width(model, vertices):
        return None
    image, cover = lay_back(
        frame, strip_uv, strip, project(vertices, pose)[0], np.ones(len(strip), bool), INTERIOR_SIZE
    )
    covered = cover == 255
    if not covered.any():
        return None
    image[~covered] = np.round(image[covered].mean(axis=0)).astype(np.uint8)
    return image


def build_samples(video: str | Path, actor: Actor, decoded: list[DecodedFrame], budget: int = BUDGET) -> Samples | None:
    """A sample library of an actor's mouth and eyes from the clip a stream codes.

    Parameters
    ----------
    video
        The video the stream was made from.
    actor
        The actor as the receiver holds it (its texture as the stream carries it).
    decoded
        The stream's frames as the receiver decodes them, in order.
    budget
        Bytes the library's images may take, at most.

    Returns
    -------
    Samples or None
        The library (the eyes first, then the mouth, each given the bytes the other leaves);
        None when no sample fits or the clip's shapes never leave the key frame's.
    """
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), mask_only=True)
    boxes = sample_boxes(actor)
    mouth = mouth_knots(actor.model.groups, puppet.deformer.knots)
    model = actor.model
    assert model.uv is not None  # an actor's model has texture coordinates
    tri = np.asarray(model.triangles)
    v = model.vertices
    normals = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    h, w = actor.texture.shape[:2]
    usable = [i for i, f in enumerate(decoded) if f.face and not f.concealed]
    keep = set(usable[:: max(1, -(-len(usable) // CANDIDATES))])
    crops: dict[str, list[list[np.ndarray]]] = {g: [] for g in boxes}
    keys: dict[str, list[np.ndarray]] = {g: [] for g in boxes}
    frames: list[int] = []
    interiors: list[np.ndarray | None] = []
    strip_uv, strip = interior_strip(model)
    if {frozenset(t) for t in strip.tolist()} & {frozenset(t) for t in tri.tolist()}:
        strip = strip[:0]  # a capped mouth (fit.actor.mouth_cap): its own texture shows the opening
    upper, lower = model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]
    with VideoReader(video) as reader:
        for i, (frame, f) in enumerate(zip(progress(reader, len(decoded), "samples"), decoded)):
            if i not in keep:
                continue
            vertices, pose = puppet.vertices(f.offsets, look=f.look), puppet.pose(f.pose)
            facing = (normals @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T)[:, 2] >= FACING
            laid, cover = lay_back(frame, model.uv, tri, project(vertices, pose)[0], facing, (w, h))
            for g, bs in boxes.items():
                crops[g].append(
                    [
                        np.where(
                            cover[y : y + bh, x : x + bw, None] == 255,
                            laid[y : y + bh, x : x + bw],
                            actor.texture[y : y + bh, x : x + bw],
                        )
                        for x, y, bw, bh in bs
                    ]
                )
            interiors.append(_interior(frame, vertices, pose, model, strip_uv, strip, upper, lower))
            keys["eyes"].append(weigh_eyes(f.look.vector()))
            keys["mouth"].append(np.asarray(f.offsets)[mouth].ravel())
            frames.append(i)
    if not frames:
        return None
    groups, left = [], budget
    for g in ("eyes", "mouth"):
        group, size = choose_group(
            g,
            boxes[g],
            crops[g],
            np.array(keys[g]),
            np.array(frames, np.int64),
            left // (2 if g == "eyes" else 1),
            interiors if g == "mouth" else None,
        )
        if group is not None:
            if g == "eyes":
                group = replace(group, keys=np.asarray(group.keys) / weigh_eyes(np.ones(group.keys.shape[1])))
            groups.append(group)
            left -= size
    return Samples(tuple(groups)) if groups else None
