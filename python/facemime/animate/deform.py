"""Local deformation: the tracked mouth and brow contours, taken into the head's own frame, move
their model vertices (the knots), and every other vertex follows smoothly (docs/method.md §3).

Knot offsets are (x, y) displacements in model units (millimetres for the built-in head) in the
head's own frame — with the head's rotation, scale and translation taken out — relative to the
first frame. Depth (z) is left as it is.

The spread is Shepard interpolation with weights 1 / (d² + ε²) over model-space distances d:
vertices above the eyes follow the brow knots, vertices between the eyes and the mouth line the
upper-lip knots, vertices below the mouth line the lower-lip knots (so an opening mouth pulls the
chin down and the cheeks little). The eyes, the nose and the face outline above the mouth line
are anchors that do not move, and a constant far-field anchor (weight 1 / :data:`REACH`²) keeps
distant vertices still.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facemime.errors import InvalidInputError
from facemime.metrics import resample
from facemime.shared_constants import CONTOUR_GROUPS, REACH, SOFTEN
from facemime.types.head import HeadModel, model_iod, mouth_capped, mouth_up, mouth_width
from facemime.types.pose import Pose, head_plane

UPPER = ("mouth_outer_upper", "mouth_inner_upper")
LOWER = ("mouth_outer_lower", "mouth_inner_lower")
BROWS = tuple(n for n in CONTOUR_GROUPS if n.startswith("brow"))


class Deformer:
    """Drives one head model by the eight tracked contours.

    ``knots`` (K,) are the model's contour vertices' indices (the mouth corners shared by the
    upper and lower curves counted once), in ascending order; ``weights`` (N, K) spreads their
    offsets to all N vertices.

    Parameters
    ----------
    model
        The head model, with the eight contour groups and ``eye_left`` and ``eye_right`` (raises
        :class:`~facemime.errors.InvalidInputError` when it lacks one).
    """

    def __init__(self, model: HeadModel):
        missing = [g for g in CONTOUR_GROUPS + ("eye_left", "eye_right") if g not in model.groups]
        if missing:
            raise InvalidInputError(f"head model {model.name!r} lacks the contour groups {', '.join(missing)}")
        self.model = model
        g = model.groups
        self.knots = np.unique(np.concatenate([g[n] for n in CONTOUR_GROUPS]))
        self._slot = {int(v): k for k, v in enumerate(self.knots)}
        # every contour's vertices in CONTOUR_GROUPS order, their knot slots and how often each knot appears
        self._members = np.concatenate([g[n] for n in CONTOUR_GROUPS])
        self._member_slots = np.array([self._slot[int(i)] for i in self._members])
        self._member_counts = np.bincount(self._member_slots, minlength=len(self.knots)).astype(np.float64)
        # the inner lips' knots between the corners, and their slots (see sealed)
        self._inner = (g["mouth_inner_upper"][1:-1], g["mouth_inner_lower"][1:-1])
        self._inner_slots = tuple(np.array([self._slot[int(i)] for i in idx], np.int64) for idx in self._inner)
        self._capped = mouth_capped(model)  # see sealed
        self._rest: dict[float, np.ndarray | None] = {}  # per share closed, the model's own _closing
        self.weights = self._spread()

    def _spread(self) -> np.ndarray:
        model, g = self.model, self.model.groups
        v = model.vertices
        iod = model_iod(model)
        eye_y = v[np.concatenate([g["eye_left"], g["eye_right"]]), 1].mean()
        mouth_y = v[g["mouth_outer_upper"][[0, -1]], 1].mean()
        sets = {
            name: np.array([self._slot[int(i)] for i in np.unique(np.concatenate([g[n] for n in names]))])
            for name, names in (("upper", UPPER), ("lower", LOWER), ("brows", BROWS))
        }
        anchors = [g[n] for n in ("eye_left", "eye_right", "nose") if n in g]
        if "face_outline" in g:
            anchors.append(g["face_outline"][v[g["face_outline"], 1] > mouth_y])
        anchor_idx = np.setdiff1d(np.concatenate(anchors), self.knots)
        soft2, far = (SOFTEN * iod) ** 2, 1.0 / (REACH * iod) ** 2
        weights = np.zeros((len(v), len(self.knots)))
        for j in range(len(v)):
            if j in self._slot:
                weights[j, self._slot[j]] = 1.0
                continue
            y = v[j, 1]
            chosen = sets["brows"] if y > eye_y else sets["upper"] if y >= mouth_y else sets["lower"]
            w = 1.0 / (np.sum((v[self.knots[chosen]] - v[j]) ** 2, axis=1) + soft2)
            a = anchor_idx[anchor_idx != j]
            rest = np.sum(1.0 / (np.sum((v[a] - v[j]) ** 2, axis=1) + soft2)) + far
            weights[j, chosen] = w / (w.sum() + rest)
        return weights

    def knot_positions(self, contours: Mapping[str, np.ndarray], pose: Pose) -> np.ndarray:
        """The knots' model-space (x, y) where the image contours put them, seen in a pose.

        Parameters
        ----------
        contours
            Name -> (M, 2) float array of (x, y) pixels for each of the eight contours (resampled to
            its model group's length where M differs; either direction along the curve).
        pose
            The head pose the contours are seen in; each point is taken at its knot's model depth.

        Returns
        -------
        (K, 2) float64 array
            Each knot's model (x, y), model units; a knot on two curves (a mouth corner) averaged.
        """
        g, v = self.model.groups, self.model.vertices
        points = []
        for name in CONTOUR_GROUPS:
            idx = g[name]
            c = np.asarray(contours[name], np.float64)
            c = c if len(c) == len(idx) else resample(c, len(idx))
            if (c[-1, 0] - c[0, 0]) * (v[idx[-1], 0] - v[idx[0], 0]) < 0:
                c = c[::-1]  # the model's groups run image-left to image-right in a frontal view
            points.append(c)
        # one inverse projection for all points; knots on two curves (the mouth corners) average
        plane = head_plane(np.concatenate(points), v[self._members, 2], pose)
        pts = np.zeros((len(self.knots), 2))
        np.add.at(pts, self._member_slots, plane)
        return pts / self._member_counts[:, None]

    def vertices(self, offsets: np.ndarray, gain: float = 1.0) -> np.ndarray:
        """The model's vertices moved by knot offsets, spread by :attr:`weights`.

        Parameters
        ----------
        offsets
            (K, 2) float array: each knot's (x, y) offset, model units.
        gain
            Factor on the offsets (the exaggeration).

        Returns
        -------
        (N, 3) float64 array
            The moved vertices, model units; z as the model's.
        """
        out = self.model.vertices.copy()
        out[:, :2] += gain * (self.weights @ offsets)
        return out

    def sealed(self, vertices: np.ndarray, closed: float) -> np.ndarray:
        """The vertices with the lips shut where the inner lips lie closer than a share of the
        mouth's width.

        The gap between the inner lips is measured across the corner line; above ``closed`` times
        the mouth's width it opens from nothing to its full size at twice that, so the opening
        never jumps. The inner-lip knots meet halfway and the other vertices follow them like
        offsets (:meth:`vertices`). On a model whose mouth is capped (fitted open:
        :func:`facemime.fit.actor.mouth_cap`, its texture showing the opening), what this does to
        the model's own vertices is taken back, so that the key frame's mouth is drawn as it was
        fitted: the corners, where the open lips come near, are not pulled shut (on ``st_aoc``'s
        key frame that misplaced the teeth: 25.6 dB in the mouth, 39.3 without). An uncapped
        mouth is sealed as it is: its lips' fitted gap would show the drawn cavity.

        Parameters
        ----------
        vertices
            (N, 3) float array: the model's vertices as deformed, model units.
        closed
            The gap below which the lips shut, a share of the mouth's width (corner to corner).

        Returns
        -------
        (N, 3) float64 array
            A sealed copy; ``vertices`` itself where the inner lips' knot counts differ or the
            mouth has no width.
        """
        close = self._closing(vertices, closed)
        if close is None:
            return vertices
        rest = None
        if self._capped:
            if closed not in self._rest:
                self._rest[closed] = self._closing(self.model.vertices, closed)
            rest = self._rest[closed]
        out = vertices.copy()
        out[:, :2] += self.weights @ (close if rest is None else close - rest)
        return out

    def _closing(self, vertices: np.ndarray, closed: float) -> np.ndarray | None:
        """The (K, 2) knot moves that shut the lips of ``vertices`` as :meth:`sealed` says, model
        units; None where the inner lips' knot counts differ or the mouth has no width."""
        upper, lower = self._inner
        up = mouth_up(self.model, vertices)
        if len(upper) != len(lower) or up is None:
            return None
        gap = (vertices[upper, :2] - vertices[lower, :2]) @ up
        limit = closed * mouth_width(self.model, vertices)
        shown = np.where(gap < limit, 0.0, np.where(gap < 2.0 * limit, 2.0 * (gap - limit), gap))
        close = np.zeros((len(self.knots), 2))
        half = 0.5 * (gap - shown)[:, None] * up
        close[self._inner_slots[0]] = -half
        close[self._inner_slots[1]] = half
        return close

    def feature_sizes(self) -> np.ndarray:
        """Per knot, the width of its feature: the scale motion is measured in when it is carried
        from one actor to another.

        Returns
        -------
        (K,) float64 array
            The mouth's corner-to-corner distance for mouth knots, the brow's length (end to end,
            in (x, y)) for brow knots, model units.
        """
        g, v = self.model.groups, self.model.vertices
        sizes = np.zeros(len(self.knots))
        for name in CONTOUR_GROUPS:
            idx = g[name]
            size = (
                mouth_width(self.model, v) if name.startswith("mouth") else np.hypot(*(v[idx[-1], :2] - v[idx[0], :2]))
            )
            sizes[[self._slot[int(i)] for i in idx]] = size
        return sizes
