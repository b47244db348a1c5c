"""A bounded least-squares solver, frame after frame: the expression weights in [0, 1] that best
explain a frame's knot offsets, pulled towards the previous frame's (:class:`BoxLeastSquares`), as
:mod:`facemime.animate.expressions` solves them."""

from __future__ import annotations

import numpy as np


class BoxLeastSquares:
    """Frame after frame (:meth:`step`), the w in [0, ``upper``]^E minimising ½ wᵀ(G + λI)w -
    (r_t + λ w_{t-1})ᵀ w for G = ``gram``, λ = ``lam`` and the frame's r_t (w_{-1} = 0): least
    squares with a pull towards the previous frame's weights.

    A primal active-set method (Lawson-Hanson's, with upper bounds), warm-started from the
    previous frame's solution and its bounds: a frame mostly takes one or two small solves. It
    is exact (no tolerance on the optimum beyond round-off) and needs no dependency (SciPy's
    ``lsq_linear``, the alternative, is not one of facemime's); 1,000 frames of 23 controls take
    0.13-0.20 s on one core (the shared videos, best of three; benchmarks/expressions.py).

    Parameters
    ----------
    gram
        (E, E) float array: G, the Gram matrix of the patterns (symmetric, positive semi-definite).
    lam
        λ, the pull towards the previous frame's weights.
    upper
        The weights' upper bound.
    """

    def __init__(self, gram: np.ndarray, lam: float, upper: float = 1.0):
        e = gram.shape[0]
        self.h, self.lam, self.upper = gram + lam * np.eye(e), lam, upper
        self.w = np.zeros(e)
        self.fixed = np.ones(e, bool)  # at a bound; at first all at 0

    def step(self, r: np.ndarray) -> np.ndarray:
        """The next frame's weights.

        Parameters
        ----------
        r
            (E,) float array: r_t, the patterns' dot products with the frame's offsets.

        Returns
        -------
        (E,) float64 array
            The weights w in [0, ``upper``] (a copy).
        """
        h, upper, w, fixed = self.h, self.upper, self.w, self.fixed
        b = r + self.lam * w
        for _ in range(6 * len(w)):
            free = ~fixed
            target = w.copy()
            if free.any():
                target[free] = np.linalg.solve(h[np.ix_(free, free)], b[free] - h[np.ix_(free, fixed)] @ w[fixed])
            low, high = free & (target < 0.0), free & (target > upper)
            if low.any() or high.any():  # step towards the target as far as the box allows
                d = target - w
                with np.errstate(divide="ignore", invalid="ignore"):
                    steps = np.where(low, -w / d, np.where(high, (upper - w) / d, np.inf))
                alpha = float(np.clip(steps.min(), 0.0, 1.0))
                w = w + alpha * d
                hit = (low | high) & (steps <= alpha + 1e-12)
                w[hit & low] = 0.0
                w[hit & high] = upper
                fixed |= hit
                continue
            w = target
            grad = h @ w - b  # > 0 at 0 or < 0 at the top: the bound holds it; else release it
            push = np.where(fixed & (w <= 0.0), -grad, np.where(fixed & (w >= upper), grad, 0.0))
            if push.max() <= 1e-12 * max(1.0, float(np.abs(b).max())):
                break
            fixed[int(np.argmax(push))] = False
        self.w, self.fixed = w, fixed
        return w.copy()


def box_qp_sequence(gram: np.ndarray, rhs: np.ndarray, lam: float, upper: float = 1.0) -> np.ndarray:
    """:meth:`BoxLeastSquares.step` over every row of ``rhs``, from w_{-1} = 0.

    Parameters
    ----------
    gram
        (E, E) float array: G, the Gram matrix of the patterns.
    rhs
        (T, E) float array: r_t per frame, the patterns' dot products with its offsets.
    lam
        λ, the pull towards the previous frame's weights.
    upper
        The weights' upper bound.

    Returns
    -------
    (T, E) float64 array
        The weights per frame, in [0, ``upper``].
    """
    solver = BoxLeastSquares(gram, lam, upper)
    return np.array([solver.step(r) for r in rhs]).reshape(len(rhs), gram.shape[0])
