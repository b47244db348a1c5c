"""2-D similarities (rotation, uniform scale, translation) as 2×3 matrices acting on (x, y)
pixel points: the head's motion in the picture, the scene's warp, re-detection's alignment."""

from __future__ import annotations

import numpy as np

from facemime import _core


def as_points(points: object) -> np.ndarray:
    """Points as the core takes (x, y) points.

    Parameters
    ----------
    points
        (x, y) pairs in any form numpy reads: an (N, 2) array, a list of pairs, or a flat
        sequence x0, y0, x1, ...

    Returns
    -------
    (N, 2) float64 array
        C-contiguous; shares memory with ``points`` when that already was such an array.
    """
    return np.ascontiguousarray(points, np.float64).reshape(-1, 2)


FIT_ROUNDS = 10  # rounds of the robust similarity fit at most


def robust_similarity(
    src: np.ndarray, dst: np.ndarray, limit: float, rounds: int = FIT_ROUNDS
) -> tuple[np.ndarray, np.ndarray]:
    """The similarity (rotation, uniform scale, translation) mapping points onto others despite
    outliers.

    Iteratively reweighted least squares with Tukey's biweight, started from the median
    displacement; deterministic (``facemime._core.robust_similarity``).

    Parameters
    ----------
    src
        (N, 2) float array: (x, y) pixels.
    dst
        (N, 2) float array: where each of ``src`` moved, (x, y) pixels.
    limit
        Residual below which a point is an inlier, pixels; the reweighting takes the residuals'
        robust spread as at least half of it.
    rounds
        Reweighting rounds at most.

    Returns
    -------
    similarity : (2, 3) float64 array
        Maps ``src`` onto ``dst`` (:func:`apply`); the identity for no points.
    inliers : (N,) bool array
        The points whose residual under it is below ``limit``.
    """
    return _core.robust_similarity(as_points(src), as_points(dst), float(limit), int(rounds))


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The composition of two 2×3 transforms (``facemime._core.compose``).

    Parameters
    ----------
    a
        (2, 3) float64 array: the transform applied second.
    b
        (2, 3) float64 array: the transform applied first.

    Returns
    -------
    (2, 3) float64 array
        The transform ``a ∘ b``.
    """
    return _core.compose(a, b)


def apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Apply a 2×3 transform to points.

    Parameters
    ----------
    m
        (2, 3) float array: the transform, acting on (x, y) column vectors.
    pts
        (N, 2) float array: (x, y) pixels.

    Returns
    -------
    (N, 2) float64 array
        The transformed (x, y), pixels.
    """
    return pts @ m[:, :2].T + m[:, 2]


IDENTITY = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
