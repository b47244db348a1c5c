"""The tracker with re-detection: the snakes track every frame, and the face landmark model
(:mod:`facemime.networks`) puts them right on the rare frames where they went astray.

A landmark pass is made

- every ``check_every`` frames, on the crop that the last pass's landmarks frame once carried
  along by the tracked contours (no detection; the detector where that crop holds no face);
- on the frame a feature has been flagged lost ``lost_for`` frames in a row;
- on a cut: a frame that differs from the one before by more than :data:`CUT` grey levels on
  average over a sparse grid of about 32 x 32 pixels (with the face detector: after a cut the
  face may be anywhere);
- on every frame after the face was lost (the head's motion could not be measured, or every
  feature collapsed), with the face detector, until a face is found again.

When a feature lies further than ``disagree`` inter-ocular distances from the pass's (the
symmetric curve distance of the shared data's NME, averaged over the feature's curves), the
contours move to the pass's. Where the pass found the face where it was expected, the tracker is
*reseated* (:meth:`facemime.track.Tracker.reseat`): it keeps what its first frame set up (the
rest shape, the edges' calibration, the lip colour, the brow templates), which a frame caught
mid-grimace would set up badly (restarting instead on ``lp_d6``'s checks took its outer mouth's
failures from 1.8% to 5.3%). Where the face was found elsewhere (a cut, a face come back), the
tracker starts afresh on it. Otherwise the tracked contours stand, and, where the tracker
started from landmarks, the convention they are reported in moves to the running mean of the
landmark passes' (:meth:`facemime.track.Tracker.recalibrate`, weight 1/n for the n-th pass): the
landmark model's error on one frame, 0.01 to 0.03 IOD, is largely its own on that frame, and the
tracker otherwise carries the first frame's for good. On the ten shared videos' automatic starts
this took the mean NME from 0.0198 / 0.0203 / 0.0172 (outer mouth / inner mouth / brows) to
0.0187 / 0.0187 / 0.0126 (the reference starts: 0.0166 / 0.0169 / 0.0120; both with a reseat
placing the head by all the knots, as it first did). Contours given by the user keep their own
convention.

Coordinates are (x, y) pixels, origin at the centre of the top-left pixel, y down.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from facemime.errors import NoFaceError
from facemime.metrics import curve_error
from facemime.networks.finder import find_face, follow_face
from facemime.networks.mesh import reference_points
from facemime.track.knots import FrameResult
from facemime.track.motion import HeadMotion
from facemime.track.params import TrackerParams
from facemime.track.scale import ScaledMotion
from facemime.track.tracker import Tracker
from facemime.types.contours import CONTOUR_NAMES, FEATURES
from facemime.types.similarity import apply, robust_similarity

#: Lowest detection score while searching for a face lost from a video that showed one:
#: MediaPipe's own threshold (a human face was found at the start; see
#: :data:`facemime.networks.finder.FACE_SCORE` for why the start asks for more).
SEARCH_SCORE = 0.5
#: A frame whose pixels on a sparse grid (every k-th row and column, k the shorter side / 32)
#: differ from the previous frame's by more than this many levels on average is a cut.
#: Measured between consecutive frames of the ten shared videos: at most 21.6 (lp_d12's
#: hand-held shake; 2.0 to 19 on the others); at a cut from lp_d0 to st_kh, 60.
CUT = 35.0


@dataclass(frozen=True)
class Redetection:
    """When the landmark model checks the tracker (see the module's docs).

    ``check_every``: frames between two checks (0: never); ``lost_for``: frames a feature stays
    lost before a check (0: never); ``disagree``: a feature this many inter-ocular distances
    from the check's is put right; ``calibrate``: a tracker started from landmarks reports its
    contours as the mean of the landmark passes would place them (:meth:`FaceTracker.update`).
    """

    check_every: int = 30
    lost_for: int = 3
    disagree: float = 0.06
    calibrate: bool = True


def contours_of(landmarks: np.ndarray, size: tuple[int, int]) -> dict[str, np.ndarray]:
    """The eight tracker contours of one face's Face Mesh landmarks, clipped to the image.

    Parameters
    ----------
    landmarks
        (468, 2+) float array (or 478 rows, with the irises): Face Mesh landmarks, (x, y) pixels
        in the first two columns.
    size
        (width, height) of the image, pixels.

    Returns
    -------
    dict of str to (N, 2) float64 array
        Each name of ``CONTOUR_NAMES`` -> its points, (x, y) pixels image-left to image-right,
        clipped to -0.5 .. width - 0.5 in x and -0.5 .. height - 0.5 in y.
    """
    points = reference_points(landmarks)
    return {n: np.clip(points[n], -0.5, np.asarray(size) - 0.5) for n in CONTOUR_NAMES}


def sparse_grid(frame: np.ndarray) -> np.ndarray:
    """Every k-th pixel of every k-th row of a frame, k = min(H, W) // 32 (at least 1), starting
    at k // 2: a glance at the whole picture for finding cuts (:data:`CUT`).

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB.

    Returns
    -------
    (about H / k, W / k, 3) float32 array
        The sampled pixels' levels, 0-255.
    """
    k = max(1, min(frame.shape[:2]) // 32)
    return frame[k // 2 :: k, k // 2 :: k].astype(np.float32)


def disagreement(tracked: Mapping[str, np.ndarray], found: Mapping[str, np.ndarray], iod: float) -> dict[str, float]:
    """Per feature, the mean over its curves of the symmetric curve distance between two sets of
    contours (:func:`facemime.metrics.curve_error`), in inter-ocular distances.

    Parameters
    ----------
    tracked
        Contour name -> (N, 2) float array, (x, y) pixels: all eight contours, as tracked.
    found
        Contour name -> (M, 2) float array, (x, y) pixels: all eight contours, as a landmark pass
        found them.
    iod
        Inter-ocular distance, pixels: the unit of the result.

    Returns
    -------
    dict of str to float
        Feature name (``mouth_outer``, ``mouth_inner``, ``brow_left``, ``brow_right``) -> its
        distance, in IOD (+inf where a tracked curve is malformed or not finite).
    """
    return {
        f: float(np.mean([curve_error(tracked[n], found[n]) for n in names])) / iod for f, names in FEATURES.items()
    }


class FaceTracker:
    """Tracks the mouth and brows of one face frame by frame, put right by the landmark model
    where the snakes went astray.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the first frame.
    contours
        Name -> (N, 2) float array: the eight contours on ``frame``, (x, y) pixels, each
        image-left to image-right; None: the largest face's landmarks start the tracker (raises
        :class:`facemime.errors.NoFaceError` where there is none).
    params
        The tracker's settings; None: the defaults of :class:`TrackerParams`.
    redetection
        When the landmark model checks the tracker; None: the defaults of :class:`Redetection`.

    Attributes
    ----------
    redetected : list of int
        The frames the landmark model put the contours right on.
    checking_seconds : float
        Time spent in the landmark model's passes and what they decided, after the first frame.
    faces : int
        How many faces the first frame showed when the tracker started on the largest (1 when
        contours were given).
    """

    def __init__(
        self,
        frame: np.ndarray,
        contours: Mapping[str, np.ndarray] | None = None,
        params: TrackerParams | None = None,
        redetection: Redetection | None = None,
    ):
        self.params = params
        self.redetection = redetection or Redetection()
        landmarks, self.faces = None, 1
        self._measured = 0  # landmark passes the reported contours average (0: given contours)
        if contours is None:
            self._measured = 1
            face = find_face(frame)
            landmarks, self.faces = face.landmarks, face.faces
            contours = contours_of(landmarks, frame.shape[1::-1])
        self.tracker = Tracker(frame, contours, params)
        self._landmarks: np.ndarray | None = None
        self._anchor = np.concatenate([self.tracker.contours[n] for n in CONTOUR_NAMES])
        self._iod = 1.0
        if landmarks is not None:
            self._note(landmarks, self._anchor)
        self._face = True
        self._since_check = 0
        self._lost_for = dict.fromkeys(FEATURES, 0)
        self.frame_index = 0
        self._glance = sparse_grid(frame)
        self.redetected: list[int] = []
        self.checking_seconds = 0.0

    def update(self, frame: np.ndarray) -> FrameResult:
        """Track one more frame, checking it with the landmark model where the module's docs say.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB, the first frame's size: the next frame.

        Returns
        -------
        FrameResult
            The frame's contours ((x, y) pixels), confidences and lost features; ``index`` is
            the frame's number (the first frame's is 0); ``redetected`` says whether the landmark
            model put the contours right. While the face is lost and not found again: the last
            contours, every feature lost with confidence 0, and ``motion_ok`` False.
        """
        self.frame_index += 1
        glance, self._glance = self._glance, sparse_grid(frame)
        if not self._face:
            return self._timed(self._search, frame)
        result = replace(self.tracker.update(frame), index=self.frame_index)
        self._since_check += 1
        for f in FEATURES:
            self._lost_for[f] = self._lost_for[f] + 1 if f in result.lost else 0
        if not result.motion_ok or len(result.lost) == len(FEATURES):
            self._face = False
            return result
        r = self.redetection
        cut = r.check_every > 0 and float(np.abs(self._glance - glance).mean()) > CUT
        if cut or 0 < r.check_every <= self._since_check or 0 < r.lost_for <= max(self._lost_for.values()):
            return self._timed(self._check, frame, result, cut)
        return result

    def _timed(self, step, *args) -> FrameResult:
        t0 = time.perf_counter()
        try:
            return step(*args)
        finally:
            self.checking_seconds += time.perf_counter() - t0

    def _check(self, frame: np.ndarray, result: FrameResult, cut: bool = False) -> FrameResult:
        """One landmark pass where the face is expected (after a ``cut``, where the detector
        finds it), and the frame's result after it."""
        self._since_check = 0
        now = np.concatenate([result.contours[n] for n in CONTOUR_NAMES])
        found = None
        if self._landmarks is not None and not cut:
            # the last pass's landmarks carried by the contours' motion since (robustly: a
            # feature gone astray does not drag the crop)
            carry = robust_similarity(self._anchor, now, limit=0.05 * self._iod)[0]
            found = follow_face(frame, apply(carry, self._landmarks[:, :2]))
        followed = found is not None
        if found is None:
            try:
                found = find_face(frame, SEARCH_SCORE).landmarks
            except NoFaceError:
                return result
        self._note(found, now)
        contours = contours_of(found, frame.shape[1::-1])
        if max(disagreement(result.contours, contours, self._iod).values()) <= self.redetection.disagree:
            if self.redetection.calibrate and self._measured:
                self._measured += 1
                reported = self.tracker.recalibrate(contours, 1.0 / self._measured)
                self._anchor = np.concatenate([reported[n] for n in CONTOUR_NAMES])
                return replace(result, contours=reported)
            return result
        if followed:  # the same face where it was expected: only the contours went astray
            self.tracker.reseat(contours)
        else:  # a face elsewhere (a cut, or one that came back): start afresh on it
            self.tracker = Tracker(frame, contours, self.params)
            self._measured = 1
        return self._redetected()

    def _search(self, frame: np.ndarray) -> FrameResult:
        """A frame after the face was lost: look for it; the last contours, all lost, if absent."""
        try:
            found = find_face(frame, SEARCH_SCORE).landmarks
        except NoFaceError:
            return FrameResult(
                self.frame_index, self.tracker.contours, dict.fromkeys(FEATURES, 0.0), list(FEATURES), 0, False
            )
        self.tracker = Tracker(frame, contours_of(found, frame.shape[1::-1]), self.params)
        self._measured = 1
        self._face = True
        self._note(found, np.concatenate([self.tracker.contours[n] for n in CONTOUR_NAMES]))
        return self._redetected()

    def _redetected(self) -> FrameResult:
        """The result of a frame whose contours the landmark model put right."""
        self._since_check = 0
        self._lost_for = dict.fromkeys(FEATURES, 0)
        self.redetected.append(self.frame_index)
        self._anchor = np.concatenate([self.tracker.contours[n] for n in CONTOUR_NAMES])
        return FrameResult(
            self.frame_index, self.tracker.contours, dict.fromkeys(FEATURES, 1.0), [], 0, True, redetected=True
        )

    def _note(self, landmarks: np.ndarray, contours: np.ndarray) -> None:
        """Keep a landmark pass and the tracked contours of its frame ((K, 2) pixels), which
        carry it to later frames."""
        self._landmarks = landmarks
        self._anchor = contours
        self._iod = max(float(np.linalg.norm(landmarks[33, :2] - landmarks[263, :2])), 1.0)

    @property
    def contours(self) -> dict[str, np.ndarray]:
        """The current contours, name -> (N, 2) float64 pixels."""
        return self.tracker.contours

    @property
    def landmarks(self) -> np.ndarray | None:
        """The last landmark pass's Face Mesh landmarks, (468, 3) float64 pixels (None before
        the first where the tracker started from given contours)."""
        return self._landmarks

    @property
    def motion(self) -> HeadMotion | ScaledMotion | None:
        """The current tracker's head-motion follower (see :attr:`Tracker.motion`)."""
        return self.tracker.motion
