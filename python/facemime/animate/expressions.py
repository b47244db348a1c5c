"""Named expression controls (blendshapes): the knot motion of the synthesis as weights.

Each control but the two blinks is a **pattern of knot offsets** (K, 2) at weight 1, spread to
every vertex by the synthesis's own deformation (:class:`facemime.animate.deform.Deformer`), so
its **morph target** (the (N, 3) vertex displacement field, z = 0) is ``Deformer.weights @
pattern`` and a performance played from weights is drawn by exactly the deformation that draws
it from knots. ``eyeBlinkRight``/``eyeBlinkLeft`` are the look's lid closure
(:func:`facemime.animate.eyes.close_lids` at closure 1), not knots.

Names are ARKit's blendshape names; left and right are the **subject's own** (the model's x axis
points to the subject's left; ``brow_left_*`` is the subject's left brow, image-right in a
frontal view). A pattern is scale-free: mouth knots move in units of the mouth's width (corner
to corner), brow knots in units of their brow's length (:meth:`Deformer.feature_sizes`), so one
set of weights means the same expression on any actor. Positions along a curve come from the
model's groups (the lip curves' 11 knots from the subject's right corner, s = -1, to the left
one, s = +1; the brows' knots from the inner end, t = 0, to the outer, t = 1), not from an
actor's shape. The magnitude at weight 1 of each control is in :data:`MAGNITUDES`.

Weights are solved per frame from the tracked knot offsets (:meth:`Expressions.solve`):
bounded least squares in [0, 1] with a small pull towards the previous frame's weights.

In a ``facemime.track/1`` file a frame's ``weights`` is an object name -> weight (0..1; names
left out are 0; ``facemime run`` writes the non-zero ones, 4 decimals). A frame with
``weights`` and no ``offsets`` is played from its weights (its ``look``'s lid closures then come
from ``eyeBlinkRight``/``eyeBlinkLeft`` unless the look gives them), so a performance can be
written by hand, e.g. ``{"index": 0, "pose": {...}, "weights": {"jawOpen": 0.6,
"mouthSmileLeft": 0.3}}``; without a ``model`` block the generic head's knots are assumed.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from facemime.animate.box_solver import BoxLeastSquares, box_qp_sequence
from facemime.animate.deform import Deformer
from facemime.animate.eyes import close_lids
from facemime.errors import InvalidInputError
from facemime.shared_constants import EYES
from facemime.types.head import HeadModel

#: The controls, in the order of every weight vector.
NAMES: tuple[str, ...] = (
    "jawOpen",
    "mouthClose",
    "mouthFunnel",
    "mouthPucker",
    "mouthLeft",
    "mouthRight",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthFrownLeft",
    "mouthFrownRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "mouthUpperUpLeft",
    "mouthUpperUpRight",
    "mouthLowerDownLeft",
    "mouthLowerDownRight",
    "mouthRollUpper",
    "mouthRollLower",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "browDownLeft",
    "browDownRight",
    "eyeBlinkLeft",
    "eyeBlinkRight",
    "jawLeft",
    "jawRight",
)
BLINKS = ("eyeBlinkRight", "eyeBlinkLeft")  # in the order of Look.closure (right eye first)

#: What each control does at weight 1: mouth knots in mouth widths, brow knots in brow lengths.
#: Measured, not tuned per video: over all 3,101 frames of the ten shared videos (their tracked
#: offsets, each in its own face's feature sizes), the 99th percentile of the amplitude along
#: each pattern alone (its least-squares projection, a negative one counted as 0), the left and
#: right controls' averaged, rounded (benchmarks/expressions.py --calibrate prints it). Large
#: values are real: lp_d12 and lp_d6 open the mouth wide, and head turns measured a little off
#: move the mouth sideways in the head's frame.
MAGNITUDES: dict[str, float] = {
    "jawOpen": 0.70,
    "mouthClose": 0.04,
    "mouthFunnel": 0.27,
    "mouthPucker": 0.22,
    "mouthLeft": 0.36,
    "mouthRight": 0.36,
    "mouthSmileLeft": 0.29,
    "mouthSmileRight": 0.29,
    "mouthFrownLeft": 0.70,
    "mouthFrownRight": 0.70,
    "mouthStretchLeft": 0.51,
    "mouthStretchRight": 0.51,
    "mouthUpperUpLeft": 0.23,
    "mouthUpperUpRight": 0.23,
    "mouthLowerDownLeft": 0.79,
    "mouthLowerDownRight": 0.79,
    "mouthRollUpper": 0.35,
    "mouthRollLower": 0.25,
    "browInnerUp": 0.39,
    "browOuterUpLeft": 0.43,
    "browOuterUpRight": 0.43,
    "browDownLeft": 0.33,
    "browDownRight": 0.33,
    "eyeBlinkLeft": 1.0,
    "eyeBlinkRight": 1.0,
    "jawLeft": 0.22,
    "jawRight": 0.22,
}
DESCRIPTIONS: dict[str, str] = {
    "jawOpen": "the jaw opens: the lower lip down (its middle the most, the corners 0.3 of it), the chin follows",
    "mouthClose": "the inner lips move towards each other (their middles, (1 - s²)²), the outer lips stay",
    "mouthFunnel": "the lips part round: inner lips apart, outer lips half that, the corners drawn in",
    "mouthPucker": "the mouth narrows towards its middle (each knot in proportion to its distance from it), "
    "the outer lips part by 0.2 (1 - s²)²",
    "mouthLeft": "the whole mouth moves to the subject's left",
    "mouthRight": "the whole mouth moves to the subject's right",
    "mouthSmileLeft": "the subject's left corner up and out (2:1), the lips beside it follow",
    "mouthSmileRight": "the subject's right corner up and out (2:1), the lips beside it follow",
    "mouthFrownLeft": "the subject's left corner down, the lips beside it follow",
    "mouthFrownRight": "the subject's right corner down, the lips beside it follow",
    "mouthStretchLeft": "the mouth's left half stretches out to the subject's left, the corner a little down (0.3)",
    "mouthStretchRight": "the mouth's right half stretches out to the subject's right, the corner a little down (0.3)",
    "mouthUpperUpLeft": "the upper lip's left half rises",
    "mouthUpperUpRight": "the upper lip's right half rises",
    "mouthLowerDownLeft": "the lower lip's left half goes down (the jaw stays)",
    "mouthLowerDownRight": "the lower lip's right half goes down (the jaw stays)",
    "mouthRollUpper": "the upper lip rolls in: its outer edge down",
    "mouthRollLower": "the lower lip rolls in: its outer edge up",
    "browInnerUp": "both brows' inner ends rise (the outer ends stay)",
    "browOuterUpLeft": "the subject's left brow's outer end rises",
    "browOuterUpRight": "the subject's right brow's outer end rises",
    "browDownLeft": "the subject's left brow lowers (its inner end the most) and draws in",
    "browDownRight": "the subject's right brow lowers (its inner end the most) and draws in",
    "eyeBlinkLeft": "the subject's left upper lid down onto the lower lid (look closure 1)",
    "eyeBlinkRight": "the subject's right upper lid down onto the lower lid (look closure 1)",
    "jawLeft": "the jaw moves to the subject's left: the lower lip sideways (the corners half of it)",
    "jawRight": "the jaw moves to the subject's right: the lower lip sideways (the corners half of it)",
}
#: Pull towards the previous frame's weights in :meth:`Expressions.solve`, a fraction of the
#: mean squared pattern norm. On the shared videos it changes the coverage by < 0.0003 IOD (0 ->
#: 0.02); on smoothly changing known weights the offsets rebuilt stay within 0.0007 IOD (mean),
#: though weights along nearly collinear patterns are then shared differently.
SMOOTH = 0.02


def _side(s: np.ndarray, sign: float) -> np.ndarray:
    """Share (0..1) of a knot at ``s`` (-1..1 along the lip) that belongs to the subject's left
    half (``sign`` +1) or right (-1): 0.5 in the middle, 1 (0) from 0.15 on its side (the other);
    the lips' knots are 0.2 apart."""
    return np.clip(0.5 + sign * s / 0.3, 0.0, 1.0)


def unit_patterns(model: HeadModel, deformer: Deformer | None = None) -> np.ndarray:
    """The controls' knot patterns at weight 1, before :meth:`Deformer.feature_sizes` scales them.

    Parameters
    ----------
    model
        The head model (the generic head or an actor's, which has its groups).
    deformer
        ``model``'s :class:`Deformer`, whose knots the patterns are of; None: one is made.

    Returns
    -------
    (E, K, 2) float64 array
        Knot (x, y) offsets per control in the order of :data:`NAMES`, in units of each knot's
        feature size (mouth width, brow length); the blinks' rows are zero.
    """
    d = deformer or Deformer(model)
    g, v = model.groups, model.vertices
    slot = {int(k): i for i, k in enumerate(d.knots)}
    k = len(d.knots)
    s = np.zeros(k)  # position along the lips, -1 (subject's right corner) .. 1
    role = {n: np.zeros(k, bool) for n in ("ou", "ol", "iu", "il", "mouth", "brow_l", "brow_r")}
    t = np.zeros(k)  # position along a brow, 0 inner .. 1 outer
    for name, key in (
        ("mouth_outer_upper", "ou"),
        ("mouth_outer_lower", "ol"),
        ("mouth_inner_upper", "iu"),
        ("mouth_inner_lower", "il"),
    ):
        idx = [slot[int(i)] for i in g[name]]
        pos = np.linspace(-1.0, 1.0, len(idx))
        if v[g[name][-1], 0] < v[g[name][0], 0]:
            pos = pos[::-1]
        s[idx] = pos
        role[key][idx[1:-1]] = True  # the corners are neither upper nor lower
        role["mouth"][idx] = True
    for name in g:
        if name.startswith("brow_") and name.split("_")[1] in ("left", "right"):
            idx = [slot[int(i)] for i in g[name]]
            pos = np.linspace(0.0, 1.0, len(idx))
            if abs(v[g[name][0], 0]) > abs(v[g[name][-1], 0]):
                pos = pos[::-1]
            t[idx] = pos
            role["brow_l" if "_left_" in name else "brow_r"][idx] = True
    corner = role["mouth"] & (np.abs(s) > 0.999)
    upper, lower = role["ou"] | role["iu"], role["ol"] | role["il"]
    bump = 1.0 - s**2
    out = {n: np.zeros((k, 2)) for n in NAMES}
    out["jawOpen"][lower, 1] = -(0.3 + 0.7 * bump[lower])
    out["jawOpen"][corner, 1] = -0.3
    out["mouthClose"][role["iu"], 1] = -(bump[role["iu"]] ** 2)  # narrower than the lip raises: not their sum
    out["mouthClose"][role["il"], 1] = bump[role["il"]] ** 2
    for key, dy in (("iu", 1.0), ("il", -1.0), ("ou", 0.5), ("ol", -0.5)):
        out["mouthFunnel"][role[key], 1] = dy * bump[role[key]]
    out["mouthFunnel"][role["mouth"], 0] = -0.3 * s[role["mouth"]] ** 3
    out["mouthPucker"][role["mouth"], 0] = -s[role["mouth"]]
    out["mouthPucker"][role["ou"], 1] = 0.2 * bump[role["ou"]] ** 2  # pushed out, the lips show fuller
    out["mouthPucker"][role["ol"], 1] = -0.2 * bump[role["ol"]] ** 2
    out["mouthLeft"][role["mouth"], 0] = 1.0
    out["mouthRight"][role["mouth"], 0] = -1.0
    m = role["mouth"]
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        near = np.where(m, np.clip(sign * s, 0.0, 1.0) ** 2, 0.0)  # 1 at this side's corner, 0 from the middle
        half = np.where(m, _side(s, sign), 0.0)
        out[f"mouthSmile{side}"][:, 0] = 0.5 * sign * near
        out[f"mouthSmile{side}"][:, 1] = near
        out[f"mouthFrown{side}"][:, 1] = -near
        out[f"mouthStretch{side}"][:, 0] = np.where(m, sign * np.clip(sign * s, 0.0, 1.0), 0.0)
        out[f"mouthStretch{side}"][:, 1] = -0.3 * near
        out[f"mouthUpperUp{side}"][upper, 1] = (bump * half)[upper]
        out[f"mouthLowerDown{side}"][lower, 1] = -(bump * half)[lower]
        brow = role["brow_l" if side == "Left" else "brow_r"]
        out[f"browOuterUp{side}"][brow, 1] = t[brow]
        out[f"browDown{side}"][brow, 1] = -(1.0 - 0.5 * t[brow])
        out[f"browDown{side}"][brow, 0] = -sign * 0.3 * (1.0 - t[brow])  # towards the middle
        out[f"jaw{side}"][lower, 0] = sign
        out[f"jaw{side}"][corner, 0] = 0.5 * sign
    out["mouthRollUpper"][role["ou"], 1] = -bump[role["ou"]]
    out["mouthRollLower"][role["ol"], 1] = bump[role["ol"]]
    brows = role["brow_l"] | role["brow_r"]
    out["browInnerUp"][brows, 1] = 1.0 - t[brows]
    return np.stack([out[n] * MAGNITUDES[n] if n not in BLINKS else out[n] for n in NAMES])


@functools.cache
def generic_unit_patterns() -> np.ndarray:
    """:func:`unit_patterns` of the generic head: the patterns of any actor fitted from it, times
    its feature sizes.

    Returns
    -------
    (E, K, 2) float64 array
        Read-only, computed once.
    """
    from facemime.head import generic_head

    return _frozen(unit_patterns(generic_head()))


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class Expressions:
    """The controls of one head model: ``patterns`` (E, K, 2) knot offsets at weight 1 and
    ``fields`` (E, N, 3) vertex displacements at weight 1 (morph targets), model units, in the
    order of ``names`` (:data:`NAMES`)."""

    names: tuple[str, ...]
    patterns: np.ndarray
    fields: np.ndarray
    deformer: Deformer = field(repr=False)

    @classmethod
    def of(cls, model: HeadModel) -> Expressions:
        """The controls of a head model.

        Parameters
        ----------
        model
            The generic head or an actor's model (which has its groups).

        Returns
        -------
        Expressions
            Its patterns and fields, model units, read-only.
        """
        d = Deformer(model)
        patterns = unit_patterns(model, d) * d.feature_sizes()[None, :, None]
        fields = np.zeros((len(NAMES), len(model.vertices), 3))
        fields[:, :, :2] = np.einsum("nk,ekc->enc", d.weights, patterns)
        rings = [model.groups[e] for e in EYES]  # right eye first, as Look.closure
        for eye, name in enumerate(BLINKS):
            closure = np.zeros(2)
            closure[eye] = 1.0
            fields[NAMES.index(name)] = close_lids(model.vertices, rings, closure) - model.vertices
        return cls(NAMES, _frozen(patterns), _frozen(fields), d)

    @property
    def _knot_rows(self) -> np.ndarray:
        return np.array([n not in BLINKS for n in self.names])

    def offsets(self, weights: np.ndarray) -> np.ndarray:
        """The knot offsets of expression weights.

        Parameters
        ----------
        weights
            (T, E) or (E,) float array: weights in the order of ``names``.

        Returns
        -------
        (T, K, 2) or (K, 2) float64 array
            Knot (x, y) offsets, model units.
        """
        w = np.asarray(weights, np.float64)
        return np.tensordot(w, self.patterns, axes=([-1], [0]))

    def closure(self, weights: np.ndarray) -> np.ndarray:
        """The lid closures of expression weights.

        Parameters
        ----------
        weights
            (T, E) or (E,) float array: weights in the order of ``names``.

        Returns
        -------
        (T, 2) or (2,) float64 array
            The blinks' weights: right eye, left eye, as ``Look.closure``.
        """
        w = np.asarray(weights, np.float64)
        return np.stack([w[..., self.names.index(n)] for n in BLINKS], axis=-1)

    def vertices(self, weights: np.ndarray) -> np.ndarray:
        """The model's vertices with one frame's weights applied to the fields (the morph; the lips
        are not sealed as :class:`~facemime.animate.synth.Puppet` does).

        Parameters
        ----------
        weights
            (E,) float array: weights in the order of ``names``.

        Returns
        -------
        (N, 3) float64 array
            The morphed vertices, model units.
        """
        return self.deformer.model.vertices + np.tensordot(np.asarray(weights, np.float64), self.fields, axes=1)

    def solver(self, smooth: float = SMOOTH) -> FrameSolver:
        """A solver that takes one frame at a time, as :meth:`solve` does all at once.

        Parameters
        ----------
        smooth
            Pull towards the previous frame's weights, a fraction of the mean squared pattern norm.

        Returns
        -------
        FrameSolver
            The solver, at its first frame.
        """
        return FrameSolver(self, smooth)

    def _system(self, smooth: float) -> tuple[np.ndarray, np.ndarray, float]:
        """(the knot controls' patterns as columns (2K, E'), their Gram matrix, λ) for ``smooth``."""
        rows = self._knot_rows
        a = self.patterns[rows].reshape(rows.sum(), -1).T
        gram = a.T @ a
        return a, gram, smooth * float(np.mean(np.diag(gram)))

    def solve(self, offsets: np.ndarray, closure: np.ndarray | None = None, smooth: float = SMOOTH) -> np.ndarray:
        """The weights of a sequence of knot offsets and lid closures.

        Per frame the bounded least squares fit of the offsets by the patterns, with ``smooth``
        times the squared distance to the previous frame's weights added. The blinks are the
        closures clipped to [0, 1] (a lid opened wider than on the key frame is 0).

        Parameters
        ----------
        offsets
            (T, K, 2) float array: each frame's knot (x, y) offsets, model units (of this model).
        closure
            (T, 2) float array: each frame's lid closures (right eye, left eye); None: open.
        smooth
            Pull towards the previous frame's weights, a fraction of the mean squared pattern norm.

        Returns
        -------
        (T, E) float64 array
            Weights in [0, 1], in the order of ``names``.
        """
        o = np.asarray(offsets, np.float64)
        if o.ndim != 3 or o.shape[1:] != self.patterns.shape[1:]:
            raise InvalidInputError(f"offsets must have shape (T, {self.patterns.shape[1]}, 2), got {o.shape}")
        rows = self._knot_rows
        a, gram, lam = self._system(smooth)
        out = np.zeros((len(o), len(self.names)))
        out[:, rows] = box_qp_sequence(gram, o.reshape(len(o), -1) @ a, lam)
        if closure is not None:
            c = np.asarray(closure, np.float64)
            if c.shape != (len(o), 2):
                raise InvalidInputError(f"closure must have shape ({len(o)}, 2), got {c.shape}")
            for eye, name in enumerate(BLINKS):
                out[:, self.names.index(name)] = np.clip(c[:, eye], 0.0, 1.0)
        return out


class FrameSolver:
    """:meth:`Expressions.solve` one frame at a time (``facemime run`` writes weights as it goes).

    Parameters
    ----------
    expressions
        The controls whose weights are solved.
    smooth
        Pull towards the previous frame's weights, a fraction of the mean squared pattern norm.
    """

    def __init__(self, expressions: Expressions, smooth: float = SMOOTH):
        self.expressions = expressions
        # The same module's helper class: it shares Expressions' internals on purpose.
        self._rows = expressions._knot_rows  # noqa: SLF001
        self._a, gram, lam = expressions._system(smooth)  # noqa: SLF001
        self._qp = BoxLeastSquares(gram, lam)

    def step(self, offsets: np.ndarray, closure: np.ndarray | None = None) -> np.ndarray:
        """The weights of the next frame.

        Parameters
        ----------
        offsets
            (K, 2) float array: the frame's knot (x, y) offsets, model units.
        closure
            (2,) float array: the frame's lid closures (right eye, left eye); None: the blinks 0.

        Returns
        -------
        (E,) float64 array
            Weights in [0, 1], in the order of the controls' ``names``.
        """
        out = np.zeros(len(self.expressions.names))
        out[self._rows] = self._qp.step(np.asarray(offsets, np.float64).reshape(-1) @ self._a)
        if closure is not None:
            for eye, name in enumerate(BLINKS):
                out[self.expressions.names.index(name)] = np.clip(float(closure[eye]), 0.0, 1.0)
        return out


def named_weights(names: tuple[str, ...], weights: np.ndarray) -> dict[str, float]:
    """Weights as a track file's name -> weight object.

    Parameters
    ----------
    names
        The weights' names, in order.
    weights
        (E,) float array: the weights, 0..1.

    Returns
    -------
    dict of str to float
        Name -> weight rounded to 4 decimals, the weights that round to 0 left out.
    """
    return {n: round(float(x), 4) for n, x in zip(names, weights) if round(float(x), 4) != 0.0}
