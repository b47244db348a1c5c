"""Analysis of a face video frame by frame: the actor fitted on the first frame, its mouth and
brow contours tracked, the head pose followed, and the local motion (knot offsets in the head's
own frame, see :mod:`facemime.animate.deform`) measured.

When the face is lost (it leaves the frame or turns away: the head's step can no longer be
measured, or every feature collapsed), frames are marked and every later frame is searched for
the face again; once found, tracking restarts from points found on it, and offsets stay relative
to the first frame. A frame whose step came from the head motion's coarse fallback (a fast,
blurred shake: the rigid points are dropped and found anew) keeps the face: its pose moves by
that step (:meth:`facemime.animate.pose.PoseTracker.update`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.pose import PoseTracker
from facemime.fit.detect import NoFaceError
from facemime.fit.placement import model_iod
from facemime.fit.run import fit_actor, init_contours
from facemime.render.projection import Pose
from facemime.track.contours import FEATURES
from facemime.track.tracker import Tracker, TrackerParams


@dataclass
class FrameMotion:
    """What one frame's analysis measured.

    ``contours``: name -> (K, 2) px; ``confidence``: feature -> 0..1; ``lost``: features whose
    contours collapsed; ``face``: False when the face was not found (pose and offsets then
    repeat the last good frame's); ``pose``: the head pose of the analysis actor; ``offsets``:
    (K, 2) knot offsets, model units.
    """

    contours: dict[str, np.ndarray]
    confidence: dict[str, float]
    lost: list[str]
    face: bool
    pose: Pose
    offsets: np.ndarray


@dataclass
class Timings:
    """Seconds spent per stage."""

    track: float = 0.0
    pose: float = 0.0
    fit: float = 0.0


class Analysis:
    """Analyses a video of one face, fed frame by frame (RGB uint8 (H, W, 3)).

    The first frame must show the face roughly frontal; an actor is fitted on it (raises
    :class:`~facemime.fit.detect.NoFaceError` when there is none). ``name`` names the video in
    messages.
    """

    def __init__(self, frame: np.ndarray, name: str, params: TrackerParams | None = None):
        self.params = params
        self.timings = Timings()
        t0 = time.perf_counter()
        self.actor, self.warnings, _ = fit_actor(frame, name)
        self.timings.fit += time.perf_counter() - t0
        self.deformer = Deformer(self.actor.model)
        contours = init_contours(self.actor)
        self._knots0 = self.deformer.knot_positions(contours, self.actor.pose)
        self._start(frame, contours, self.actor.pose)
        self.last = FrameMotion(contours, {f: 1.0 for f in FEATURES}, [], True, self.actor.pose,
                                np.zeros((len(self.deformer.knots), 2)))
        self.frames_without_face = 0

    def _start(self, frame: np.ndarray, contours: dict[str, np.ndarray], pose: Pose) -> None:
        self.tracker = Tracker(frame, contours, self.params)
        self.pose = PoseTracker(self.actor.model.vertices, self.actor.model.triangles, pose, self.tracker.motion)

    def update(self, frame: np.ndarray) -> FrameMotion:
        """Analyse the next frame."""
        if not self.last.face:
            return self._recover(frame)
        t0 = time.perf_counter()
        result = self.tracker.update(frame)
        t1 = time.perf_counter()
        # The pose is measured on the rigid points, or moved by the head's step without them.
        self.pose.update(self.tracker.motion)
        face = result.motion_ok and len(result.lost) < len(FEATURES)
        if face:
            offsets = self.deformer.knot_positions(result.contours, self.pose.pose) - self._knots0
            self.last = FrameMotion(result.contours, result.confidence, result.lost, True, self.pose.pose, offsets)
        else:
            self.frames_without_face += 1
            self.last = FrameMotion(self.last.contours, {f: 0.0 for f in FEATURES}, list(FEATURES), False,
                                    self.last.pose, self.last.offsets)
        self.timings.track += t1 - t0
        self.timings.pose += time.perf_counter() - t1
        return self.last

    def _recover(self, frame: np.ndarray) -> FrameMotion:
        t0 = time.perf_counter()
        try:
            found, _, _ = fit_actor(frame, "frame", model=self.actor.model)
        except NoFaceError:
            found = None
        self.timings.fit += time.perf_counter() - t0
        if found is None:
            self.frames_without_face += 1
            return self.last
        contours = init_contours(found)
        self._start(frame, contours, found.pose)
        offsets = self.deformer.knot_positions(contours, found.pose) - self._knots0
        self.last = FrameMotion(contours, {f: 1.0 for f in FEATURES}, [], True, found.pose, offsets)
        return self.last

    @property
    def model_block(self) -> dict:
        """The track file's ``model`` entry: unit, knot vertices, their feature sizes and the
        distance between the outer eye corners (model units)."""
        return {"unit": self.actor.model.unit, "knots": self.deformer.knots.tolist(),
                "feature_sizes": np.round(self.deformer.feature_sizes(), 3).tolist(),
                "iod": round(model_iod(self.actor.model), 3)}

