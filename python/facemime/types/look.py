"""A frame's look beyond the mouth and brows: how far each eye is closed and where each iris
looks. Like the knot offsets, every value is relative to the key frame the actor was fitted on
(all zero: the eyes look as they did there), so it carries over to another actor.

- ``closure``: (2,) per eye, the subject's right (image-left) eye first. 0: the lids as on the
  key frame; 1: the upper lid down on the lower one; negative: opened wider. The share of the
  key frame's opening (upper-lid middle to lower-lid middle) that is closed.
- ``iris``: (2, 2) per eye, the iris centre's shift from its key-frame place, (u, v) in units of
  that eye's width (corner to corner): u along the line from the eye's image-left corner to its
  image-right corner, v across it, down on the screen for an upright face.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facemime.shared_constants import LOOK_NAMES as NAMES  # the order of Look.vector and of the stream's kinds


def _frozen(values, shape: tuple[int, ...]) -> np.ndarray:
    a = np.array(values, np.float64).reshape(shape)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class Look:
    """One frame's eyes (see the module docstring for units)."""

    closure: np.ndarray = field(default_factory=lambda: _frozen(np.zeros(2), (2,)))
    iris: np.ndarray = field(default_factory=lambda: _frozen(np.zeros(4), (2, 2)))

    def __post_init__(self) -> None:
        for name, shape in (("closure", (2,)), ("iris", (2, 2))):
            object.__setattr__(self, name, _frozen(getattr(self, name), shape))

    def vector(self) -> np.ndarray:
        """The look as one vector.

        Returns
        -------
        (6,) float64 array
            ``closure`` then ``iris`` row by row, in the order of :data:`NAMES`.
        """
        return np.concatenate([self.closure, self.iris.ravel()])

    @classmethod
    def from_vector(cls, v: np.ndarray) -> Look:
        """The look of a :meth:`vector`.

        Parameters
        ----------
        v
            (6,) float array in the order of :data:`NAMES`.

        Returns
        -------
        Look
            Its first two values the closures, the last four the iris shifts.
        """
        v = np.asarray(v, np.float64)
        return cls(v[0:2], v[2:6].reshape(2, 2))

    def as_dict(self) -> dict[str, float]:
        """The look as named values for a JSON file.

        Returns
        -------
        dict of str -> float
            :data:`NAMES` -> value, rounded to 4 decimals.
        """
        return {n: round(float(x), 4) for n, x in zip(NAMES, self.vector())}

    @classmethod
    def from_dict(cls, d: dict) -> Look:
        """The look of :meth:`as_dict`'s mapping.

        Parameters
        ----------
        d
            Name (of :data:`NAMES`) -> number; a missing name is 0, other keys are ignored.

        Returns
        -------
        Look
            The values in the module docstring's units.
        """
        return cls.from_vector(np.array([float(d.get(n, 0.0)) for n in NAMES]))
