"""The motion of a ``facemime.track/1`` file written by ``facemime run`` (or authored as
expression weights), read into what synthesis plays: poses, knot offsets in model units, looks.
The file's format is :mod:`facemime.io.contours_json`'s; turning expression weights into knot
offsets (:mod:`facemime.animate.expressions`) is what makes this animation, not file reading."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.expressions import BLINKS, NAMES, generic_unit_patterns
from facemime.head import generic_head
from facemime.io.contours_json import LOOK_LIMIT, MAX_OFFSET, POSE_KEYS, TRACK_FORMAT, ContourFileError, load_document
from facemime.limits import pose_in_range
from facemime.types.head import model_iod
from facemime.types.look import Look


def _weights(raw: Any, where: str) -> np.ndarray:
    """The (E,) weight vector of a frame's ``weights`` object (name -> 0..1, a missing name 0)."""
    if not isinstance(raw, dict):
        raise ContourFileError(f"{where}: 'weights' must be an object of expression name -> weight in [0, 1]")
    unknown = [k for k in raw if k not in NAMES]
    if unknown:
        raise ContourFileError(
            f"{where}: unknown expression weight {unknown[0]!r} in 'weights' (known: {', '.join(NAMES)})"
        )
    w = np.zeros(len(NAMES))
    for k, v in raw.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= float(v) <= 1.0:
            raise ContourFileError(f"{where}: expression weight {k!r} must be a number in [0, 1], got {v!r}")
        w[NAMES.index(k)] = float(v)
    return w


def _generic_model_block() -> dict[str, Any]:
    """The ``model`` block of motion made for the generic head (its knots and sizes)."""
    head = generic_head()
    d = Deformer(head)
    return {
        "unit": head.unit,
        "knots": d.knots.tolist(),
        "feature_sizes": d.feature_sizes().tolist(),
        "iod": model_iod(head),
    }


def weights_to_motion(weights: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The knot offsets and lid closures of one frame's expression weights.

    Parameters
    ----------
    weights
        (E,) float array: the weights, in the order of
        :data:`~facemime.animate.expressions.NAMES`.
    sizes
        (K,) float array: the feature size of each knot of the face (whose knots are the generic
        head's, as every actor fitted from it), model units; raises ``ValueError`` when K is not
        the generic head's knot count.

    Returns
    -------
    offsets : (K, 2) float64 array
        Knot (x, y) offsets, model units (those of ``sizes``).
    closure : (2,) float array
        Lid closures (right eye, left eye): the blinks' weights.
    """
    unit = generic_unit_patterns()
    if len(sizes) != unit.shape[1]:
        raise ValueError(
            f"expression weights need the generic head's {unit.shape[1]} knots, the motion has {len(sizes)}"
        )
    offsets = np.tensordot(weights, unit * np.asarray(sizes, np.float64)[None, :, None], axes=([-1], [0]))
    return offsets, np.array([weights[NAMES.index(n)] for n in BLINKS])


def read_motion(path: str | Path) -> tuple[dict[str, Any], dict[str, Any], list[dict[str, Any]]]:
    """Read the motion of a ``facemime.track/1`` file written by ``facemime run`` (or authored).

    A frame with ``weights`` and no ``offsets`` gets its offsets from them, and its lid closures
    unless its ``look`` gives them (:mod:`facemime.animate.expressions`); a file of such frames
    needs no ``model`` block. Raises :class:`~facemime.io.contours_json.ContourFileError`, naming
    the file and the frame, for a malformed one.

    Parameters
    ----------
    path
        The track file.

    Returns
    -------
    video : dict
        The file's ``video`` block (empty where it has none).
    model : dict
        The ``model`` block (``knots``, ``feature_sizes``, ...); the generic head's for a file of
        frames with weights only and no block.
    frames : list of dict
        The frames in order, each with ``index`` (the file's, else the frame's position), ``face``
        (bool), ``pose`` (the six :class:`~facemime.types.pose.Pose` values by name, floats),
        ``offsets`` ((K, 2) float64 array, model units), ``look`` (a
        :class:`facemime.types.look.Look`; neutral for files written before it, or without one),
        ``weights`` ((E,) float64 expression weights, or None) and ``lost`` (the features named
        lost).
    """
    doc = load_document(path, "track", TRACK_FORMAT)
    where = str(path)
    model = doc.get("model")
    frames = doc.get("frames")
    authored = (
        isinstance(frames, list)
        and bool(frames)
        and all(isinstance(f, dict) and "offsets" not in f and "weights" in f for f in frames)
    )
    if model is None and authored:
        model = _generic_model_block()
    if (
        not isinstance(model, dict)
        or not isinstance(model.get("knots"), list)
        or not isinstance(model.get("feature_sizes"), list)
    ):
        raise ContourFileError(
            f"{where}: has no head motion ('model' with 'knots' and 'feature_sizes'); write it with facemime run"
        )
    if not isinstance(frames, list) or not frames:
        raise ContourFileError(f"{where}: 'frames' must be a non-empty list")
    k = len(model["knots"])
    out = []
    for n, f in enumerate(frames):
        pose, offsets = (f.get("pose", {}), f.get("offsets")) if isinstance(f, dict) else ({}, None)
        weights = None
        if isinstance(f, dict) and "weights" in f:
            weights = _weights(f["weights"], f"{where}: frame entry {n}")
        closure = None
        if offsets is None and weights is not None:
            try:
                offsets, closure = weights_to_motion(weights, np.asarray(model["feature_sizes"], np.float64))
            except (TypeError, ValueError) as e:
                raise ContourFileError(f"{where}: frame entry {n}: {e}") from None
        try:
            if any(isinstance(pose[key], bool) for key in POSE_KEYS):  # JSON's true is not a number here
                raise TypeError
            values = {key: float(pose[key]) for key in POSE_KEYS}
            arr = np.asarray(offsets, dtype=np.float64)
        except (TypeError, KeyError, ValueError, OverflowError):
            raise ContourFileError(
                f"{where}: frame entry {n} needs a 'pose' with {', '.join(POSE_KEYS)} and 'offsets' (or 'weights')"
            ) from None
        if arr.shape != (k, 2) or not np.isfinite(arr).all() or np.abs(arr).max(initial=0.0) > MAX_OFFSET:
            raise ContourFileError(f"{where}: frame entry {n} has malformed 'offsets'")
        if not pose_in_range(*(values[key] for key in POSE_KEYS)):
            raise ContourFileError(f"{where}: frame entry {n} has a pose out of range ({values})")
        try:
            look = f.get("look", {})
            if not isinstance(look, dict):
                raise TypeError
            if closure is not None:  # the blinks' closures where the look gives none
                look = {"eye_right_closure": closure[0], "eye_left_closure": closure[1], **look}
            look = Look.from_dict(look)
        except (TypeError, ValueError, OverflowError):
            raise ContourFileError(f"{where}: frame entry {n} has a malformed 'look'") from None
        if not np.isfinite(look.vector()).all() or np.abs(look.vector()).max() > LOOK_LIMIT:
            raise ContourFileError(f"{where}: frame entry {n} has a 'look' value beyond ±{LOOK_LIMIT:g}")
        lost = f.get("lost", [])
        if not isinstance(lost, list) or not all(isinstance(x, str) for x in lost):
            raise ContourFileError(f"{where}: frame entry {n}: 'lost' must be a list of feature names")
        out.append(
            {
                "index": f.get("index", n),
                "face": bool(f.get("face", True)),
                "pose": values,
                "offsets": arr,
                "look": look,
                "weights": weights,
                "lost": lost,
            }
        )
    return doc.get("video", {}), model, out
