"""A frame's motion as the bitstream's parameter vector, and back.

The vector is the head pose (yaw, pitch, roll in degrees; ln of the scale, the scale in pixels
per model unit; tx, ty in pixels: :class:`facemime.types.pose.Pose`) followed by M
coefficients of the knot offsets on an orthonormal basis (model units, millimetres for the
generic head): offsets (K, 2), flattened x0, y0, x1, y1, ..., are ``basis.T @ coefficients``.
The basis travels in the stream's header as int16 (entries ×32767); both ends use that
quantised basis, so they agree exactly. A version-2 stream (``docs/bitstream.md``, "Look") ends
the vector with *extras*, each named by a kind: facemime sends the six values of a
:class:`facemime.types.look.Look` as kinds 1-6 (:data:`LOOK_KINDS`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from facemime.animate.deform import Deformer
from facemime.shared_constants import BASIS_ONE, LOOK_NAMES, POSE_FIELDS
from facemime.types.head import HeadModel
from facemime.types.look import Look
from facemime.types.pose import Pose

POSE_PARAMETERS = len(POSE_FIELDS)
#: The extra parameters' kinds of the look's values, in the order of :meth:`Look.vector`
#: (``facemime.types.look.NAMES``): kind k is ``vector()[k - 1]``.
LOOK_KINDS = tuple(range(1, len(LOOK_NAMES) + 1))


def pose_vector(pose: Pose) -> np.ndarray:
    """(6,) yaw, pitch, roll, ln scale, tx, ty."""
    return np.array([pose.yaw, pose.pitch, pose.roll, np.log(pose.scale), pose.tx, pose.ty])


def pose_from_vector(v: np.ndarray) -> Pose:
    """The pose of a (6,) :func:`pose_vector`."""
    return Pose(
        yaw=float(v[0]), pitch=float(v[1]), roll=float(v[2]), scale=float(np.exp(v[3])), tx=float(v[4]), ty=float(v[5])
    )


def look_from_extras(kinds: tuple[int, ...], values: np.ndarray) -> Look:
    """The look of a stream's extras: ``values`` (X,) of the parameters of ``kinds`` (X,). A kind
    that is not a look value (:data:`LOOK_KINDS`) is ignored; a look value without its kind is 0.

    Examples
    --------
    >>> look_from_extras((5, 1, 7, 200), np.array([0.25, 0.5, 8.0, 9.0])).vector().tolist()
    [0.5, 0.0, 0.0, 0.0, 0.25, 0.0]
    """
    v = np.zeros(len(LOOK_KINDS))
    for kind, value in zip(kinds, values):
        if kind in LOOK_KINDS:
            v[kind - 1] = value
    return Look.from_vector(v)


@dataclass(frozen=True, eq=False)
class Basis:
    """M orthonormal directions of knot motion: ``raw`` (M, 2K) int16 as sent, ``vectors`` the
    same as float64."""

    raw: np.ndarray

    @cached_property
    def vectors(self) -> np.ndarray:
        return self.raw.astype(np.float64) / BASIS_ONE

    @classmethod
    def learn(cls, offsets: np.ndarray, m: int) -> Basis:
        """The ``m`` principal directions (uncentred: the rest shape is offset zero) of
        ``offsets`` (T, K, 2) model units, from a singular value decomposition. Fewer frames
        than ``m`` give the remaining directions of the knots' own coordinates."""
        x = np.asarray(offsets, np.float64).reshape(len(offsets), -1)
        rows = x.shape[1]
        m = int(min(m, rows))
        vt = np.linalg.svd(x, full_matrices=True)[2] if len(x) else np.eye(rows)
        return cls(np.round(vt[:m] * BASIS_ONE).astype(np.int16))

    def coefficients(self, offsets: np.ndarray) -> np.ndarray:
        """(M,) coefficients of (K, 2) offsets."""
        return self.vectors @ np.asarray(offsets, np.float64).ravel()

    def offsets(self, coefficients: np.ndarray) -> np.ndarray:
        """(K, 2) offsets of (M,) coefficients."""
        return (self.vectors.T @ np.asarray(coefficients, np.float64)).reshape(-1, 2)


def topology_id(model: HeadModel) -> bytes:
    """Eight bytes naming the model's topology: its vertex count, triangles and knot vertices
    (the first 8 bytes of the SHA-256 of their compact JSON, ``docs/bitstream.md``)."""
    doc = {
        "vertices": len(model.vertices),
        "triangles": np.asarray(model.triangles).tolist(),
        "knots": Deformer(model).knots.tolist(),
    }
    return hashlib.sha256(json.dumps(doc, separators=(",", ":")).encode()).digest()[:8]
