"""Analysis of a face video frame by frame: the actor fitted on the first frame, its mouth and
brow contours tracked, the head pose followed, and the local motion (knot offsets in the head's
own frame, see :mod:`facemime.animate.deform`) measured.

The head pose comes from the Face Mesh landmarks: one landmark pass a frame, on the crop the last
frame's landmarks frame (no detection), aligned to the key frame's
(:class:`facemime.animate.landmark_pose.LandmarkPose`) and smoothed
(:class:`~facemime.animate.landmark_pose.PoseFilter`), which measures the head's turn and nod as
well as its roll. Where the pass finds no face in its crop, the pose is measured on the rigid
points the optical flow follows (:class:`facemime.animate.pose.PoseTracker`), as below.

The contours are tracked by :class:`facemime.track.redetect.FaceTracker`: where they went astray
the face landmark model puts them right. When the face is lost (it leaves the frame or turns
away: the head's step can no longer be measured, or every feature collapsed), frames are marked
and every later frame is searched for the face again; once found, tracking restarts from its
landmarks, the pose from the actor's model fitted to them, and offsets stay relative to the
first frame. A frame whose step came from the head motion's coarse fallback (a fast,
blurred shake: the rigid points are dropped and found anew) keeps the face and its contours: its
pose moves by that step (:meth:`facemime.animate.pose.PoseTracker.update`), and is anchored
again by a fit of the actor on the frame at most once in :data:`ANCHOR_EVERY` frames.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.landmark_pose import LandmarkPose, PoseFilter
from facemime.animate.pose import PoseTracker
from facemime.errors import NoFaceError
from facemime.fit.actor import find_points, fit_actor, init_contours
from facemime.fit.adjust import fit_model
from facemime.networks.finder import follow_face
from facemime.networks.mesh import reference_points
from facemime.track.eyes import EyeTracker
from facemime.track.params import TrackerParams
from facemime.track.redetect import FaceTracker
from facemime.types.actor import Actor
from facemime.types.contours import FEATURES
from facemime.types.head import model_iod
from facemime.types.look import Look
from facemime.types.pose import Pose

#: Frames at least between two fits of the actor that anchor a pose carried by the head's step.
#: On lp_d6 and lp_d12 (PSNR of the re-synthesised face, mean of the two): a fit on every such
#: frame 20.67 dB (10 frames/s for lp_d12's run on one core), at most one in 15 or 30 frames the
#: same (30: 47 frames/s), one in 90 20.30 dB; never, 17.5 dB (the carried pose drifts: lp_d12's
#: nose tip 0.16 IOD off in the median, 0.07 with these fits). Marking the face lost and
#: restarting the tracker from a fit on each such frame, as this analysis first did, gave 20.19 dB
#: at 12 frames/s, the contours 0.06 IOD off.
ANCHOR_EVERY = 30


@dataclass
class FrameMotion:
    """What one frame's analysis measured.

    ``contours``: name -> (K, 2) px; ``confidence``: feature -> 0..1; ``lost``: features whose
    contours collapsed; ``face``: False when the face was not found (pose and offsets then
    repeat the last good frame's); ``pose``: the head pose of the analysis actor; ``offsets``:
    (K, 2) knot offsets, model units; ``redetected``: the face landmark model put the contours
    right on this frame; ``look``: the eyes (:class:`~facemime.types.look.Look`, relative to
    the first frame's).
    """

    contours: dict[str, np.ndarray]
    confidence: dict[str, float]
    lost: list[str]
    face: bool
    pose: Pose
    offsets: np.ndarray
    redetected: bool = False
    look: Look = field(default_factory=Look)


@dataclass
class Timings:
    """Seconds spent per stage."""

    track: float = 0.0
    pose: float = 0.0
    fit: float = 0.0
    look: float = 0.0


class Analysis:
    """Analyses a video of one face, fed frame by frame (RGB uint8 (H, W, 3)).

    The first frame must show the face roughly frontal; an actor is fitted on it (raises
    :class:`~facemime.errors.NoFaceError` when there is none), or, given ``actor`` (the same
    person's, fitted before), only that actor's model is placed on it, so that the motion is
    measured on the actor a receiver already holds. ``name`` names the video in messages;
    ``fps`` is its frame rate (frames a second), which sets the pose filter's time step.
    """

    def __init__(
        self,
        frame: np.ndarray,
        name: str,
        params: TrackerParams | None = None,
        actor: Actor | None = None,
        fps: float = 25.0,
    ):
        self.params = params
        self.timings = Timings()
        t0 = time.perf_counter()
        found, self.warnings = find_points(frame, name)
        self.actor, _, _ = fit_actor(frame, name, found.points, model=None if actor is None else actor.model)
        if actor is not None:  # placed on this frame, in this frame's scene
            self.actor = replace(actor, pose=self.actor.pose, source=self.actor.source, scene=self.actor.scene)
        model = self.actor.model
        # the reference measured as every later frame's is (one pass on the crop the landmarks
        # frame), not as the fit's (two passes averaged): the two differ by a constant offset
        key = follow_face(frame, found.face.landmarks)
        self._landmarks: np.ndarray | None = found.face.landmarks if key is None else key
        self._landmark_pose = LandmarkPose(self._landmarks, self.actor.pose, model.vertices, model.triangles)
        self._fps = max(float(fps), 1.0)
        self._smooth = PoseFilter(self._fps)
        self._smooth(self.actor.pose)
        self.timings.fit += time.perf_counter() - t0
        self.deformer = Deformer(self.actor.model)
        contours = init_contours(self.actor)
        self._knots0 = self.deformer.knot_positions(contours, self.actor.pose)
        self.tracker = FaceTracker(frame, contours, params)
        self.eyes = EyeTracker(self.actor.model, frame, self.actor.pose)
        self.eye_state = self.eyes.key  # the eyes as last measured (image positions, for checks)
        self._follow_pose(self.actor.pose)
        self.last = FrameMotion(
            contours, dict.fromkeys(FEATURES, 1.0), [], True, self.actor.pose, np.zeros((len(self.deformer.knots), 2))
        )
        self.frames_without_face = 0

    def _follow_pose(self, pose: Pose) -> None:
        """Follow the pose from ``pose`` on, on the rigid points of the current frame."""
        self.pose = PoseTracker(self.actor.model.vertices, self.actor.model.triangles, pose, self.tracker.motion)
        self._since_anchor = 0

    def _anchor(self, frame: np.ndarray) -> None:
        """Fit the actor to ``frame`` again and follow the pose from the fitted one; the contours
        are tracked on. Without a face found, the carried pose stays (until the next attempt,
        :data:`ANCHOR_EVERY` frames on)."""
        try:
            self._follow_pose(fit_actor(frame, "frame", model=self.actor.model)[0].pose)
        except NoFaceError:
            self._since_anchor = 0

    def update(self, frame: np.ndarray) -> FrameMotion:
        """Analyse the next frame."""
        t0 = time.perf_counter()
        follower = self.tracker.tracker
        result = self.tracker.update(frame)
        t1 = time.perf_counter()
        elsewhere = 0.0  # seconds after t1 that are counted as fitting or look, not as the pose's
        measured = True
        if self.tracker.tracker is not follower:  # restarted on a face found anew: new rigid points
            self._landmarks = self.tracker.landmarks
            self._follow_pose(fit_model(self.actor.model, reference_points(self.tracker.landmarks)).pose)
            self._smooth = PoseFilter(self._fps)  # the face came back: no smoothing across the gap
            self._smooth(self.pose.pose)
            fitting = time.perf_counter() - t1
            self.timings.fit += fitting
            elsewhere += fitting
        elif self.last.face:
            # The pose is measured on the landmarks, or, where the crop shows no face, on the rigid
            # points the flow follows, or moved by the head's step without them.
            found = None if self._landmarks is None else follow_face(frame, self._landmarks)
            if found is not None:
                self._landmarks = found
                self.pose.follow(self._smooth(self._landmark_pose.measure(found)), self.tracker.motion)
            else:
                measured = self.pose.update(self.tracker.motion)
        face = result.motion_ok and len(result.lost) < len(FEATURES)
        self._since_anchor += 1
        if face and not measured and self._since_anchor >= ANCHOR_EVERY:
            t2 = time.perf_counter()
            self._anchor(frame)
            fitting = time.perf_counter() - t2
            self.timings.fit += fitting
            elsewhere += fitting
        if face:
            offsets = self.deformer.knot_positions(result.contours, self.pose.pose) - self._knots0
            t2 = time.perf_counter()
            self.eye_state = self.eyes.update(frame, self.pose.pose)
            closure, iris = self.eyes.look(self.eye_state)
            look = Look(closure, iris)
            looking = time.perf_counter() - t2
            self.timings.look += looking
            elsewhere += looking
            self.last = FrameMotion(
                result.contours, result.confidence, result.lost, True, self.pose.pose, offsets, result.redetected, look
            )
        else:
            self.frames_without_face += 1
            self.last = FrameMotion(
                self.last.contours,
                dict.fromkeys(FEATURES, 0.0),
                list(FEATURES),
                False,
                self.last.pose,
                self.last.offsets,
                look=self.last.look,
            )
        self.timings.track += t1 - t0
        self.timings.pose += time.perf_counter() - t1 - elsewhere
        return self.last

    @property
    def model_block(self) -> dict:
        """The track file's ``model`` entry: unit, knot vertices, their feature sizes and the
        distance between the outer eye corners (model units)."""
        return {
            "unit": self.actor.model.unit,
            "knots": self.deformer.knots.tolist(),
            "feature_sizes": np.round(self.deformer.feature_sizes(), 3).tolist(),
            "iod": round(model_iod(self.actor.model), 3),
        }


def start_analysis(frame: np.ndarray, video: str, **options: Any) -> Analysis:
    """The :class:`Analysis` of a video whose first frame is ``frame`` (``video``: its name, in
    messages; ``options``: :class:`Analysis`'s). Raises :class:`~facemime.errors.NoFaceError`,
    saying that the video must start with a frontal face, where that frame shows none."""
    try:
        return Analysis(frame, f"the first frame of {video}", **options)
    except NoFaceError as e:
        raise NoFaceError(f"{e}; the video must start with a frontal face") from None


def analysed(
    frames: Iterable[np.ndarray], video: str, **options: Any
) -> Iterator[tuple[np.ndarray, Analysis, FrameMotion]]:
    """Each of ``frames`` (RGB, (H, W, 3) uint8) with the video's :class:`Analysis` and that
    frame's :class:`FrameMotion`: the first frame starts the analysis (:func:`start_analysis`:
    its one message for a first frame without a face), each later one updates it, re-detecting
    a face that was lost. ``video`` names the video in messages; ``options`` are
    :class:`Analysis`'s. The analysis is the same object on every frame."""
    analysis = None
    for frame in frames:
        if analysis is None:
            analysis = start_analysis(frame, video, **options)
            yield frame, analysis, analysis.last
        else:
            yield frame, analysis, analysis.update(frame)
