"""Argument checks shared by the public API: each raises :class:`InvalidInputError` with one
line naming the argument, what was expected and what was given."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from facemime import _core
from facemime.errors import InvalidInputError


def _describe(a: object) -> str:
    if isinstance(a, np.ndarray):
        return f"array of shape {a.shape} and dtype {a.dtype}"
    return type(a).__name__


def float_array(name: str, a: object, shape: tuple[int | None, ...]) -> np.ndarray:
    """An argument as a C-contiguous float64 array of a given shape, all finite.

    Parameters
    ----------
    name
        The argument's name, for the error message.
    a
        The value given: anything numpy converts to a numeric array.
    shape
        The expected shape, one entry per dimension; None: any size.

    Returns
    -------
    float64 array
        ``a`` converted (``a`` itself when it already was such an array).

    Examples
    --------
    >>> float_array("points", [[0, 1], [2, 3]], (None, 2)).dtype
    dtype('float64')
    """
    try:
        arr = np.ascontiguousarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be a numeric array of shape {_shape_text(shape)}, got {_describe(a)}"
        ) from None
    if arr.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, arr.shape)):
        raise InvalidInputError(f"{name} must have shape {_shape_text(shape)}, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise InvalidInputError(f"{name} must be finite, found NaN or inf")
    return arr


def index_array(name: str, a: object, columns: int, count: int) -> np.ndarray:
    """An argument as a C-contiguous array of indices, e.g. triangles.

    Parameters
    ----------
    name
        The argument's name, for the error message.
    a
        The value given: a 2-D integer array (or anything numpy converts to one).
    columns
        The number of indices per row.
    count
        The number of items indexed (vertices); every index must be below it.

    Returns
    -------
    (F, columns) uint32 array
        ``a`` converted.
    """
    arr = np.asarray(a)
    if arr.ndim != 2 or arr.shape[1] != columns:
        raise InvalidInputError(f"{name} must have shape (F, {columns}), got {_describe(arr)}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise InvalidInputError(f"{name} must hold integer indices, got dtype {arr.dtype}")
    if arr.size and (arr.min() < 0 or arr.max() >= count):
        bad = int(arr.min()) if arr.min() < 0 else int(arr.max())
        raise InvalidInputError(f"{name} index {bad} is out of range for {count} vertices")
    return np.ascontiguousarray(arr, dtype=np.uint32)


def image(name: str, a: object) -> np.ndarray:
    """An argument as a C-contiguous uint8 image.

    Parameters
    ----------
    name
        The argument's name, for the error message.
    a
        The value given: a uint8 numpy array, (H, W) gray or (H, W, C) with C in 1..4, not empty.

    Returns
    -------
    (H, W) or (H, W, C) uint8 array
        ``a`` itself when it is C-contiguous, else a contiguous copy.
    """
    if not isinstance(a, np.ndarray) or a.dtype != np.uint8:
        raise InvalidInputError(f"{name} must be a uint8 numpy array (H, W) or (H, W, C), got {_describe(a)}")
    if a.ndim not in (2, 3) or (a.ndim == 3 and not 1 <= a.shape[2] <= 4) or 0 in a.shape:
        raise InvalidInputError(f"{name} must have shape (H, W) or (H, W, C) with C in 1..4, got {a.shape}")
    return np.ascontiguousarray(a)


def image_size(name: str, size: object) -> tuple[int, int]:
    """An argument as an image size within the core's limits.

    Parameters
    ----------
    name
        The argument's name, for the error message.
    size
        The value given: two numbers int() takes, (width, height) pixels.

    Returns
    -------
    tuple of (int, int)
        (width, height) pixels, each positive and at most ``_core.MAX_IMAGE_SIDE``, their
        product at most ``_core.MAX_IMAGE_PIXELS``.
    """
    try:
        if not isinstance(size, Iterable):
            raise TypeError
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a (width, height) pair of integers, got {size!r}") from None
    if w <= 0 or h <= 0:
        raise InvalidInputError(f"{name} must be positive, got {w}x{h}")
    if w > _core.MAX_IMAGE_SIDE or h > _core.MAX_IMAGE_SIDE or w * h > _core.MAX_IMAGE_PIXELS:
        raise InvalidInputError(
            f"{name} {w}x{h} is too large: at most {_core.MAX_IMAGE_SIDE} pixels per side and "
            f"{_core.MAX_IMAGE_PIXELS} pixels in all"
        )
    return w, h


def choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    """An argument that must be one of a few names.

    Parameters
    ----------
    name
        The argument's name, for the error message.
    value
        The value given.
    allowed
        The names accepted.

    Returns
    -------
    str
        ``value``, when it is one of ``allowed``.
    """
    if value not in allowed:
        raise InvalidInputError(f"{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")
    return str(value)


def _shape_text(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("N" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
