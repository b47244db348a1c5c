"""The actor's type: a head model fitted to one person, with that person's face smeared on it as
texture (made by :mod:`facemime.fit`, stored by :mod:`facemime.io.actor_file`).

Model coordinates are the generic head's (right-handed, x to the subject's left, y up, z towards
the camera, millimetres for the built-in head). Texture coordinates are in [0, 1] from the
texture's top-left corner; texel (i, j) has its centre at ((i + 0.5) / W, (j + 0.5) / H).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facemime.errors import InvalidInputError
from facemime.types.head import HeadModel
from facemime.types.points import ReferencePoints
from facemime.types.pose import Pose
from facemime.types.samples import MOUTH_GROUPS, Samples


@dataclass(frozen=True, eq=False)
class Actor:
    """A fitted, textured head.

    Attributes
    ----------
    model : HeadModel
        The adjusted model; its ``uv`` address ``texture``.
    texture : (H, W, 3) uint8 array
        RGB, the source photo cropped around the face.
    pose : Pose
        The frontal pose that maps ``model.vertices`` onto the source photo.
    source : dict
        Where the face came from: ``file`` (name only), ``frame``, ``width``, ``height``.
    points : dict of str -> (K, 2) float64 array
        The reference points the model was fitted to, pixels of the source photo.
    scene : (Hs, Ws, 3) uint8 array or None
        RGB, the whole source photo (shrunk to at most :data:`facemime.fit.actor.SCENE_MAX_SIDE` pixels a side):
        the picture the face is synthesised in (:mod:`facemime.render.scene`); None for an
        actor without one (the face is then shown alone).
    samples : Samples or None
        The actor's own mouth and eyes as frames of a clip showed them
        (:mod:`facemime.types.samples`); None: the mouth's interior is drawn and the irises are
        moved in the texture.
    """

    model: HeadModel
    texture: np.ndarray
    pose: Pose
    source: dict = field(default_factory=dict)
    points: ReferencePoints = field(default_factory=dict)
    scene: np.ndarray | None = None
    samples: Samples | None = None

    def __post_init__(self) -> None:
        for name, t in (("texture", self.texture), ("scene", self.scene)):
            if t is None and name == "scene":
                continue
            if not (
                isinstance(t, np.ndarray)
                and t.dtype == np.uint8
                and t.ndim == 3
                and t.shape[2] == 3
                and min(t.shape[:2]) >= 1
            ):
                raise InvalidInputError(
                    f"actor {name} must be an (H, W, 3) uint8 image, got {getattr(t, 'shape', type(t).__name__)}"
                )
        if self.scene is not None and not all(
            isinstance(self.source.get(k), int) and self.source[k] > 0 for k in ("width", "height")
        ):
            raise InvalidInputError("an actor with a scene needs its source picture's width and height")
        if self.model.uv is None:
            raise InvalidInputError("actor model needs texture coordinates (uv)")
        if self.samples is not None:
            h, w = self.texture.shape[:2]
            lips = len(np.unique(np.concatenate([self.model.groups[n] for n in MOUTH_GROUPS])))
            for g in self.samples.groups:
                x, y, bw, bh = g.boxes.T
                if ((x >= w) | (bw > w - x) | (y >= h) | (bh > h - y)).any():
                    raise InvalidInputError(f"sample group {g.name!r} has a box outside the {w}x{h} texture")
                if g.name == "mouth" and g.keys.shape[1] != 2 * lips:
                    raise InvalidInputError(
                        f"sample group 'mouth': its keys must hold the {lips} lip knots' (x, y), "
                        f"got {g.keys.shape[1]} values"
                    )
