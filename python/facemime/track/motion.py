"""Head-motion compensation: the similarity transform (rotation, uniform scale, translation) of
the face between consecutive frames, from pyramidal Lucas-Kanade optical flow
(:mod:`facemime.track.flow`) of textured points
in the rigid parts of the face (nose bridge and nose, forehead), forward-backward checked and
fitted robustly (:func:`robust_similarity`, deterministic: the same frames always give the same
track). Mouth and brows ride on this motion before the snakes refine them, so the
snake search range δ0/(1−σ) can stay small (docs/method.md §4).

Transforms are 2×3 float64 matrices mapping (x, y) pixels of one frame to another.
"""

from __future__ import annotations

from collections.abc import Mapping

import cv2
import numpy as np

from facemime import _core
from facemime.track.flow import EPSILON, ITERATIONS, LEVELS, MIN_EIGEN, WINDOW
from facemime.track.template import gray_crop
from facemime.types.similarity import FIT_ROUNDS, IDENTITY, as_points, compose, robust_similarity

#: Rigid zones in face coordinates (s, t) of the first frame: a point is ``c + s·W·u + t·v``
#: where ``c`` is the centre of the brows, ``v`` runs from it to the centre of the mouth, ``u`` is
#: ``v`` turned to image-right (unit) and ``W`` is the outer width of the brows. In later frames
#: the zones follow the tracked brows.
ZONES = (
    ((-0.2, 0.2), (0.2, 0.72)),  # nose bridge, nose, nostrils
    ((-0.45, 0.45), (-1.0, -0.4)),  # forehead above raised brows (hair, glasses)
)
FB_LIMIT = 1.0  # px: forward-backward error above this rejects a point
#: Pyramid levels above the frame at most for the flows that start where the head's step carries
#: the points: the ``extra`` points' both ways (one that fails the forward-backward check then
#: gets all the levels, from no guess), and the rigid points' way back, from where the inverse
#: of the step fitted to their forward flow carries them (one that fails is dropped: all the
#: levels from no guess found 1 of 100,923 such points again). Each level costs as
#: much as the frame's own. Measured on the six videos over 24 starts (and lp_d6 over 48 more),
#: 2 tracks as all 5 levels from no guess did; 1 doubled the inner mouth's failures from lp_d6's
#: automatic start (12 to 20 frames a start). The rigid points' guided way back, rather than
#: all the levels from no guess, tracked the six videos as before from the reference, the
#: automatic start and six of seven noisy starts (the seventh's mean NMEs moved by at most
#: 0.0003), and made the tracker about 2.5% faster.
GUIDED_LEVELS = 2
MIN_POINTS = 6
DETECT_MARGIN = 8  # px around the zones for the corner measure (block 5, Sobel 3)
QUALITY = 0.01  # a corner's measure is above this fraction of the zones' strongest
CORNER_BLOCK = 5  # px: side of the square over which the corner measure sums gradients


def face_frame(contours: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The face's frame of :data:`ZONES` in a set of contours.

    Parameters
    ----------
    contours
        Name -> (N, 2) float array, (x, y) pixels, each curve image-left to image-right: the
        four brow curves and the two outer mouth curves at least.

    Returns
    -------
    tuple of (c, u, v, W)
        c : (2,) float64 array
            Centre of the brows (mean of all their points), pixels.
        u : (2,) float64 array
            Unit vector: ``v`` turned to image-right.
        v : (2,) float64 array
            From ``c`` to the centre of the outer mouth (mean of its points), pixels.
        W : float
            Outer width of the brows (``brow_right_upper``'s first point to
            ``brow_left_upper``'s last), pixels.
    """
    brows = np.concatenate([contours[n] for n in contours if n.startswith("brow")])
    mouth = np.concatenate([contours[n] for n in contours if n.startswith("mouth_outer")])
    c = brows.mean(axis=0)
    v = mouth.mean(axis=0) - c
    u = np.array([v[1], -v[0]]) / max(np.linalg.norm(v), 1e-9)
    width = float(np.linalg.norm(contours["brow_left_upper"][-1] - contours["brow_right_upper"][0]))
    return c, u, v, width


def zone_polygons(contours: Mapping[str, np.ndarray]) -> list[np.ndarray]:
    """The rigid zones of a set of contours as pixel polygons.

    Parameters
    ----------
    contours
        Name -> (N, 2) float array, (x, y) pixels, as :func:`face_frame` takes them.

    Returns
    -------
    list of (4, 2) float64 array
        One quadrilateral per zone of :data:`ZONES`, in that order, (x, y) pixels.
    """
    c, u, v, width = face_frame(contours)
    polys = []
    for (s0, s1), (t0, t1) in ZONES:
        corners = [(s0, t0), (s1, t0), (s1, t1), (s0, t1)]
        polys.append(np.array([c + s * width * u + t * v for s, t in corners]))
    return polys


def brow_similarity(src: Mapping[str, np.ndarray], dst: Mapping[str, np.ndarray]) -> np.ndarray:
    """The similarity that best maps the brow contours of ``src`` onto those of ``dst`` (robust
    least squares over their points: :func:`facemime.types.similarity.robust_similarity`, 1 px
    inlier limit).

    Parameters
    ----------
    src
        Name -> (N, 2) float array, (x, y) pixels: the contours whose brow curves (names starting
        ``brow``) are mapped.
    dst
        Name -> (N, 2) float array, (x, y) pixels: the same brow curves, as many points each,
        where they are to go.

    Returns
    -------
    (2, 3) float64 array
        The similarity (rotation, uniform scale, translation) of (x, y) pixels.
    """
    names = [n for n in src if n.startswith("brow")]
    a = np.concatenate([src[n] for n in names])
    b = np.concatenate([dst[n] for n in names])
    return robust_similarity(a, b, limit=1.0)[0]


class HeadMotion:
    """Follows the head from frame to frame. Feed frames, (H, W) grey or (H, W, 3) RGB uint8
    (RGB is read as OpenCV's ``RGB2GRAY`` grey), to :meth:`update` with the brow points tracked
    in the previous frame (:meth:`brow_points` of its contours): they place the rigid zones, so
    the points stay on the face even when the accumulated motion drifts. The flow, the fit and
    the zones run in the core (``facemime._core.HeadFollower``, which converts only the part of
    an RGB frame the flow reads), and so does finding corners on those grey levels
    (``HeadFollower.corners``, OpenCV's ``goodFeaturesToTrack``); the coarse fallback is
    OpenCV's, here.

    ``total`` is the accumulated transform from the first frame to the current one, ``step``
    the last frame's (identity before the first update and where it was not measured). ``points``
    (M, 2) float32 are the rigid points followed into the current frame and ``ids`` (M,) int64
    their identities: a point keeps its id for as long as it is followed, new detections get
    new ids (the head-pose estimator keeps each point's 3D position by id). ``followed`` is the
    (points, ids) pair of the points followed from the previous frame, before any re-detection.

    Parameters
    ----------
    frame
        (H, W) grey or (H, W, 3) RGB uint8: the first frame; every later frame has its size.
    contours
        Name -> (N, 2) float array, (x, y) pixels: the first frame's contours, the brow and outer
        mouth curves at least (:func:`face_frame`); its brow curves are the ones
        :meth:`brow_points` joins from then on.
    max_points
        Most rigid points one detection finds (``goodFeaturesToTrack``'s ``maxCorners``), kept
        at least max(3, W / 30) pixels apart, W the brows' outer width.
    """

    def __init__(self, frame: np.ndarray, contours: Mapping[str, np.ndarray], max_points: int = 60):
        self._min_distance = max(3.0, face_frame(contours)[3] / 30.0)
        self._max_points = max_points
        self.total = IDENTITY.copy()
        self.step = IDENTITY.copy()
        self._prev = frame = np.ascontiguousarray(frame, np.uint8)
        self._shape = frame.shape[:2]
        self._brows = tuple(n for n in contours if n.startswith("brow"))
        zones = zone_polygons(contours)
        self._head = _core.HeadFollower(
            frame,
            self.brow_points(contours),
            np.stack(zones),
            WINDOW,
            LEVELS,
            GUIDED_LEVELS,
            FB_LIMIT,
            MIN_POINTS,
            FIT_ROUNDS,
            ITERATIONS,
            EPSILON,
            MIN_EIGEN,
        )
        self._head.detected(self._detect(zones))

    @property
    def points(self) -> np.ndarray:
        return self._head.points[0]

    @property
    def ids(self) -> np.ndarray:
        return self._head.points[1]

    @property
    def followed(self) -> tuple[np.ndarray, np.ndarray]:
        return self._head.followed

    @property
    def brows(self) -> tuple[str, ...]:
        """The brow contours' names, in the order :meth:`brow_points` joins them."""
        return self._brows

    def brow_points(self, contours: Mapping[str, np.ndarray]) -> np.ndarray:
        """The brow contours' points joined, as :meth:`update` takes them.

        Parameters
        ----------
        contours
            Name -> (N, 2) float array, (x, y) pixels, with the brow curves of the first frame's
            contours (:attr:`brows`), as many points each.

        Returns
        -------
        (N, 2) float64 array
            The points of the curves of :attr:`brows`, in that order, (x, y) pixels.
        """
        return as_points(np.concatenate([contours[n] for n in self._brows]))

    @staticmethod
    def _zones_box(
        zones: np.ndarray | list[np.ndarray], shape: tuple[int, ...], margin: int
    ) -> tuple[int, int, int, int]:
        """(x0, y0, x1, y1), exclusive ends: the ``zones``' box, from the floor of their
        smallest to the ceiling of their largest coordinates, grown by ``margin`` px, inside
        the frame."""
        return _core.grown_box(as_points(zones), margin, shape[1], shape[0])

    def _detect(self, zones: np.ndarray | list[np.ndarray]) -> np.ndarray:
        """(M, 2) float32 corners in the ``zones`` of the frame last followed (OpenCV's
        ``goodFeaturesToTrack`` on its grey levels, computed by ``HeadFollower.corners``). The
        corner measure reads a few pixels around each pixel, so it runs on the zones' box grown
        by :data:`DETECT_MARGIN` px only: the same corners as on the whole frame, for a
        fraction of the work."""
        x0, y0, x1, y1 = self._zones_box(zones, self._shape, DETECT_MARGIN)
        if x1 - x0 <= 2 * DETECT_MARGIN or y1 - y0 <= 2 * DETECT_MARGIN:
            return np.zeros((0, 2), np.float32)
        mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
        for poly in np.rint(np.asarray(zones) - (x0, y0)).astype(np.int32):
            cv2.fillConvexPoly(mask, poly, 255)
        return self._head.corners((x0, y0, x1, y1), mask, self._max_points, QUALITY, self._min_distance, CORNER_BLOCK)

    def _coarse_shift(self, frame: np.ndarray) -> tuple[np.ndarray, bool]:
        """Fallback for motion too fast or blurred for the flow: the translation that best
        matches the previous frame's face zones (normalised cross-correlation at 1/4 scale,
        searched up to half the zone size away); the rigid points are then dropped."""
        x0, y0, x1, y1 = self._zones_box(self._head.zones, frame.shape, 0)
        if x1 - x0 < 16 or y1 - y0 < 16:
            return IDENTITY.copy(), False
        rx, ry = (x1 - x0) // 2, (y1 - y0) // 2
        sx0, sy0 = max(x0 - rx, 0), max(y0 - ry, 0)
        sx1, sy1 = min(x1 + rx, frame.shape[1]), min(y1 + ry, frame.shape[0])

        def small(img: np.ndarray) -> np.ndarray:
            return np.asarray(cv2.resize(img, None, fx=0.25, fy=0.25, interpolation=cv2.INTER_AREA), np.uint8)

        templ = small(gray_crop(self._prev, (x0, y0), (x1, y1)))
        search = small(gray_crop(frame, (sx0, sy0), (sx1, sy1)))
        if templ.shape[0] > search.shape[0] or templ.shape[1] > search.shape[1] or templ.std() < 1.0:
            return IDENTITY.copy(), False
        (bx, by), best = _core.best_match(search, templ)
        if best < 0.5:
            return IDENTITY.copy(), False
        shift = np.array([sx0 + 4.0 * bx - x0, sy0 + 4.0 * by - y0])
        step = IDENTITY.copy()
        step[:, 2] = shift
        self._head.drop_points()
        return step, True

    def update(
        self, frame: np.ndarray, brows: np.ndarray, extra: np.ndarray | None = None
    ) -> tuple[np.ndarray, bool, np.ndarray | None]:
        """Motion from the previous frame to ``frame``.

        Parameters
        ----------
        frame
            (H, W) grey or (H, W, 3) RGB uint8, the first frame's size: the next frame.
        brows
            (N, 2) float array, (x, y) pixels: the brow points tracked in the previous frame
            (:meth:`brow_points` of its contours, as many as the first frame's); the brows, the
            most reliably tracked feature, place the rigid zones.
        extra
            (E, 2) float array, (x, y) pixels of the previous frame: other points to follow by
            the same flow; None: none.

        Returns
        -------
        tuple of (step, measured, moved)
            step : (2, 3) float64 array
                The similarity from the previous frame's pixels to this one's: from the rigid
                points' flow, else a translation from the coarse template search; the identity
                when both failed.
            measured : bool
                Whether ``step`` was measured (False: the identity of a failure).
            moved : (E, 2) float64 array or None
                The ``extra`` points' positions in ``frame``, (x, y) pixels, NaN where the flow
                failed its forward-backward check (all NaN when the head had fewer than
                :data:`MIN_POINTS` rigid points to follow); None when ``extra`` is None.
        """
        frame = np.ascontiguousarray(frame, np.uint8)
        extra_pts = as_points(np.zeros((0, 2)) if extra is None else extra)
        fit, moved = self._head.follow(frame, as_points(brows), extra_pts)
        step, ok = (fit, True) if fit is not None else self._coarse_shift(frame)
        self.step = step
        self.total = compose(step, self.total)
        if self._head.advance(step):
            self._head.detected(self._detect(self._head.zones))
        self._prev = frame
        return step, ok, None if extra is None else moved
