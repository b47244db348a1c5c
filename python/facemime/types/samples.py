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
from facemime.shared_constants import INTERIOR_SIZE
from facemime.shared_constants import SAMPLE_GROUPS as GROUPS  # the groups a library may hold, in painting order

#: The head model's groups whose knots key the mouth's samples.
MOUTH_GROUPS = ("mouth_outer_upper", "mouth_outer_lower", "mouth_inner_upper", "mouth_inner_lower")
#: A key's values at most, in absolute value (shares, eye widths, model units).
MAX_KEY = 1e4
#: Samples a group, and boxes a group, at most; texels of a library's images at most (boxes and
#: interiors, all samples: 64 MB of RGB).
MAX_SAMPLES = 64
MAX_BOXES = 4
MAX_TEXELS = 1 << 24


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
    interiors : list of ((40, 96, 3) uint8 array or None) or None
        ``mouth`` only: per sample, the mouth's opening as its frame showed it, laid out between
        the inner lips (:func:`facemime.animate.samples.interior_uv`,
        :data:`~facemime.shared_constants.INTERIOR_SIZE`); None for a sample whose mouth was
        closed. None: no sample has one.
    """

    name: str
    boxes: np.ndarray
    images: list[list[np.ndarray]]
    keys: np.ndarray
    frames: np.ndarray
    interiors: list[np.ndarray | None] | None = None

    def __post_init__(self) -> None:
        try:
            self._check()
        except InvalidInputError:
            raise
        except (TypeError, ValueError, AttributeError, IndexError) as e:  # arrays of the wrong kind
            raise InvalidInputError(f"sample group {self.name!r}: malformed ({e})") from None

    def _check(self) -> None:
        if not isinstance(self.name, str) or self.name not in GROUPS:
            raise InvalidInputError(f"a sample group is one of {', '.join(GROUPS)}, got {self.name!r}")
        boxes = np.asarray(self.boxes)
        if (
            boxes.dtype.kind not in "iu"
            or boxes.ndim != 2
            or boxes.shape[1] != 4
            or not 1 <= len(boxes) <= MAX_BOXES
            or (boxes[:, 2:] < 1).any()
            or (boxes < 0).any()
            or (boxes > 1 << 16).any()
        ):
            raise InvalidInputError(
                f"sample group {self.name!r}: boxes must be 1-{MAX_BOXES} rows of integer x, y, width, height ≥ 0"
            )
        object.__setattr__(self, "boxes", boxes.astype(np.int64))
        keys = np.asarray(self.keys)
        if keys.dtype.kind not in "iuf" or keys.ndim != 2:
            raise InvalidInputError(f"sample group {self.name!r}: keys must be rows of real numbers")
        object.__setattr__(self, "keys", keys := keys.astype(np.float64))
        frames = np.asarray(self.frames)
        if frames.dtype.kind not in "iu" or frames.shape != (len(keys),) or not isinstance(self.images, list):
            raise InvalidInputError(f"sample group {self.name!r}: one key, one frame and one image list per sample")
        object.__setattr__(self, "frames", frames.astype(np.int64))
        if len(self.images) != len(keys) or not 1 <= len(keys) <= MAX_SAMPLES:
            raise InvalidInputError(
                f"sample group {self.name!r}: 1-{MAX_SAMPLES} samples, each with its key and images"
            )
        if self.name == "eyes" and keys.shape[1] != 6:
            raise InvalidInputError(f"sample group 'eyes': its keys are looks of 6 values, got {keys.shape[1]}")
        if not np.isfinite(keys).all() or (np.abs(keys) > MAX_KEY).any():
            raise InvalidInputError(f"sample group {self.name!r}: its keys must be finite, within ±{MAX_KEY:g}")
        if len(keys) * int((boxes[:, 2] * boxes[:, 3]).sum()) > MAX_TEXELS:
            raise InvalidInputError(f"sample group {self.name!r}: more than {MAX_TEXELS} texels of images")
        for sample in self.images:
            if (
                not isinstance(sample, list | tuple)
                or len(sample) != len(boxes)
                or any(not (_rgb(im) and im.shape[:2] == (int(h), int(w))) for im, (_, _, w, h) in zip(sample, boxes))
            ):
                raise InvalidInputError(
                    f"sample group {self.name!r}: each sample needs an RGB image of each box's size"
                )
        if self.interiors is not None:
            if self.name != "mouth" or not isinstance(self.interiors, list) or len(self.interiors) != len(keys):
                raise InvalidInputError(f"sample group {self.name!r}: interiors are the mouth's, one per sample")
            w, h = INTERIOR_SIZE
            if any(im is not None and not (_rgb(im) and im.shape[:2] == (h, w)) for im in self.interiors):
                raise InvalidInputError(f"sample group 'mouth': an interior is a {w} x {h} RGB image")


@dataclass(frozen=True, eq=False)
class Samples:
    """An actor's sample library: its groups, at most one of each name."""

    groups: tuple[SampleGroup, ...]

    def __post_init__(self) -> None:
        if not isinstance(self.groups, tuple) or not all(isinstance(g, SampleGroup) for g in self.groups):
            raise InvalidInputError("a sample library is a tuple of sample groups")
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
