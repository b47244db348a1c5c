"""The contour tracker: the eight mouth and brow curves of ``facemime.types.contours`` as
STB-snakes over one shared knot array, solved jointly each frame after head-motion
compensation (docs/method.md §1).

Per frame: the head's motion moves the previous knots and the rest shape (where the flow lost the
mouth, the mouth region or the lip colour places it); the solver settles the snakes on the edges;
a feature whose edges collapse is searched for more widely or flagged ``lost`` — the steps in
docs/tracker.md, "One frame, step by step".

Coordinates are (x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facemime import _core, validate
from facemime.errors import InvalidInputError
from facemime.track import motion
from facemime.track.brows import BrowSearch
from facemime.track.field import build_field, regions
from facemime.track.knots import FrameResult, check_contours, layout, rgb_frame
from facemime.track.lips import LipSearch
from facemime.track.params import CENTRING, FAST, NARROWEST, OPERATORS, TrackerParams
from facemime.track.scale import FrameScale, ScaledMotion
from facemime.track.searches import Searches
from facemime.types import similarity
from facemime.types.contours import CONTOUR_NAMES, FEATURES, POLARITY


class Tracker(Searches):
    """Tracks the mouth and brow contours frame by frame; usable on a live camera.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the frame the contours were drawn on; every later frame has its size.
    contours
        Name -> (N, 2) float array: all eight contours of
        ``facemime.types.contours.CONTOUR_NAMES``, (x, y) pixels inside the frame, at least 2
        points each, image-left to image-right; the two curves of each mouth contour share their
        end points (their mean where they differ).
    params
        The tracker's settings; None: the defaults of :class:`TrackerParams`.

    Examples
    --------
    >>> import numpy as np
    >>> from facemime.track.synthetic import band_face
    >>> frame, contours = band_face()
    >>> tracker = Tracker(frame, contours)
    >>> result = tracker.update(band_face(shift=(1.0, 0.5))[0])
    >>> sorted(result.confidence)
    ['brow_left', 'brow_right', 'mouth_inner', 'mouth_outer']
    """

    def __init__(self, frame: np.ndarray, contours: Mapping[str, np.ndarray], params: TrackerParams | None = None):
        self.params = p = params or TrackerParams()
        validate.choice("operator", p.operator, OPERATORS)
        frame = rgb_frame("frame", frame)
        contours = check_contours(contours, frame.shape[1], frame.shape[0])
        self._scale = FrameScale(frame.shape[1], frame.shape[0], motion.face_frame(contours)[3], p.face_width)
        frame = self._scale.frame(frame)
        contours = {n: self._scale.to_work(c) for n, c in contours.items()}
        self.width, self.height = self._scale.work  # px: the frames the snakes see
        self._knots0, self._index = layout(contours, p)
        self._down0 = self._mouth_down(self._knots0)
        self._features = {
            f: np.unique(np.concatenate([self._index[n] for n in names])) for f, names in FEATURES.items()
        }
        self._mouth_knots = np.unique(np.concatenate([self._features["mouth_outer"], self._features["mouth_inner"]]))
        self._affine_groups = [[int(i) for i in self._features[f]] for f in ("mouth_outer", "mouth_inner")]
        # The field's bands: the mouth's knots with its solver passes, each brow's with one (a
        # band apiece, so that where a tilted head puts one brow above the other, the rows of
        # one brow alone are computed only around it).
        self._frame_bands = self._band_args(
            ((self._mouth_knots, p.mouth_passes), (self._features["brow_left"], 1), (self._features["brow_right"], 1))
        )
        self._mouth_uintp = self._mouth_knots.astype(np.uintp)
        self._inner_uintp, self._outer_uintp = (
            self._features[f].astype(np.uintp) for f in ("mouth_inner", "mouth_outer")
        )
        # Each feature's upper curve's end knots and how far its chord may shrink.
        self._chord_ends = np.array(
            [[self._index[up][0], self._index[up][-1]] for up, _ in FEATURES.values()], np.uintp
        )
        # The inner lips' knots pair by pair, corners left out: (upper, lower).
        self._inner_pairs = tuple(self._index[n][1:-1].astype(np.uintp) for n in FEATURES["mouth_inner"])
        self._least_chord = np.array([NARROWEST if up == "mouth_inner_upper" else 0.5 for up, _ in FEATURES.values()])
        # All contours' knots in CONTOUR_NAMES order, and each contour's span of them.
        self._order = np.concatenate([self._index[n] for n in CONTOUR_NAMES])
        ends = np.cumsum([0] + [len(self._index[n]) for n in CONTOUR_NAMES]).tolist()
        self._spans = list(zip(CONTOUR_NAMES, ends[:-1], ends[1:]))
        self._feature_rows = {f: tuple(CONTOUR_NAMES.index(n) for n in names) for f, names in FEATURES.items()}
        # Curve masks of the features solved on their own: the mouth's second pass, a brow found again.
        self._feature_curves = {
            f: np.isin(np.arange(len(CONTOUR_NAMES)), rows) for f, rows in self._feature_rows.items()
        }
        self._mouth_curves = np.array([n.startswith("mouth") for n in CONTOUR_NAMES])
        self._solver, self._targets0 = self._build_solver()
        self._field_buffer = np.empty(0, np.float32)
        self._motion = motion.HeadMotion(frame, contours) if p.motion else None
        if self._motion is not None:
            # The knots of the brow points the head motion takes, in its order.
            self._brow_knots = np.concatenate([self._index[n] for n in self._motion.brows])
        self._prev = frame
        self._mouth_lost_for = 0  # frames in a row with a mouth feature lost
        self.frame_index = 0
        # The snakes settle on the image edges, which may sit a little off the given contours
        # (a landmark convention, not an error): settle them on the first frame, track the edges
        # and report them shifted back by that offset (which turns and scales with the head).
        edges = self._knots0
        for _ in range(p.calibration_passes):
            edges = self._solve(self._field(frame, edges), edges, self._knots0, self._down0, self._targets0)[0]
        self._offset = edges - self._knots0
        self._knots0 = edges
        self._knots = edges.copy()
        self._lips = None
        if p.lip_reach > 0:
            self._lips = LipSearch(frame, contours, self._index, edges, p.lip_reach, p.lip_step)
        self._linear = np.eye(2)
        self._down = self._down0
        self._response0 = np.maximum(self._responses(frame, edges, edges, self._down0, self._targets0), 1e-6)
        self._brow_search = {f: BrowSearch(frame, edges[self._features[f]]) for f in ("brow_left", "brow_right")}
        self._reported = self._reported_knots()
        # The frame's steps around the solver, in the core: the start, the rest shape and gap
        # targets, then the confidences and shape checks.
        self._plan = _core.FramePlan(
            self._knots0,
            tuple(self._down0),
            self._targets0,
            self._response0,
            (self.width - 1.0, self.height - 1.0),
            self._mouth_uintp,
            p.mouth_patch,
            self._affine_groups,
            p.mouth_affine,
            self._inner_uintp,
            self._outer_uintp,
            CENTRING,
            self._chord_ends,
            self._least_chord,
            np.array(list(self._feature_rows.values()), np.uintp),
        )

    def _build_solver(self) -> tuple[_core.SnakeSolver, np.ndarray]:
        p = self.params
        order = list(CONTOUR_NAMES)
        rows = []
        for name in order:
            w = p.mouth_inner if name.startswith("mouth_inner") else p.mouth if name.startswith("mouth") else p.brows
            sl, sc = POLARITY[name]
            rows.append(
                [w.alpha, w.beta, w.tau, w.rho, w.gamma, sl * w.luma, sc * w.chroma, OPERATORS.index(p.operator)]
            )
        pairs, kinds, targets = [], [], []
        k0, down = self._knots0, self._down0

        def add(a_name: str, b_name: str, kind: int, weight: float, fraction: float) -> None:
            ia, ib = self._index[a_name], self._index[b_name]
            inner = slice(1, -1) if a_name.startswith("mouth") else slice(None)
            for a, b in zip(ia[inner], ib[inner]):
                pairs.append((a, b))
                kinds.append((kind, weight))
                targets.append(fraction * float(down @ (k0[b] - k0[a])))

        add("mouth_outer_upper", "mouth_inner_upper", 0, p.gap_weight, p.lip_keep)
        add("mouth_inner_lower", "mouth_outer_lower", 0, p.gap_weight, p.lip_keep)
        add("mouth_inner_upper", "mouth_inner_lower", 0, p.gap_weight, 0.0)
        for side in ("left", "right"):
            add(f"brow_{side}_upper", f"brow_{side}_lower", 1, p.brow_weight, 1.0)
        targets_arr = np.maximum(np.array(targets), 0.0)
        solver = _core.SnakeSolver(
            np.concatenate([self._index[n] for n in order]).astype(np.uint32),
            np.array([len(self._index[n]) for n in order], np.uint32),
            np.array(rows, np.float64),
            np.array(pairs, np.uint32).reshape(-1, 2),
            np.array(kinds, np.float64).reshape(-1, 2),
            p.points_per_segment,
            p.delta0,
            p.sigma,
            p.iterations,
            p.tol,
        )
        return solver, targets_arr

    def _mouth_down(self, knots: np.ndarray) -> np.ndarray:
        """Unit vector perpendicular to the mouth's corner line, pointing down the face."""
        corners = knots[self._index["mouth_outer_upper"][[0, -1]]]
        along = (corners[1] - corners[0]) / max(np.linalg.norm(corners[1] - corners[0]), 1e-9)
        return np.array([-along[1], along[0]])

    def _band_args(self, bands: tuple[tuple[np.ndarray, int], ...]) -> list[tuple[np.ndarray, float]]:
        """(knot indices as np.uintp, margin px) of each of ``bands``, (knot indices, solver
        passes): the margin that so many passes from the knots, each reaching δ0/(1−σ) px, can
        read (and the bilinear cell of a point read); the field's box grows beyond it by the
        smoothing's radius (:func:`facemime.track.field.regions`)."""
        reach = self.params.reach
        return [(np.asarray(idx, np.uintp), passes * reach + 2.0) for idx, passes in bands]

    def _previous(self) -> np.ndarray | None:
        """The previous frame when the temporal brightness term reads it, else None."""
        p = self.params
        return self._prev if max(p.mouth.gamma, p.mouth_inner.gamma, p.brows.gamma) > 0 else None

    def _field(
        self, frame: np.ndarray, knots: np.ndarray, bands: tuple[tuple[np.ndarray, int], ...] | None = None
    ) -> tuple[np.ndarray, tuple[float, float]]:
        """The image field the solver reads around ``knots``: (field, origin of its box). Each of
        ``bands``, (knot indices, solver passes), is the box around those knots that so many
        passes from them can read (default: the mouth's passes and one for the brows). The field
        is valid until the next call (one buffer, reused)."""
        # The snakes read the image only near the knots: around the brows and around the mouth,
        # not the eyes and nose between them.
        band_args = self._band_args(bands) if bands is not None else self._frame_bands
        box, boxes = regions(knots, band_args, self.width, self.height, self.params.smoothing)
        # One buffer reused frame after frame: a fresh megabyte-sized array each frame cost
        # more in page faults than filling it.
        size = (box[3] - box[1]) * (box[2] - box[0]) * _core.FIELD_CHANNELS
        if self._field_buffer.size < size:
            self._field_buffer = np.empty(size + size // 4, np.float32)
        out = self._field_buffer[:size].reshape(box[3] - box[1], box[2] - box[0], _core.FIELD_CHANNELS)
        return build_field(frame, self._previous(), box, self.params.smoothing, boxes, out), (
            float(box[0]),
            float(box[1]),
        )

    def _responses(
        self, frame: np.ndarray, start: np.ndarray, rest: np.ndarray, down: np.ndarray, targets: np.ndarray
    ) -> np.ndarray:
        fld, origin = self._field(frame, start)
        _, resp = self._solver.evaluate(fld, origin, (self.width, self.height), start, rest, tuple(down), targets)
        return resp

    def _solve(
        self,
        field: tuple[np.ndarray, tuple[float, float]],
        start: np.ndarray,
        rest: np.ndarray,
        down: np.ndarray,
        targets: np.ndarray,
        curves: np.ndarray | None = None,
        held: np.ndarray | None = None,
    ) -> tuple[np.ndarray, int, np.ndarray]:
        """One solver pass from ``start`` on ``field`` (:meth:`_field`); with ``curves``, a mask
        over CONTOUR_NAMES, for the features of those curves only (the others stay at ``start``,
        their responses NaN); with ``held``, a mask over the knots, those knots stay at ``start``
        (their curves still read the image and pull on the others through the couplings)."""
        knots, iters, _, resp = self._solver.solve(
            *field, (self.width, self.height), start, rest, tuple(down), targets, curves, held
        )
        return knots, iters, resp

    def _confidences(self, resp: np.ndarray) -> dict[str, float]:
        """Each feature's confidence: the mean of its two curves' edge responses ``resp`` as
        fractions of the first frame's, clipped to 0..1 (``facemime._core.FramePlan``)."""
        return dict(zip(FEATURES, self._plan.confidences(resp)[1]))

    def update(self, frame: np.ndarray) -> FrameResult:
        """Track one more frame.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB, the first frame's size (another size raises
            :class:`facemime.errors.InvalidInputError`): the next frame.

        Returns
        -------
        FrameResult
            The frame's contours, (x, y) pixels of the frame; each feature's confidence, 0..1;
            the features flagged lost; the solver's iterations; whether the head motion was
            measured. ``index`` is the frame's number (the first frame's is 0).
        """
        frame = rgb_frame("frame", frame)
        if frame.shape[1::-1] != self._scale.size:
            width, height = self._scale.size
            raise InvalidInputError(f"frame size changed from {width}x{height} to {frame.shape[1]}x{frame.shape[0]}")
        frame = self._scale.frame(frame)
        p = self.params
        self.frame_index += 1
        step, ok, flow = similarity.IDENTITY, True, None
        if self._motion is not None:
            step, ok, flow = self._motion.update(
                frame, self._reported.take(self._brow_knots, axis=0), self._knots if p.knot_flow else None
            )
        total = self._motion.total if self._motion is not None else similarity.IDENTITY
        # Where the flow followed a knot, else where the head's step carries it; the head's
        # scale, and the mouth's downward normal turned with the head.
        start, followed, mouth_unfollowed, scale, down = self._plan.begin(step, total, self._knots, flow)
        reach = p.reach
        if followed is not None:
            if mouth_unfollowed:
                self._mouth_sideways(frame, start, followed, step, down, reach)
            if self._lips is not None:
                self._lips.move(frame, start, ~followed, scale)
        # The start inside the frame, the first frame's knots carried by the head, the rest
        # shape (:meth:`_mouth_rest`) and the pairs' gaps at the head's scale.
        carried, rest, targets = self._plan.settle(start, total, scale)
        # The field around the start, a solver pass, then more for the mouth while a mouth knot
        # moved FAST of a pass's reach in the last.
        knots, iters, resp = self._solver.track(
            frame,
            self._previous(),
            start,
            rest,
            tuple(down),
            targets,
            (self.width, self.height),
            p.smoothing,
            self._frame_bands,
            self._mouth_uintp,
            self._mouth_curves,
            p.mouth_passes,
            FAST * reach,
        )
        # The inner mouth centred (:meth:`_centre_inner`), the confidences and shape checks.
        ratio, confs, shapes = self._plan.assess(knots, rest, tuple(down), resp, carried)
        ratio, confidence, lost = ratio.tolist(), dict(zip(FEATURES, confs)), []
        assessed_inner = confidence["mouth_inner"]  # before a relocated mouth replaces it
        for feature, shape_ok in zip(FEATURES, shapes):
            conf, fallback = confidence[feature], carried
            search = self._brow_search.get(feature)
            if search is not None and (
                min(ratio[r] for r in self._feature_rows[feature]) < p.brow_search or not shape_ok
            ):
                conf, shape_ok, fallback, more = self._search_brow(
                    frame, feature, search, knots, start, rest, down, targets, carried, scale, conf, shape_ok
                )
                iters += more
                confidence[feature] = conf
            if conf < p.lost_response or not shape_ok:
                lost.append(feature)
                if feature.startswith("brow"):
                    knots[self._features[feature]] = fallback[self._features[feature]]
        self._mouth_lost_for = self._mouth_lost_for + 1 if any(f.startswith("mouth") for f in lost) else 0
        if 0 < p.mouth_relocate <= self._mouth_lost_for and self._lips is not None and self._lips.active:
            relocated, more = self._relocate_mouth(frame, self._lips, knots, carried, down, targets)
            iters += more
            if relocated is not None:
                confidence.update(relocated)
                lost = [f for f in lost if not f.startswith("mouth")]
        if p.inner_search > 0 and "mouth_inner" in lost:
            inner, more = self._search_inner(frame, knots, rest, down, targets, carried, assessed_inner)
            iters += more
            if inner is not None:
                confidence["mouth_inner"] = inner
                lost.remove("mouth_inner")
                if "mouth_outer" not in lost:
                    self._mouth_lost_for = 0
        self._knots = knots
        self._linear = total[:, :2]
        self._down = down
        self._prev = frame
        # The head motion reads the brows' reported knots next frame.
        self._reported = self._reported_knots()
        return FrameResult(
            self.frame_index, self._named(self._scale.to_frame(self._reported)), confidence, lost, iters, ok
        )

    def reseat(self, contours: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Move the contours of the frame last tracked to ``contours``, keeping what the first
        frame set up (its shape as the rest shape, the edges' calibration, the lip colour, the
        brow templates): the head's accumulated motion becomes the similarity that best takes
        the first frame's brows onto these (robustly; over all the knots, the mouth's outnumber
        the brows', and a grimace's mouth turned and scaled the head: on lp_d6 the mouth then
        left the lips for 15 frames after a reseat).

        Parameters
        ----------
        contours
            Name -> (N, 2) float array: all eight contours, (x, y) pixels of the frame last
            tracked, in the convention of the first frame's (a landmark pass's), laid out in as
            many knots as the first frame's (else :class:`facemime.errors.InvalidInputError`).

        Returns
        -------
        dict of str to (N, 2) float64 array
            The contours as now reported, (x, y) pixels of the frame (:attr:`contours`).
        """
        knots = self._knots_of(contours)
        given = self._knots0 - self._offset  # the first frame's contours, as given
        total = motion.brow_similarity(self._named(given), self._named(knots))
        if self._motion is not None:
            self._motion.total = total
            self._linear = total[:, :2]
            down = self._linear @ np.asarray(self._down0)
            self._down = down / max(float(np.linalg.norm(down)), 1e-12)
        self._knots = knots + self._offset @ self._linear.T
        self._reported = self._reported_knots()
        return self.contours

    def recalibrate(self, contours: Mapping[str, np.ndarray], weight: float) -> dict[str, np.ndarray]:
        """Move the convention the contours are reported in part of the way towards ``contours``:
        the calibration offset between the image edges the snakes hold and the reported contours
        becomes ``weight`` of the way to the offset that would report these.

        Parameters
        ----------
        contours
            Name -> (N, 2) float array: all eight contours, (x, y) pixels of the frame last
            tracked, laid out in as many knots as the first frame's (else
            :class:`facemime.errors.InvalidInputError`).
        weight
            How far to move, 0..1 (0: not at all; 1: report ``contours`` for this frame).

        Returns
        -------
        dict of str to (N, 2) float64 array
            The contours as now reported, (x, y) pixels of the frame (:attr:`contours`).
        """
        knots = self._knots_of(contours)
        wanted = np.linalg.solve(self._linear, (self._knots - knots).T).T  # in the first frame's orientation
        self._offset = (1.0 - weight) * self._offset + weight * wanted
        self._reported = self._reported_knots()
        return self.contours

    def _knots_of(self, contours: Mapping[str, np.ndarray]) -> np.ndarray:
        """The knots, in the frames the snakes see, that lay out all eight ``contours`` ((x, y)
        pixels of the frame) as the first frame's were laid out."""
        contours = check_contours(contours, *self._scale.size)
        knots, _ = layout({n: self._scale.to_work(c) for n, c in contours.items()}, self.params)
        if len(knots) != len(self._knots):
            raise InvalidInputError(f"contours give {len(knots)} knots, the tracker has {len(self._knots)}")
        return knots

    def _centre_inner(self, knots: np.ndarray, rest: np.ndarray, down: np.ndarray) -> None:
        """Slide the inner mouth along the mouth line by :data:`CENTRING` of its drift from
        where it sat in the outer mouth in the rest shape (a closed mouth's dark line gives the
        inner curves nothing to hold them sideways; ``FramePlan.centre``, in place)."""
        self._plan.centre(knots, rest, tuple(down))

    def _mouth_rest(self, carried: np.ndarray, start: np.ndarray) -> np.ndarray:
        """The rest knots: ``carried`` (the first frame's, moved by the head) with each mouth
        feature moved ``mouth_affine`` of the way to its affine least-squares fit to ``start``
        (``FramePlan.rest``)."""
        return self._plan.rest(carried, start)

    def _shapes_ok(self, knots: np.ndarray, rest: np.ndarray) -> dict[str, bool]:
        """Per feature, whether its upper curve's chord stays within a factor 2 of its chord in
        ``rest`` (the inner mouth's may shrink to :data:`NARROWEST` of it: a mouth rounding into
        an "O" opens only in the middle of the line where the lips met; ``FramePlan.shapes``)."""
        return dict(zip(FEATURES, self._plan.shapes(knots, rest)))

    def _shape_ok(self, knots: np.ndarray, rest: np.ndarray, feature: str) -> bool:
        """:meth:`_shapes_ok` of one feature."""
        return self._shapes_ok(knots, rest)[feature]

    @property
    def motion(self) -> motion.HeadMotion | ScaledMotion | None:
        """The head-motion follower (its rigid points, in the frame's pixels, feed the head
        pose); None when head-motion compensation is off."""
        if self._motion is not None and self._scale.active:
            return ScaledMotion(self._motion, self._scale)
        return self._motion

    @property
    def edges(self) -> dict[str, np.ndarray]:
        """The first frame's contours as settled on the image edges (no calibration offset
        taken out), name -> (N, 2) float64 pixels."""
        return self._named(self._scale.to_frame(self._knots0))

    @property
    def contours(self) -> dict[str, np.ndarray]:
        """The current contours, name -> (N, 2) float64 pixels."""
        return self._named(self._scale.to_frame(self._reported_knots()))

    def _reported_knots(self) -> np.ndarray:
        """The knots as reported: calibration offset (turned and scaled with the head) taken
        out, inner curves uncrossed (where the inner lower lip lies above the inner upper lip
        along ``down``, both points go to their midpoint)."""
        return _core.reported_knots(self._knots, self._offset, self._linear, tuple(self._down), *self._inner_pairs)

    def _named(self, knots: np.ndarray) -> dict[str, np.ndarray]:
        """name -> (N, 2) the contours' knots (slices of one new array)."""
        flat = knots.take(self._order, axis=0)  # (take: a quarter of fancy indexing's time)
        return {n: flat[a:b] for n, a, b in self._spans}
