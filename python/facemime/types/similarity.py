"""2-D similarities (rotation, uniform scale, translation) as 2×3 matrices acting on (x, y)
pixel points: the head's motion in the picture, the scene's warp, re-detection's alignment."""

from __future__ import annotations

import numpy as np

from facemime import _core


def as_points(points: object) -> np.ndarray:
    """``points`` as the core takes (x, y) points: a C-contiguous (N, 2) float64 array."""
    return np.ascontiguousarray(points, np.float64).reshape(-1, 2)


FIT_ROUNDS = 10  # rounds of the robust similarity fit at most


def robust_similarity(
    src: np.ndarray, dst: np.ndarray, limit: float, rounds: int = FIT_ROUNDS
) -> tuple[np.ndarray, np.ndarray]:
    """The 2×3 similarity (rotation, uniform scale, translation) mapping ``src`` (N, 2) onto
    ``dst`` (N, 2) px despite outliers, and the (N,) inlier mask (residual below ``limit`` px).
    Iteratively reweighted least squares with Tukey's biweight, started from the median
    displacement; deterministic (``facemime._core.robust_similarity``)."""
    return _core.robust_similarity(as_points(src), as_points(dst), float(limit), int(rounds))


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The 2×3 transform ``a ∘ b`` (apply ``b`` first; ``facemime._core.compose``)."""
    return _core.compose(a, b)


def apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Apply a 2×3 transform to (N, 2) points."""
    return pts @ m[:, :2].T + m[:, 2]


IDENTITY = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
