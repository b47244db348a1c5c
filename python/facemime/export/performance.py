"""``facemime export``: a tracked performance as a binary glTF 2.0 file (``.glb``).

The file holds one scene with one node, the head: the actor's mesh (positions in metres, the
model's millimetres × 0.001; its axes are glTF's: x to the subject's left, y up, z towards the
viewer, the asset's front; triangles counter-clockwise seen from outside, glTF's front faces),
its texture as an embedded PNG (texture coordinates from the image's top-left, as glTF's are;
no flip), an unlit material (``KHR_materials_unlit``: the texture as it is, as facemime draws
it), one morph target for each of ARKit's 52 blendshapes (:mod:`facemime.animate.arkit`; the
displacement at weight 1, in metres, named in ``mesh.extras.targetNames``, which three.js and
Blender read), and one animation with a key per track frame at ``index / fps`` seconds: the 52
values (``path: "weights"``) and the head's pose as the node's rotation, translation and scale
(:mod:`facemime.export.animation`; linear). The head shows the expression controls' 27 (their
targets are the controls' fields); the eyes' look directions, animated as measured, and the
names the analysis does not measure (always 0) have targets that move nothing (accessors of
zeros, which store no bytes), so that the animation keeps every name for retargeting onto an
avatar that has them. The values are the track's ``arkit`` (written by ``facemime run``: what
``facemime live`` sends, the jaw from the chin and the blinks from both eye measures,
:class:`facemime.animate.arkit.ArkitSolver`); a track without them (written by hand, or before
them) has them made from its ``weights`` or offsets and look (:func:`facemime.animate.arkit.arkit_values`:
the jaw as the lips' solve has it). The blinks are ARKit's (shut at a closure of 0.5), not the lid
closure facemime draws.

The pose's pixels are mapped relative to the first frame at the size the head is shown in
facemime's own picture with ``--mask-only`` (the measured scale times the ratio of the eye
distances, :class:`facemime.animate.synth.Puppet`); ``scenes[0].extras.facemime`` records the
video's ``size`` (pixels), ``metres_per_pixel`` and ``origin`` (the pixel on the world origin),
what an orthographic camera needs to see each frame as facemime draws it. The mouth's opening is
closed by a strip in the cavity's colour, not the teeth facemime paints behind the lips, and the
irises' motion (repainted in the texture) is not in the file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from facemime import __version__
from facemime.animate.arkit import NAMES as ARKIT
from facemime.animate.arkit import arkit_values
from facemime.animate.motion_file import read_motion
from facemime.animate.replay import track_settings
from facemime.errors import InvalidInputError
from facemime.export.animation import POSE_KEYS, node_keys
from facemime.export.gltf import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, Glb
from facemime.fit.actor import generic_actor
from facemime.io.contours_json import TRACK_FORMAT, ContourFileError, load_document
from facemime.shared_constants import CAVITY
from facemime.types.actor import Actor
from facemime.types.head import lip_strip, model_iod

#: Metres per model unit, by the model's ``unit``.
METRES = {"mm": 0.001, "cm": 0.01, "m": 1.0}
LINEAR = 9729
CLAMP = 33071


@dataclass(frozen=True, eq=False)
class Performance:
    """What an exported file holds.

    Attributes
    ----------
    actor : Actor
        The head, its texture and model (vertices in model units, see :data:`METRES`).
    names : tuple of str
        The morph targets' names, E of them (ARKit's 52).
    fields : (E, N, 3) float array
        Each target's vertex displacement at weight 1, model units (zero for those the head
        cannot show).
    times : (T,) float array
        Seconds of each frame (``index / fps``).
    weights : (T, E) float array
        Each frame's values, 0..1.
    poses : (T, 6) float array
        Each frame's pose as facemime shows it alone (:data:`POSE_KEYS`; degrees, pixels per model
        unit, pixels).
    size : (int, int)
        The video's (width, height), pixels.
    """

    actor: Actor
    names: tuple[str, ...]
    fields: np.ndarray
    times: np.ndarray
    weights: np.ndarray
    poses: np.ndarray
    size: tuple[int, int]

    @property
    def metres_per_unit(self) -> float:
        """Metres per model unit of the actor's model (its ``unit`` looked up in :data:`METRES`).

        Returns
        -------
        float
            0.001 for a model in millimetres, 0.01 in centimetres, 1 in metres.
        """
        unit = self.actor.model.unit
        if unit not in METRES:
            raise InvalidInputError(f"the actor's model is in {unit!r}; export needs one in {', '.join(METRES)}")
        return METRES[unit]


def add_face(g: Glb, perf: Performance) -> int:
    """Store the actor's textured mesh and its morph targets in a glTF document being built (the
    module docstring describes them): positions and targets in metres, texture coordinates from
    the image's top-left, the texture as an embedded PNG under an unlit material; the mesh's
    ``weights`` are the first frame's; a second primitive, where the actor has no mouth cap,
    closes the mouth's opening with the strip between the inner lips in the cavity's colour
    (:data:`~facemime.shared_constants.CAVITY`), moving with the same targets. Adds
    ``KHR_materials_unlit`` to ``extensionsUsed``.

    Parameters
    ----------
    g
        The document being built.
    perf
        The performance: its actor's mesh and texture, its targets' names and fields.

    Returns
    -------
    int
        The mesh's index in ``g.doc["meshes"]``.
    """
    m = perf.metres_per_unit
    model = perf.actor.model
    n = len(model.vertices)
    index_type = np.uint16 if n < 65535 else np.uint32
    attributes = {
        "POSITION": g.accessor((model.vertices * m).astype(np.float32), ARRAY_BUFFER, bounds=True),
        "TEXCOORD_0": g.accessor(model.uv.astype(np.float32), ARRAY_BUFFER),
    }
    indices = g.accessor(model.triangles.astype(index_type).ravel(), ELEMENT_ARRAY_BUFFER)
    primitive: dict[str, Any] = {"attributes": attributes, "indices": indices, "mode": 4}
    mesh: dict[str, Any] = {"name": "face", "primitives": [primitive]}
    if perf.names:
        primitive["targets"] = [
            {
                "POSITION": g.accessor((f * m).astype(np.float32), ARRAY_BUFFER, bounds=True)
                if f.any()
                else g.zeros(n, 3)
            }
            for f in perf.fields
        ]
        mesh["weights"] = [float(w) for w in perf.weights[0]]
        mesh["extras"] = {"targetNames": list(perf.names)}
    ok, png = cv2.imencode(".png", cv2.cvtColor(perf.actor.texture, cv2.COLOR_RGB2BGR))
    if not ok:
        raise InvalidInputError("cannot encode the actor's texture as PNG")
    image = g.add("images", {"bufferView": g.view(png.tobytes()), "mimeType": "image/png"})
    sampler = g.add("samplers", {"magFilter": LINEAR, "minFilter": LINEAR, "wrapS": CLAMP, "wrapT": CLAMP})
    texture = g.add("textures", {"source": image, "sampler": sampler})
    primitive["material"] = g.add(
        "materials",
        {
            "name": "face",
            "pbrMetallicRoughness": {"baseColorTexture": {"index": texture}, "metallicFactor": 0.0},
            "extensions": {"KHR_materials_unlit": {}},
        },
    )
    g.doc["extensionsUsed"] = ["KHR_materials_unlit"]
    # the mouth's opening: facemime draws a cavity behind the lips; the file closes it with a
    # dark strip between the inner lips (a capped actor's strip is in the mesh, textured)
    capped = {frozenset(t) for t in model.triangles.tolist()}
    cavity = np.array([t for t in lip_strip(model).tolist() if frozenset(t) not in capped], np.int64)
    if len(cavity):
        linear = [((c / 255.0 + 0.055) / 1.055) ** 2.4 for c in CAVITY]  # glTF's colour factors are linear
        inner = {k: v for k, v in primitive.items() if k != "attributes"}
        inner["attributes"] = {"POSITION": attributes["POSITION"]}
        inner["indices"] = g.accessor(cavity.astype(index_type).ravel(), ELEMENT_ARRAY_BUFFER)
        inner["material"] = g.add(
            "materials",
            {
                "name": "mouth",
                "pbrMetallicRoughness": {"baseColorFactor": [*linear, 1.0], "metallicFactor": 0.0},
                "doubleSided": True,
                "extensions": {"KHR_materials_unlit": {}},
            },
        )
        mesh["primitives"].append(inner)
    return g.add("meshes", mesh)


def add_animation(g: Glb, perf: Performance, node: int) -> int:
    """Store the performance as one linear animation of a node (the module docstring): a key per
    frame at ``perf.times``, the node's translation, rotation and scale
    (:func:`~facemime.export.animation.node_keys`) and, when the performance has targets, the
    mesh's weights.

    Parameters
    ----------
    g
        The document being built.
    perf
        The performance.
    node
        The index of the node animated, the one holding the mesh of :func:`add_face`.

    Returns
    -------
    int
        The animation's index in ``g.doc["animations"]``.
    """
    translation, rotation, scale = node_keys(perf.poses, perf.metres_per_unit)
    times = g.accessor(perf.times.astype(np.float32), bounds=True)
    channels = [("translation", translation), ("rotation", rotation), ("scale", scale)]
    if perf.names:
        channels.append(("weights", perf.weights.reshape(-1)))
    samplers, targets = [], []
    for k, (path, values) in enumerate(channels):
        samplers.append({"input": times, "output": g.accessor(values.astype(np.float32)), "interpolation": "LINEAR"})
        targets.append({"sampler": k, "target": {"node": node, "path": path}})
    return g.add("animations", {"name": "performance", "channels": targets, "samplers": samplers})


def glb_bytes(perf: Performance) -> bytes:
    """The ``.glb`` file of a performance (see the module docstring).

    Parameters
    ----------
    perf
        The performance: the actor's mesh, texture and morph targets, and one animation key per
        frame.

    Returns
    -------
    bytes
        The binary glTF 2.0 file; positions and morph targets in metres, key times in seconds.
    """
    m = perf.metres_per_unit
    g = Glb(f"facemime {__version__}")
    mesh = add_face(g, perf)
    rotation = node_keys(perf.poses[:1], m)[1]
    node = g.add("nodes", {"name": perf.actor.model.name, "mesh": mesh, "rotation": rotation[0].tolist()})
    first = perf.poses[0]
    per_pixel = m / float(first[3])
    g.doc["scenes"] = [
        {
            "name": "performance",
            "nodes": [node],
            "extras": {
                "facemime": {
                    "size": list(perf.size),
                    "metres_per_pixel": per_pixel,
                    "origin": [float(first[4]), float(first[5])],
                    "pose_mapping": "rotation Rz(roll)Rx(pitch)Ry(yaw); scale relative to the first frame; "
                    "translation: pixel shift from the first frame times metres_per_pixel, image y down = -y",
                }
            },
        }
    ]
    g.doc["scene"] = 0
    add_animation(g, perf, node)
    return g.bytes()


def _file_weights(path: Path, names: tuple[str, ...], key: str = "weights") -> np.ndarray | None:
    """(T, E) weights stored in the track's frames (``key``: name -> value), in the order of
    ``names``, a missing name 0; None when a frame has none."""
    frames = load_document(path, "track", TRACK_FORMAT)["frames"]
    if not all(isinstance(f, dict) and key in f for f in frames):
        return None
    out = np.zeros((len(frames), len(names)))
    slot = {n: k for k, n in enumerate(names)}
    for t, f in enumerate(frames):
        w = f[key]
        if not isinstance(w, dict):
            raise ContourFileError(f"{path}: frame entry {t} has malformed {key!r}")
        for name, value in w.items():
            if name not in slot:
                raise ContourFileError(f"{path}: frame entry {t} {key!r} names {name!r}, not one of {', '.join(names)}")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise ContourFileError(f"{path}: frame entry {t} {key!r} value {name!r} must be a number in [0, 1]")
            out[t, slot[name]] = value
    return out


def load_performance(track: str | Path, actor: Actor | None = None) -> Performance:
    """The performance of a ``facemime.track/1`` file written by ``facemime run``, played by an
    actor.

    Parameters
    ----------
    track
        Path of the track file.
    actor
        The head that plays the track; None: the generic painted head framed in the track's video
        size, as ``facemime view`` plays a track file. Its model must have the generic head's
        expression controls and knots.

    Returns
    -------
    Performance
        The frames' ``arkit`` values when every frame has them, else ARKit's 52 of their
        ``weights`` when every frame has them, else of the controls solved from their knot
        offsets and eye closure (the look directions from their irises); key times
        ``index / fps`` seconds; each pose's scale multiplied by the track's outer eye corner
        distance over the actor model's (both model units), the size the head is shown at alone.
    """
    from facemime.animate.expressions import Expressions

    track = Path(track)
    video, block, frames = read_motion(track)
    size, fps, sizes, iod = track_settings(str(track), video, block)
    index = np.array([f["index"] for f in frames])
    if index.dtype.kind != "i" or (len(index) > 1 and (np.diff(index) <= 0).any()) or index[0] < 0:
        raise ContourFileError(f"{track}: frame indices must be whole numbers, increasing")
    if len(index) > 1 and (np.diff((index / fps).astype(np.float32)) <= 0).any():  # glTF's key times
        raise ContourFileError(
            f"{track}: frame indices up to {index[-1]} at {fps:g} frames/s are too late for glTF's times"
        )
    actor = actor or generic_actor(size)
    model = actor.model
    try:
        ex = Expressions.of(model)
    except (KeyError, IndexError, ValueError) as e:  # a head without the generic head's groups
        raise InvalidInputError(f"actor {model.name!r} is not a facemime head with expression controls ({e})") from None
    knots = block.get("knots", ex.deformer.knots.tolist())
    if len(knots) != len(ex.deformer.knots) or not all(
        isinstance(k, int) and 0 <= k < len(model.vertices) for k in knots
    ):
        raise InvalidInputError(
            f"the track's motion has {len(knots)} knots of another head model than actor "
            f"{model.name!r} ({len(ex.deformer.knots)} knots, {len(model.vertices)} vertices)"
        )
    weights = _file_weights(track, ARKIT, "arkit")  # as run measured them, live's own
    if weights is None:
        controls = _file_weights(track, ex.names)
        if controls is None:  # solved as the actor would play the knots: offsets scaled per feature (Puppet)
            ratio = (ex.deformer.feature_sizes() / sizes)[:, None]
            offsets = np.stack([f["offsets"] for f in frames]) * ratio
            closure = np.stack([f["look"].closure for f in frames])
            controls = np.asarray(ex.solve(offsets, closure), np.float64)
        weights = np.array([arkit_values(c, f["look"].iris) for c, f in zip(controls, frames)])
    fields = np.zeros((len(ARKIT), *ex.fields.shape[1:]))
    for k, name in enumerate(ARKIT):
        if name in ex.names:
            fields[k] = ex.fields[ex.names.index(name)]
    ratio = 1.0 if iod is None else iod / model_iod(model)
    poses = np.array([[f["pose"][k] for k in POSE_KEYS] for f in frames])
    poses[:, 3] *= ratio
    return Performance(actor, ARKIT, fields, index / fps, weights, poses, size)
