"""The sender's side of the actor's own mouth and eyes (:mod:`facemime.types.samples`): a
library chosen from the clip that is coded, sent once inside the stream's actor chunk.

Each frame with a face is laid back onto the texture through the geometry the receiver draws
(:func:`~facemime.codec.appearance.lay_back`, the stream decoded here), and each group's boxes are
cut out of it (texels no facing triangle covers keep the texture's, faded in over
:data:`FEATHER` texels), keyed by the frame's decoded shape (:mod:`facemime.animate.samples`); an
open mouth's opening is laid out on its interior image too. The library covers the shapes seen
(:func:`build_samples`): per group, the frames' keys are chosen farthest first from the key
frame's and from each other's (k-centre), the frames are put with the nearest chosen key (the key
frame's own among them), and each chosen sample is the frame of its cluster whose boxes look most
like the cluster's mean. Samples are added in that order while the library stays under
:data:`BUDGET` bytes as the stream carries it. Then each frame's sample is chosen by what the
frame shows (:func:`choose_samples`) and sent with it (``docs/bitstream.md``, "Sample choices").
"""

from __future__ import annotations

import json
import zlib
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.eyes import LookPainter
from facemime.animate.samples import interior_strip, mouth_knots, weigh_eyes
from facemime.animate.synth import Puppet
from facemime.codec.appearance import FACING, lay_back
from facemime.codec.clip import analyse, encode_clip
from facemime.codec.decoder import DecodedFrame, MotionDecoder
from facemime.codec.params import Basis
from facemime.codec.stream import Settings
from facemime.io.samples_file import SAMPLE_QUALITY
from facemime.io.video import VideoReader
from facemime.progress import track as progress
from facemime.shared_constants import CAVITY, INTERIOR_SIZE, SEAL
from facemime.types.actor import Actor
from facemime.types.head import HeadModel, model_iod, mouth_capped, mouth_up, mouth_width
from facemime.types.pose import Pose, project, rotation_matrix
from facemime.types.samples import GROUPS, SampleGroup, Samples

#: The library's size at most, bytes as the stream carries it: its images (WebP) and its
#: description (issue 64: 30 kB with the archive's own headers).
BUDGET = 29_000
#: Samples a group at most.
MOST = 24
#: The mouth's box: the outer lips' extent in the texture grown this much about its centre.
MOUTH_GROW = 1.4
#: A frame's mouth is open, and its interior kept, where its decoded inner lips stand further
#: apart than this share of the mouth's width somewhere (where the synthesis shows an opening at
#: its full size: twice the gap it seals, :data:`~facemime.shared_constants.SEAL`).
OPEN = 2 * SEAL
#: A frame keeps its predecessor's sample unless another's error is this share smaller (fewer
#: switches: fewer bits, and no flicker between samples that fit about as well).
SWITCH = 0.25
#: Texels (Gaussian sigma) over which a laid-back frame fades into the texture where its facing
#: triangles end.
FEATHER = 2.0
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


def _atlases(
    crops: list[list[np.ndarray]], interiors: list[np.ndarray | None] | None, chosen: list[int]
) -> list[np.ndarray]:
    """The images an actor file stores for the chosen candidates (:mod:`facemime.io.samples_file`):
    per box their crops stacked top to bottom, then their interiors stacked, if any."""
    out = [np.vstack([crops[i][b] for i in chosen]) for b in range(len(crops[chosen[0]]))]
    inside = [i for i in (interiors[c] for c in chosen) if i is not None] if interiors is not None else []
    return out + ([np.vstack(inside)] if inside else [])


def _described(keys: np.ndarray, frames: np.ndarray) -> int:
    """About the bytes the samples' entries take in the actor file's ``samples.json``, deflated."""
    entries = [{"frame": int(f), "key": [round(float(v), 4) for v in k]} for f, k in zip(frames, keys)]
    return len(zlib.compress(json.dumps(entries, separators=(",", ":")).encode()))


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
        Bytes the group may take in the actor file: its images as the stream carries them and its
        entries in ``samples.json``.
    interiors
        ``mouth`` only: per candidate, its interior image (None: its mouth was closed); None:
        none.

    Returns
    -------
    group : SampleGroup or None
        The samples (keys unweighed: as the actor stores them); None when none fits or the
        clip's shapes never leave the key frame's.
    size : int
        The bytes it takes.
    """
    centres = _centres(keys, MOST)
    if not centres:
        return None, 0
    all_keys = np.vstack([np.zeros(keys.shape[1]), keys[centres]])
    owner = np.argmin(np.linalg.norm(keys[:, None, :] - all_keys[None, :, :], axis=2), axis=1) - 1
    chosen: list[int] = []
    size = 0
    for c, centre in enumerate(centres):
        members = np.flatnonzero(owner == c)
        flat = np.array([np.concatenate([b.ravel() for b in crops[i]]) for i in members], np.float32)
        best = int(members[np.argmin(((flat - flat.mean(axis=0)) ** 2).sum(axis=1))]) if len(members) else centre
        cost = sum(len(_webp(atlas)) for atlas in _atlases(crops, interiors, chosen + [best]))
        cost += _described(keys[chosen + [best]], frames[chosen + [best]])
        if cost > budget:
            break
        chosen.append(best)
        size = cost
    if not chosen:
        return None, 0
    carried = [_as_carried(atlas) for atlas in _atlases(crops, interiors, chosen)]
    per_box = [np.split(carried[b], len(chosen)) for b in range(len(boxes))]
    images = [[per_box[b][s] for b in range(len(boxes))] for s in range(len(chosen))]
    opened = [i for i in chosen if interiors is not None and interiors[i] is not None]
    inside = iter(np.split(carried[len(boxes)], len(opened)) if opened else [])
    kept = [None if interiors is None or interiors[i] is None else next(inside) for i in chosen]
    interiors_kept = kept if any(k is not None for k in kept) else None
    return SampleGroup(name, boxes, images, keys[chosen], frames[chosen], interiors_kept), size


def _blend(base: np.ndarray, over: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``base`` + ``weight`` · (``over`` − ``base``), rounded: uint8 RGB images, (h, w, 1) weights 0-1."""
    return np.clip(base + weight * (over.astype(np.float32) - base) + 0.5, 0, 255).astype(np.uint8)


def _interior(
    frame: np.ndarray, vertices: np.ndarray, pose: Pose, model: HeadModel, strip_uv: np.ndarray, strip: np.ndarray
) -> np.ndarray | None:
    """A frame's mouth opening laid out on the interior image (:func:`interior_uv`), or None where
    the decoded inner lips are closer than :data:`OPEN` of the mouth's width. Texels no triangle
    covers take the covered ones' mean colour (the renderer's bilinear lookups reach them)."""
    up = mouth_up(model, vertices)
    if up is None or not len(strip):
        return None
    upper, lower = model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]
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


class _Regions:
    """Lays frames back onto an actor's texture through the geometry the receiver draws, and cuts
    out the sample groups' boxes and the mouth's interior.

    Parameters
    ----------
    actor
        The actor as the receiver holds it.
    """

    def __init__(self, actor: Actor):
        self.actor = actor
        self.puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), mask_only=True)
        self.boxes = sample_boxes(actor)
        self.mouth = mouth_knots(actor.model.groups, self.puppet.deformer.knots)
        model = actor.model
        assert model.uv is not None  # an actor's model has texture coordinates
        self.strip_uv, self.strip = interior_strip(model)
        if mouth_capped(model):  # a capped mouth (fit.actor.mouth_cap) shows the photo's own opening, as it is
            self.strip = self.strip[:0]
        self.triangles = tri = np.asarray(model.triangles)
        v = model.vertices
        normals = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
        self.normals = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)

    def key(self, group: str, f: DecodedFrame) -> np.ndarray:
        """A decoded frame's key in a group.

        Parameters
        ----------
        group
            ``eyes`` or ``mouth``.
        f
            The decoded frame.

        Returns
        -------
        (D,) float64 array
            Its look weighed for distances (:func:`~facemime.animate.samples.weigh_eyes`), or its
            lip knots' offsets flattened, model units.
        """
        return weigh_eyes(f.look.vector()) if group == "eyes" else np.asarray(f.offsets)[self.mouth].ravel()

    def laid(
        self, frame: np.ndarray, f: DecodedFrame
    ) -> tuple[dict[str, list[np.ndarray]], dict[str, list[np.ndarray]], np.ndarray | None]:
        """A frame laid back onto the texture, cut into the groups' boxes.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB: the real frame.
        f
            Its motion as the receiver decodes it.

        Returns
        -------
        crops : dict of str -> list of (h, w, 3) uint8 arrays
            Per group, the frame in each box (texels no facing triangle covers keep the
            texture's).
        covers : dict of str -> list of (h, w) bool arrays
            Per group and box, the texels the frame covers.
        interior : (40, 96, 3) uint8 array or None
            Its mouth's opening (:func:`_interior`).
        """
        model, texture = self.actor.model, self.actor.texture
        assert model.uv is not None
        vertices, pose = self.puppet.vertices(f.offsets, look=f.look), self.puppet.pose(f.pose)
        facing = (self.normals @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T)[:, 2] >= FACING
        h, w = texture.shape[:2]
        laid, cover = lay_back(frame, model.uv, self.triangles, project(vertices, pose)[0], facing, (w, h))
        crops: dict[str, list[np.ndarray]] = {}
        covers: dict[str, list[np.ndarray]] = {}
        covered = (cover == 255).astype(np.float32)
        # where the frame's facing triangles end (the far cheek of a turned head), it fades into the
        # texture over a few texels instead of leaving a seam
        weight = (cv2.GaussianBlur(covered, (0, 0), FEATHER) * covered)[:, :, None]
        for g, bs in self.boxes.items():
            covers[g] = [cover[y : y + bh, x : x + bw] == 255 for x, y, bw, bh in bs]
            crops[g] = [
                _blend(texture[y : y + bh, x : x + bw], laid[y : y + bh, x : x + bw], weight[y : y + bh, x : x + bw])
                for x, y, bw, bh in bs
            ]
        return crops, covers, _interior(frame, vertices, pose, model, self.strip_uv, self.strip)


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
    regions = _Regions(actor)
    usable = [i for i, f in enumerate(decoded) if f.face and not f.concealed]
    keep = set(usable[:: max(1, -(-len(usable) // CANDIDATES))])
    crops: dict[str, list[list[np.ndarray]]] = {g: [] for g in regions.boxes}
    keys: dict[str, list[np.ndarray]] = {g: [] for g in regions.boxes}
    frames: list[int] = []
    interiors: list[np.ndarray | None] = []
    with VideoReader(video) as reader:
        for i, (frame, f) in enumerate(zip(progress(reader, len(decoded), "samples"), decoded)):
            if i not in keep:
                continue
            laid, _, interior = regions.laid(frame, f)
            for g in regions.boxes:
                crops[g].append(laid[g])
                keys[g].append(regions.key(g, f))
            interiors.append(interior)
            frames.append(i)
    if not frames:
        return None
    groups, left = [], budget
    for g in ("eyes", "mouth"):
        group, size = choose_group(
            g,
            regions.boxes[g],
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


def _errors(
    candidates: np.ndarray,
    frame: np.ndarray,
    covered: np.ndarray,
    openings: np.ndarray | None = None,
    opening: np.ndarray | None = None,
) -> np.ndarray:
    """Each candidate's mean squared difference (levels², over RGB) from a frame: over the texels
    of its boxes the frame covers, and over the interior where the frame has one.

    ``candidates`` (C, P) float32: each candidate's boxes flattened; ``frame`` (P,) the frame's,
    ``covered`` (P,) 1 where it covers them; ``openings`` (C, Q) each candidate's interior
    flattened, ``opening`` (Q,) the frame's (None: none)."""
    total = ((candidates - frame) ** 2) @ covered
    count = float(covered.sum())
    if openings is not None and opening is not None:
        total = total + ((openings - opening) ** 2).sum(axis=1)
        count += opening.size
    return total / count if count else np.zeros(len(candidates))


def choose_samples(video: str | Path, actor: Actor, decoded: list[DecodedFrame]) -> list[tuple[int | None, ...]]:
    """The sample each frame draws, per group, chosen by what the frame shows: the candidate
    (each sample, and the key frame's own: the texture with the irises moved, a drawn interior)
    whose boxes, laid back as for the library, differ least from the frame's, and for the mouth its
    interior too (a drawn one compared as :data:`~facemime.shared_constants.CAVITY`'s colour). A
    frame keeps its predecessor's sample unless another's error is smaller by :data:`SWITCH`.

    Parameters
    ----------
    video
        The video the stream was made from.
    actor
        The actor as the receiver holds it, with its sample library.
    decoded
        The stream's frames as the receiver decodes them, in order.

    Returns
    -------
    list of tuple of (int or None)
        Per frame, per group of :data:`~facemime.types.samples.GROUPS`, the sample's index (None:
        the key frame's own); frames without a face keep their predecessor's.
    """
    assert actor.samples is not None
    regions, painter = _Regions(actor), LookPainter(actor)
    cavity = np.tile(np.array(CAVITY, np.float32), INTERIOR_SIZE[0] * INTERIOR_SIZE[1])  # a drawn interior, flattened
    flat = lambda images: np.concatenate([im.ravel() for im in images]).astype(np.float32)  # noqa: E731
    samples = {g.name: np.array([flat(images) for images in g.images]) for g in actor.samples.groups}
    # the mouth's candidates' interiors: a drawn one (the key frame's, a sample without) as the cavity
    openings = {
        g.name: np.array([cavity] + [cavity if i is None else flat([i]) for i in g.interiors or [None] * len(g.images)])
        for g in actor.samples.groups
        if g.name == "mouth"
    }
    previous: dict[str, int | None] = dict.fromkeys(GROUPS)
    out: list[tuple[int | None, ...]] = []
    with VideoReader(video) as reader:
        for frame, f in zip(progress(reader, len(decoded), "sample choice"), decoded):
            if f.face and not f.concealed:
                crops, covers, interior = regions.laid(frame, f)
                for group in actor.samples.groups:
                    base = painter.texture(f.look) if group.name == "eyes" else actor.texture
                    own = flat([base[y : y + h, x : x + w] for x, y, w, h in group.boxes])
                    covered = np.concatenate([np.repeat(c.ravel(), 3) for c in covers[group.name]]).astype(np.float32)
                    errors = _errors(
                        np.vstack([own[None], samples[group.name]]),
                        flat(crops[group.name]),
                        covered,
                        openings.get(group.name),
                        None if interior is None else flat([interior]),
                    )
                    best, kept = int(np.argmin(errors)), previous[group.name]
                    stay = 0 if kept is None else kept + 1
                    previous[group.name] = (
                        kept if errors[stay] <= (1.0 + SWITCH) * errors[best] else (None if best == 0 else best - 1)
                    )
            out.append(tuple(previous[g] for g in GROUPS))
    return out


def library_from_clip(video: str | Path, actor: Actor) -> Samples | None:
    """A sample library for an actor from a clip of the same person (``fit --samples-from``): the
    clip analysed with the actor placed on its face and coded as ``encode --actor`` codes it, the
    library taken from what a receiver holding the actor decodes (:func:`build_samples`).

    Parameters
    ----------
    video
        The clip, the person's face roughly frontal on its first frame and, like the actor's
        photo, neutral there.
    actor
        The actor, fitted on a photo of the same person.

    Returns
    -------
    Samples or None
        The library; None when the clip's shapes never leave its first frame's.
    """
    clip = analyse(video, actor)
    faces = [m.offsets for m in clip.motion if m.face]
    settings = Settings()
    basis = Basis.learn(np.array(faces).reshape(len(faces), -1, 2), settings.basis_size)
    header, _, packets = encode_clip(clip, settings, False, basis)
    decoder = MotionDecoder(actor)
    return build_samples(video, actor, decoder.push(header + b"".join(packets)) + decoder.finish())
