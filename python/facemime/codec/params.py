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
from facemime.shared_constants import BASIS_ONE, LOOK_NAMES, POSE_FIELDS, SAMPLE_KINDS
from facemime.types.head import HeadModel
from facemime.types.look import Look
from facemime.types.pose import Pose

POSE_PARAMETERS = len(POSE_FIELDS)
#: The extra parameters' kinds of the look's values, in the order of :meth:`Look.vector`
#: (``facemime.types.look.NAMES``): kind k is ``vector()[k - 1]``.
LOOK_KINDS = tuple(range(1, len(LOOK_NAMES) + 1))


def pose_vector(pose: Pose) -> np.ndarray:
    """The first six parameters of a frame (``docs/bitstream.md``, "Parameters"): the pose's.

    Parameters
    ----------
    pose
        The head pose.

    Returns
    -------
    (6,) float64 array
        yaw, pitch, roll (degrees), ln of the scale (scale in pixels per model unit), tx, ty
        (pixels).
    """
    return np.array([pose.yaw, pose.pitch, pose.roll, np.log(pose.scale), pose.tx, pose.ty])


def pose_from_vector(v: np.ndarray) -> Pose:
    """The pose of a :func:`pose_vector`.

    Parameters
    ----------
    v
        (6,) float array (only its first six entries are read): yaw, pitch, roll (degrees), ln of
        the scale (pixels per model unit), tx, ty (pixels).

    Returns
    -------
    Pose
        The head pose, its scale ``exp(v[3])``.
    """
    return Pose(
        yaw=float(v[0]), pitch=float(v[1]), roll=float(v[2]), scale=float(np.exp(v[3])), tx=float(v[4]), ty=float(v[5])
    )


def look_from_extras(kinds: tuple[int, ...], values: np.ndarray) -> Look:
    """The look of a stream's extra parameters (``docs/bitstream.md``, "Look (version 2)").

    A kind that is not a look value (:data:`LOOK_KINDS`) is ignored; a look value without its kind
    is 0.

    Parameters
    ----------
    kinds
        (X,) the extra parameters' kinds, in the header's order.
    values
        (X,) float array: the extra parameters' values, in the order of ``kinds``.

    Returns
    -------
    Look
        The look: eye closures (shares of the key frame's opening), iris shifts (eye widths).

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


def samples_from_extras(kinds: tuple[int, ...], values: np.ndarray) -> tuple[int | None, ...] | None:
    """The samples a stream chose for a frame (``docs/bitstream.md``, "Sample choices").

    Parameters
    ----------
    kinds
        (X,) the extra parameters' kinds, in the header's order.
    values
        (X,) float array: the extra parameters' values, in the order of ``kinds``.

    Returns
    -------
    tuple of (int or None) or None
        Per sample group (eyes, mouth), the index of the sample drawn, None for the key frame's
        own; None when the stream carries no choice (the receiver chooses by the shapes).

    Examples
    --------
    >>> samples_from_extras((1, 7, 8), np.array([0.5, 3.0, 0.0]))
    (2, None)
    >>> samples_from_extras((1,), np.array([0.5])) is None
    True
    """
    if not any(k in SAMPLE_KINDS for k in kinds):
        return None
    sent = dict(zip(kinds, values))
    return tuple(None if (k := int(round(float(sent.get(kind, 0.0))))) < 1 else k - 1 for kind in SAMPLE_KINDS)


@dataclass(frozen=True, eq=False)
class Basis:
    """M orthonormal directions of knot motion: ``raw`` (M, 2K) int16 as sent (entries ×32767),
    ``vectors`` the same as float64."""

    raw: np.ndarray

    @cached_property
    def vectors(self) -> np.ndarray:
        """The directions as numbers.

        Returns
        -------
        (M, 2K) float64 array
            :attr:`raw` / 32767: each row a unit direction over x0, y0, x1, y1, ...
        """
        return self.raw.astype(np.float64) / BASIS_ONE

    @classmethod
    def learn(cls, offsets: np.ndarray, m: int) -> Basis:
        """The principal directions (uncentred: the rest shape is offset zero) of knot offsets,
        from a singular value decomposition, quantised as sent.

        Parameters
        ----------
        offsets
            (T, K, 2) float array: each frame's knot offsets (x to the subject's left, y up),
            model units.
        m
            Directions wanted; at most 2K are given.

        Returns
        -------
        Basis
            min(``m``, 2K) directions, the most significant first. With fewer frames than ``m``,
            the directions after the T-th complete an orthonormal basis (as the SVD gives them).
        """
        x = np.asarray(offsets, np.float64).reshape(len(offsets), -1)
        rows = x.shape[1]
        m = int(min(m, rows))
        vt = np.linalg.svd(x, full_matrices=True)[2] if len(x) else np.eye(rows)
        return cls(np.round(vt[:m] * BASIS_ONE).astype(np.int16))

    def coefficients(self, offsets: np.ndarray) -> np.ndarray:
        """The coefficients of knot offsets on this basis (their projection).

        Parameters
        ----------
        offsets
            (K, 2) float array: the knots' offsets (x to the subject's left, y up), model units.

        Returns
        -------
        (M,) float64 array
            The coefficients, model units.
        """
        return self.vectors @ np.asarray(offsets, np.float64).ravel()

    def offsets(self, coefficients: np.ndarray) -> np.ndarray:
        """The knot offsets of coefficients on this basis.

        Parameters
        ----------
        coefficients
            (M,) float array, model units.

        Returns
        -------
        (K, 2) float64 array
            The knots' offsets (x to the subject's left, y up), model units.
        """
        return (self.vectors.T @ np.asarray(coefficients, np.float64)).reshape(-1, 2)


def topology_id(model: HeadModel) -> bytes:
    """The topology of a head model, as the stream's header names it (``docs/bitstream.md``,
    "Actor").

    Parameters
    ----------
    model
        The head model.

    Returns
    -------
    bytes
        Eight bytes: the first 8 of the SHA-256 of the compact JSON of the model's vertex count,
        triangles and knot vertices.
    """
    doc = {
        "vertices": len(model.vertices),
        "triangles": np.asarray(model.triangles).tolist(),
        "knots": Deformer(model).knots.tolist(),
    }
    return hashlib.sha256(json.dumps(doc, separators=(",", ":")).encode()).digest()[:8]
