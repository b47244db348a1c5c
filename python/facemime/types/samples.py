"""An actor's library of its own mouth and eyes: samples of the texture's eye and mouth regions
as real frames showed them, each indexed by the shape it shows (issue 64; Cosatto and Graf's
sample-based synthesis).

A sample is a rectangle of the actor's texture (texels: x right, y down, (0, 0) the top-left
texel) taken from one frame: the frame laid back onto the texture through the geometry the
receiver draws (:func:`facemime.codec.appearance.lay_back`). The synthesis of a frame pastes, for
each group, the sample whose shape is nearest the frame's (:mod:`facemime.animate.samples`).

Groups: ``eyes`` (both eye rectangles, from one frame, so that the two eyes always look the same
way), indexed by the frame's :class:`~facemime.types.look.Look` vector; ``mouth`` (one
rectangle around the lips), indexed by the mouth knots' offsets (model units, relative to the key
frame like every offset).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facemime.errors import InvalidInputError
from facemime.shared_constants import SAMPLE_GROUPS as GROUPS  # the groups a library may hold, in painting order


def _rgb(image: object) -> bool:
    """Whether ``image`` is an (h, w, 3) uint8 array."""
    return isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3


@dataclass(frozen=True, eq=False)
class SampleGroup:
    """The samples of one group.

    Attributes
    ----------
    name : str
        One of :data:`GROUPS`.
    boxes : (B, 4) int64 array
        Each rectangle's left column, top row, width and height in the texture, texels.
    images : list of list of (H, W, 3) uint8 arrays
        Per sample, its image of each rectangle (RGB, the rectangle's size).
    keys : (S, D) float64 array
        Per sample, the shape it shows: the look vector (``eyes``, D = 6) or the mouth knots'
        (x, y) offsets flattened (``mouth``, model units).
    frames : (S,) int64 array
        Per sample, the index of the frame it was taken from (informative).
    interiors : list of ((h, w, 3) uint8 array or None) or None
        ``mouth`` only: per sample, the mouth's opening as its frame showed it, laid out between
        the inner lips (:func:`facemime.animate.samples.interior_uv`); None for a sample whose
        mouth was closed. None: no sample has one.
    """

    name: str
    boxes: np.ndarray
    images: list[list[np.ndarray]]
    keys: np.ndarray
    frames: np.ndarray
    interiors: list[np.ndarray | None] | None = None

    def __post_init__(self) -> None:
        if self.name not in GROUPS:
            raise InvalidInputError(f"a sample group is one of {', '.join(GROUPS)}, got {self.name!r}")
        boxes = np.asarray(self.boxes)
        if boxes.ndim != 2 or boxes.shape[1] != 4 or not len(boxes) or (boxes[:, 2:] < 1).any() or (boxes < 0).any():
            raise InvalidInputError(f"sample group {self.name!r}: boxes must be rows of x, y, width, height ≥ 0")
        keys = np.asarray(self.keys, np.float64)
        if keys.ndim != 2 or len(keys) != len(self.images) or len(self.frames) != len(keys) or not len(keys):
            raise InvalidInputError(f"sample group {self.name!r}: one key and one frame per sample are needed")
        if self.name == "eyes" and keys.shape[1] != 6:
            raise InvalidInputError(f"sample group 'eyes': its keys are looks of 6 values, got {keys.shape[1]}")
        if not np.isfinite(keys).all():
            raise InvalidInputError(f"sample group {self.name!r}: its keys must be finite")
        for sample in self.images:
            if len(sample) != len(boxes) or any(
                not (_rgb(im) and im.shape[:2] == (int(h), int(w))) for im, (_, _, w, h) in zip(sample, boxes)
            ):
                raise InvalidInputError(
                    f"sample group {self.name!r}: each sample needs an RGB image of each box's size"
                )
        if self.interiors is not None:
            if self.name != "mouth" or len(self.interiors) != len(keys):
                raise InvalidInputError(f"sample group {self.name!r}: interiors are the mouth's, one per sample")
            inside = [im for im in self.interiors if im is not None]
            if any(
                not (
                    isinstance(im, np.ndarray)
                    and im.dtype == np.uint8
                    and im.ndim == 3
                    and im.shape[2] == 3
                    and min(im.shape[:2]) >= 1
                )
                for im in inside
            ):
                raise InvalidInputError("sample group 'mouth': an interior is an (h, w, 3) uint8 RGB image")
            if len({im.shape for im in inside}) > 1:
                raise InvalidInputError("sample group 'mouth': its interiors must be of one size")


@dataclass(frozen=True, eq=False)
class Samples:
    """An actor's sample library: its groups, at most one of each name."""

    groups: tuple[SampleGroup, ...]

    def __post_init__(self) -> None:
        names = [g.name for g in self.groups]
        if len(set(names)) != len(names):
            raise InvalidInputError(f"a sample library holds each group once, got {', '.join(names)}")

    def group(self, name: str) -> SampleGroup | None:
        """The group of a name.

        Parameters
        ----------
        name
            One of :data:`GROUPS`.

        Returns
        -------
        SampleGroup or None
            None when the library has no such group.
        """
        return next((g for g in self.groups if g.name == name), None)
