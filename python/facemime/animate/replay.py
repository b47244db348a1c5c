"""Playing the motion of a ``facemime.track/1`` file (from ``facemime run``, or a performance
written by hand as expression weights, :mod:`facemime.animate.expressions`) on an actor: what
``view``, ``run`` and ``encode`` do with a track file instead of a video.

The actor is the one given, or the generic painted head; the picture has the size and frame rate
of the file's ``video`` block (512x512 at 25 frames/s where it gives none); an actor with a
scene is shown in it, moved relative to the track's first pose (:class:`Puppet`).
"""

from __future__ import annotations

import reprlib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from facemime.animate.analysis import FrameMotion
from facemime.animate.deform import Deformer
from facemime.animate.motion_file import read_motion
from facemime.animate.synth import Puppet
from facemime.errors import InvalidInputError
from facemime.fit.actor import generic_actor
from facemime.io.contours_json import ContourFileError
from facemime.limits import limit
from facemime.types.actor import Actor
from facemime.types.head import model_iod
from facemime.types.pose import Pose

#: The largest frame side of a track file's ``video`` block, pixels.
MAX_SIDE = 16384
#: The frame rates a track file may give (a video's own beyond them is clamped by the viewer).
FPS_RANGE = (0.1, 1000.0)


def track_settings(where: str, video: Any, model: dict) -> tuple[tuple[int, int], float, np.ndarray, float | None]:
    """The picture's settings and the measured face's sizes from a track file's ``video`` and
    ``model`` blocks, checked: :class:`ContourFileError` names the first wrong field.

    Parameters
    ----------
    where
        The file's name, in messages.
    video
        The ``video`` block: an object with optional ``width``, ``height`` and ``fps``.
    model
        The ``model`` block, with ``knots`` and ``feature_sizes`` lists (as :func:`read_motion`
        checked) and an optional ``iod``.

    Returns
    -------
    size : tuple of (int, int)
        (width, height) of the picture, pixels; 512x512 where the block gives none.
    fps : float
        The frame rate, frames/s; 25 where the block gives none.
    sizes : (K,) float64 array
        The measured face's feature size per knot, model units.
    iod : float or None
        The measured face's eye-corner distance, model units; None where the block gives none.
    """
    if not isinstance(video, dict):
        raise ContourFileError(f"{where}: 'video' must be an object (width, height, fps), got {reprlib.repr(video)}")

    def number(block: dict, key: str, default: float | None, ok: Any, expected: str) -> Any:
        value = block.get(key, default)
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float)) or not ok(value)):
            raise ContourFileError(f"{where}: {key!r} must be {expected}, got {reprlib.repr(value)}")
        return value

    side = (lambda v: isinstance(v, int) and 0 < v <= MAX_SIDE, f"a whole number from 1 to {MAX_SIDE}")
    size = (number(video, "width", 512, *side), number(video, "height", 512, *side))
    if size[0] * size[1] > limit("FACEMIME_MAX_IMAGE_PIXELS"):
        raise ContourFileError(
            f"{where}: a {size[0]}x{size[1]} frame is over the limit of "
            f"{limit('FACEMIME_MAX_IMAGE_PIXELS')} pixels (FACEMIME_MAX_IMAGE_PIXELS)"
        )
    fps = float(
        number(
            video,
            "fps",
            25.0,
            lambda v: FPS_RANGE[0] <= v <= FPS_RANGE[1],
            f"a number from {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}",
        )
    )
    iod = number(model, "iod", None, lambda v: 0 < v < float("inf"), "a positive number")
    sizes = model["feature_sizes"]
    if (
        len(sizes) != len(model["knots"])
        or any(isinstance(s, bool) or not isinstance(s, (int, float)) for s in sizes)
        or not all(0 < s < float("inf") for s in sizes)
    ):
        raise ContourFileError(f"{where}: 'feature_sizes' must be {len(model['knots'])} positive numbers, one per knot")
    return size, fps, np.asarray(sizes, np.float64), None if iod is None else float(iod)


@dataclass
class Replay:
    """A track file's motion, ready to play: the ``actor`` it drives, the picture's ``size``
    (width, height) and ``fps``, the ``motion`` per frame (in the measured face's units; no
    contours), and the measured face's feature ``sizes`` (K,) and eye distance ``iod`` (model
    units)."""

    actor: Actor
    size: tuple[int, int]
    fps: float
    motion: list[FrameMotion]
    sizes: np.ndarray
    iod: float

    def puppet(self, mask_only: bool = False) -> Puppet:
        """The actor driven by this motion.

        Parameters
        ----------
        mask_only
            Show the face alone, not in the actor's scene (it is alone anyway without one).

        Returns
        -------
        Puppet
            The actor driven by the motion; in its scene, moved relative to the motion's first
            pose.
        """
        return Puppet(self.actor, self.sizes, self.iod, self.motion[0].pose, mask_only)

    def in_actor_units(self) -> list[FrameMotion]:
        """The motion as measured on the actor itself (what a stream carries).

        Returns
        -------
        list of FrameMotion
            One per frame: offsets scaled per knot by the ratio of the feature sizes, model units of
            the actor, and the pose's scale by the ratio of the eye distances, as :class:`Puppet`
            does when it plays.
        """
        ratio = (Deformer(self.actor.model).feature_sizes() / self.sizes)[:, None]
        scale = self.iod / model_iod(self.actor.model)
        return [
            replace(m, offsets=m.offsets * ratio, pose=replace(m.pose, scale=m.pose.scale * scale)) for m in self.motion
        ]


def load_replay(path: str | Path, actor: Actor | None = None) -> Replay:
    """The motion of a track file on an actor; one-line errors (:class:`ContourFileError`) for a
    malformed file.

    Parameters
    ----------
    path
        The ``facemime.track/1`` file.
    actor
        The actor it drives, with the file's knot count (else
        :class:`~facemime.errors.InvalidInputError`); None: the generic painted head.

    Returns
    -------
    Replay
        The motion ready to play; its ``iod`` the actor model's where the file gives none.
    """
    video, model, frames = read_motion(path)
    size, fps, sizes, iod = track_settings(str(path), video, model)
    driven = actor or generic_actor()
    knots = len(Deformer(driven.model).knots)
    if len(sizes) != knots:
        raise InvalidInputError(
            f"the motion of {path} has {len(sizes)} knots but actor {driven.model.name!r} has {knots}"
        )
    motion = [
        FrameMotion({}, {}, list(f["lost"]), f["face"], Pose(**f["pose"]), f["offsets"], look=f["look"]) for f in frames
    ]
    return Replay(driven, size, fps, motion, sizes, model_iod(driven.model) if iod is None else iod)
