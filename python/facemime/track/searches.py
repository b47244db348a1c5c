"""The tracker's wider searches, run when the snakes alone lose a feature: a brow matched
again (:mod:`facemime.track.brows`), the mouth moved sideways with its region
(:mod:`facemime.track.mouth`), a lost inner mouth tried up and down the face, a lost mouth
looked for by its lip colour. Methods of :class:`facemime.track.tracker.Tracker`, kept here so
that the frame's main path reads alone; (x, y) pixels, y down."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from facemime.track import motion
from facemime.track.brows import BrowSearch
from facemime.track.lips import LipSearch
from facemime.track.mouth import mouth_shift, relocate
from facemime.track.params import AGREE
from facemime.types import similarity
from facemime.types.contours import FEATURES

if TYPE_CHECKING:
    from collections.abc import Callable

    from facemime.track.params import TrackerParams


class Searches:
    """The searches (mixed into :class:`~facemime.track.tracker.Tracker`, which defines what
    they use: declared here for the type checker)."""

    if TYPE_CHECKING:
        params: TrackerParams
        _prev: np.ndarray
        _knots: np.ndarray
        _knots0: np.ndarray
        _index: dict[str, np.ndarray]
        _features: dict[str, np.ndarray]
        _feature_curves: dict[str, np.ndarray]
        _mouth_curves: np.ndarray
        _mouth_knots: np.ndarray
        _mouth_lost_for: int

        # The tracker's own steps (signatures in tracker.py).
        _field: Callable[..., tuple[np.ndarray, tuple[float, float]]]
        _solve: Callable[..., tuple[np.ndarray, int, np.ndarray]]
        _confidences: Callable[[np.ndarray], dict[str, float]]
        _centre_inner: Callable[[np.ndarray, np.ndarray, np.ndarray], None]
        _mouth_rest: Callable[[np.ndarray, np.ndarray], np.ndarray]
        _shape_ok: Callable[[np.ndarray, np.ndarray, str], bool]
        _named: Callable[[np.ndarray], dict[str, np.ndarray]]

    def _search_brow(
        self,
        frame: np.ndarray,
        feature: str,
        search: BrowSearch,
        knots: np.ndarray,
        start: np.ndarray,
        rest: np.ndarray,
        down: np.ndarray,
        targets: np.ndarray,
        carried: np.ndarray,
        scale: float,
        conf: float,
        shape_ok: bool,
    ) -> tuple[float, bool, np.ndarray, int]:
        """Look for a brow whose edge or shape was lost (``brow_search``) around where the head
        motion put it (``start``): when the match moves its knots at least :data:`AGREE` solver
        reaches, the brow is settled there by a solver pass and kept (in ``knots``, in place)
        when its confidence rose or its shape (``shape_ok`` against ``carried``) was unsound.
        Returns the brow's confidence and shape check then, where it goes should it be lost (the
        match, else ``carried``), and the solver's iterations."""
        p, idx = self.params, self._features[feature]
        found = search.find(frame, scale, start[idx])
        fallback, iters = carried, 0
        if found is not None:
            fallback = knots.copy()
            fallback[idx] = found
            if np.abs(found - knots[idx]).max() >= AGREE * p.reach:
                again, iters, again_resp = self._solve(
                    self._field(frame, fallback, ((idx, 1),)),
                    fallback,
                    rest,
                    down,
                    targets,
                    self._feature_curves[feature],
                )
                conf_again = self._confidences(again_resp)[feature]
                if conf_again > conf or not shape_ok:
                    knots[idx], conf = again[idx], conf_again
                    shape_ok = self._shape_ok(knots, carried, feature)
        return conf, shape_ok, fallback, iters

    def _mouth_sideways(
        self,
        frame: np.ndarray,
        start: np.ndarray,
        followed: np.ndarray,
        step: np.ndarray,
        down: np.ndarray,
        reach: float,
    ) -> None:
        """Move the mouth knots the flow lost (``followed`` False) along the mouth line by how far
        the previous frame's mouth region moved that way beyond the head's ``step``, when that is
        at least :data:`AGREE` × ``reach`` px (in place; the mouth's motion up and down, an
        opening, is the lip searches' to follow)."""
        mouth = self._mouth_knots
        shift = mouth_shift(self._prev, frame, self._knots[mouth], similarity.apply(step, self._knots[mouth]))
        if shift is None:
            return
        along = np.array([down[1], -down[0]])
        sideways = float(shift @ along)
        if abs(sideways) >= AGREE * reach:
            start[mouth[~followed[mouth]]] += sideways * along

    def _search_inner(
        self,
        frame: np.ndarray,
        knots: np.ndarray,
        rest: np.ndarray,
        down: np.ndarray,
        targets: np.ndarray,
        carried: np.ndarray,
        conf: float,
    ) -> tuple[float | None, int]:
        """Look for a lost inner mouth (``inner_search``): each inner curve in turn, upper first, is
        moved along ``down`` by ±1 to ±``inner_search`` solver reaches and the inner mouth settled
        from there by a solver pass in which the outer mouth stays; the placement that gives the
        inner mouth the highest confidence (``conf``: its confidence now) is kept when higher than
        before. The inner knots are replaced (in place) when the inner mouth then
        holds its edges (confidence at least ``lost_response``, shape sound against
        ``carried``). Returns its confidence then, else None; and the solver's iterations."""
        p = self.params
        reach = p.reach
        inner = self._features["mouth_inner"]
        # One field for every trial: a trial moves a knot at most inner_search reaches and its
        # pass one more.
        image = self._field(frame, knots, ((self._mouth_knots, p.inner_search + 1),))
        held = np.ones(len(knots), bool)
        held[inner] = False
        placed, best, iters = knots.copy(), conf, 0
        for name in FEATURES["mouth_inner"]:
            idx, found = self._index[name][1:-1], None
            for steps in range(-p.inner_search, p.inner_search + 1):
                if steps == 0:
                    continue
                trial = placed.copy()
                trial[idx] += steps * reach * down
                settled, more, resp = self._solve(image, trial, rest, down, targets, self._mouth_curves, held)
                iters += more
                if (trial_conf := self._confidences(resp)["mouth_inner"]) > best:
                    found, best = settled[inner], trial_conf
            if found is not None:
                placed[inner] = found
        if best >= p.lost_response and self._shape_ok(placed, carried, "mouth_inner"):
            knots[inner] = placed[inner]
            return best, iters
        return None, iters

    def _relocate_mouth(
        self,
        frame: np.ndarray,
        lips: LipSearch,
        knots: np.ndarray,
        carried: np.ndarray,
        down: np.ndarray,
        targets: np.ndarray,
    ) -> tuple[dict[str, float] | None, int]:
        """Look for the mouth, lost for ``mouth_relocate`` frames, where its lip colour (``lips``'s) is found
        near where the brows put the first frame's mouth, in that mouth's shape, and let one
        solver pass (the frame's ``down`` and gap ``targets``) settle it there. The settled mouth
        replaces the mouth knots (in place) only when it is no longer lost: confidences at least
        ``lost_response``, shapes sound against the rest knots ``carried``. Returns then the
        mouth features' confidences, else None; and the solver's iterations."""
        expected = similarity.apply(motion.brow_similarity(self._named(self._knots0), self._named(knots)), self._knots0)
        upper, lower = self._index["mouth_outer_upper"], self._index["mouth_outer_lower"]
        outer = lambda k: np.concatenate([k[upper], k[lower][::-1]])  # noqa: E731
        polygon = outer(expected)
        if lips.colour is None:  # no lip colour to look for (then the search is not active either)
            return None, 0
        found = relocate(frame, lips.colour, polygon, outer(knots), down)
        if found is None:
            return None, 0
        mouth = self._mouth_knots
        placed = knots.copy()
        placed[mouth] = found.apply(expected[mouth], polygon.mean(axis=0))
        rest = self._mouth_rest(carried, placed)
        settled, iters, resp = self._solve(
            self._field(frame, placed, ((mouth, 1),)), placed, rest, down, targets, self._mouth_curves
        )
        self._centre_inner(settled, rest, down)
        features = ("mouth_outer", "mouth_inner")
        confidence = {f: c for f, c in self._confidences(resp).items() if f in features}
        if all(confidence[f] >= self.params.lost_response and self._shape_ok(settled, carried, f) for f in features):
            knots[mouth] = settled[mouth]
            self._mouth_lost_for = 0
            return confidence, iters
        return None, iters
