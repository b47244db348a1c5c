"""Analysis of a face video frame by frame: the actor fitted on the first frame, its mouth and
brow contours tracked, the head pose followed, and the local motion (knot offsets in the head's
own frame, see :mod:`facemime.animate.deform`) measured.

The head pose is followed by :class:`facemime.animate.head_pose.PoseFollower`: from the Face
Mesh landmarks, one landmark pass a frame, which measures the head's turn and nod as well as its
roll; from the rigid points the optical flow follows where the pass finds no face.

The contours are tracked by :class:`facemime.track.redetect.FaceTracker`: where they went astray
the face landmark model puts them right. When the face is lost (it leaves the frame or turns
away: the head's step can no longer be measured, or every feature collapsed), frames are marked
and every later frame is searched for the face again; once found, tracking restarts from its
landmarks, the pose from the actor's model fitted to them, and offsets stay relative to the
first frame. A frame whose step came from the head motion's coarse fallback (a fast,
blurred shake: the rigid points are dropped and found anew) keeps the face and its contours.
"""

from __future__ import annotations

import time
from collections.abc import Generator, Iterable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from facemime.animate.arkit import LID_GATE, jaw_opening, landmark_openings, quick_closures
from facemime.animate.deform import Deformer
from facemime.animate.head_pose import PoseFollower
from facemime.errors import NoFaceError
from facemime.fit.actor import find_points, fit_actor, init_contours
from facemime.networks.eyelids import eye_openings
from facemime.track.eyes import EyeTracker
from facemime.track.params import TrackerParams
from facemime.track.redetect import FaceTracker
from facemime.types.actor import Actor
from facemime.types.contours import FEATURES
from facemime.types.head import model_iod
from facemime.types.look import Look
from facemime.types.pose import Pose


@dataclass
class FrameMotion:
    """What one frame's analysis measured.

    ``contours``: name -> (K, 2) px; ``confidence``: feature -> 0..1; ``lost``: features whose
    contours collapsed; ``face``: False when the face was not found (pose and offsets then
    repeat the last good frame's); ``pose``: the head pose of the analysis actor; ``offsets``:
    (K, 2) knot offsets, model units; ``redetected``: the face landmark model put the contours
    right on this frame; ``look``: the eyes (:class:`~facemime.types.look.Look`, relative to
    the first frame's); ``landmark_closure``: (2,) the lids' closures in the head pose's Face Mesh
    landmarks (1 - each eye's :func:`~facemime.animate.arkit.landmark_openings` over the first
    frame's; the subject's right eye first), None where the landmark pass measured none;
    ``landmark_jaw``: the jaw's opening in those landmarks
    (:func:`~facemime.animate.arkit.jaw_opening`, mouth widths), None likewise; ``lid_closure``:
    (2,) the eye model's closures (:func:`~facemime.networks.eyelids.eye_openings` over the first
    frame's, the two eyes' mean), measured only on an eye whose quick closure
    (:func:`~facemime.animate.arkit.quick_closures`) is at least
    :data:`~facemime.animate.arkit.LID_GATE`, NaN on the other; None where the landmark pass
    measured none or the analysis does not use the eye model.
    """

    contours: dict[str, np.ndarray]
    confidence: dict[str, float]
    lost: list[str]
    face: bool
    pose: Pose
    offsets: np.ndarray
    redetected: bool = False
    look: Look = field(default_factory=Look)
    landmark_closure: np.ndarray | None = None
    landmark_jaw: float | None = None
    lid_closure: np.ndarray | None = None


@dataclass
class Timings:
    """Seconds spent per stage."""

    track: float = 0.0
    pose: float = 0.0
    fit: float = 0.0
    look: float = 0.0


class Analysis:
    """Analyses a video of one face, fed frame by frame.

    The first frame must show the face roughly frontal; an actor is fitted on it (raises
    :class:`~facemime.errors.NoFaceError` when there is none), or, given ``actor``, only that
    actor's model is placed on it, so that the motion is measured on the actor a receiver already
    holds.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the video's first frame, the face roughly frontal.
    name
        Names the first frame in messages (e.g. ``the first frame of clip.mp4``).
    params
        The contour tracker's settings (:class:`~facemime.track.redetect.FaceTracker`); None: its
        defaults.
    actor
        The same person's actor, fitted before: its model and texture are kept, its pose, source
        and scene are this frame's. None: an actor is fitted on ``frame``.
    fps
        The video's frame rate, frames/s (at least 1 is used): sets the pose filter's time step.
    eye_model
        Look at closing eyes with the eye model (FrameMotion's ``lid_closure``, for the ARKit
        blinks: up to 7 ms a frame); False: ``lid_closure`` is None.
    """

    def __init__(
        self,
        frame: np.ndarray,
        name: str,
        params: TrackerParams | None = None,
        actor: Actor | None = None,
        fps: float = 25.0,
        eye_model: bool = False,
    ):
        self.params = params
        self.timings = Timings()
        t0 = time.perf_counter()
        found, self.warnings = find_points(frame, name)
        self.actor, _, _ = fit_actor(frame, name, found.points, model=None if actor is None else actor.model)
        if actor is not None:  # placed on this frame, in this frame's scene
            self.actor = replace(actor, pose=self.actor.pose, source=self.actor.source, scene=self.actor.scene)
        self.timings.fit += time.perf_counter() - t0
        self.deformer = Deformer(self.actor.model)
        contours = init_contours(self.actor)
        self._knots0 = self.deformer.knot_positions(contours, self.actor.pose)
        self.tracker = FaceTracker(frame, contours, params)
        self.eyes = EyeTracker(self.actor.model, frame, self.actor.pose)
        self.eye_state = self.eyes.key  # the eyes as last measured (image positions, for checks)
        t0 = time.perf_counter()
        self.pose = PoseFollower(frame, found.face.landmarks, self.actor.model, self.actor.pose, self.tracker, fps)
        self.timings.fit += time.perf_counter() - t0
        self._key_openings = landmark_openings(self.pose.key_landmarks)
        # the eye model's opening of the key frame's eyes, their mean: None where it is not used
        self._key_lids = float(eye_openings(frame, self.pose.key_landmarks).mean()) if eye_model else None
        self.last = FrameMotion(
            contours, dict.fromkeys(FEATURES, 1.0), [], True, self.actor.pose, np.zeros((len(self.deformer.knots), 2))
        )
        self.frames_without_face = 0

    def update(self, frame: np.ndarray) -> FrameMotion:
        """Analyse the next frame.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB, the same size as the first frame.

        Returns
        -------
        FrameMotion
            What the frame's analysis measured (also kept as ``last``); where the face was not
            found, the last good frame's pose, offsets and look, ``face`` False.
        """
        t0 = time.perf_counter()
        result = self.tracker.update(frame)
        t1 = time.perf_counter()
        face = result.face
        fitted = self.pose.fit_seconds
        pose = self.pose.update(frame, self.last.face, face)
        elsewhere = self.pose.fit_seconds - fitted  # seconds after t1 counted as fitting or look, not as the pose's
        self.timings.fit += elsewhere
        if face:
            offsets = self.deformer.knot_positions(result.contours, pose) - self._knots0
            t2 = time.perf_counter()
            self.eye_state = self.eyes.update(frame, pose)
            closure, iris = self.eyes.look(self.eye_state)
            look = Look(closure, iris)
            landmarks, lids, jaw, eyelids = self.pose.landmarks, None, None, None
            if landmarks is not None:
                lids = 1.0 - landmark_openings(landmarks) / np.maximum(self._key_openings, 1e-6)
                jaw = jaw_opening(landmarks, self.pose.key_landmarks)
                if self._key_lids is not None:
                    eyelids = self._lid_closures(frame, landmarks, quick_closures(closure, lids))
            looking = time.perf_counter() - t2
            self.timings.look += looking
            elsewhere += looking
            self.last = FrameMotion(
                result.contours,
                result.confidence,
                result.lost,
                True,
                pose,
                offsets,
                result.redetected,
                look,
                lids,
                jaw,
                eyelids,
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

    def _lid_closures(self, frame: np.ndarray, landmarks: np.ndarray, quick: np.ndarray) -> np.ndarray:
        """The eye model's closures (FrameMotion's ``lid_closure``) of the eyes whose ``quick``
        closures are at least :data:`~facemime.animate.arkit.LID_GATE`; NaN for the other."""
        out = np.full(2, np.nan)
        eyes = np.flatnonzero(quick >= LID_GATE)
        out[eyes] = 1.0 - eye_openings(frame, landmarks, eyes.tolist()) / max(self._key_lids or 0.0, 1e-6)
        return out

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
    """The :class:`Analysis` of a video, started on its first frame.

    Raises :class:`~facemime.errors.NoFaceError`, saying that the video must start with a frontal
    face, where that frame shows none.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the video's first frame.
    video
        The video's name, in messages.
    **options
        :class:`Analysis`'s keyword arguments (``params``, ``actor``, ``fps``, ``eye_model``).

    Returns
    -------
    Analysis
        The analysis, ``last`` holding the first frame's :class:`FrameMotion`.
    """
    try:
        return Analysis(frame, f"the first frame of {video}", **options)
    except NoFaceError as e:
        raise NoFaceError(f"{e}; the video must start with a frontal face") from None


def analysed(
    frames: Iterable[np.ndarray], video: str, **options: Any
) -> Generator[tuple[np.ndarray, Analysis, FrameMotion]]:
    """Each frame with the video's :class:`Analysis` and that frame's :class:`FrameMotion`.

    The first frame starts the analysis (:func:`start_analysis`: its one message for a first
    frame without a face), each later one updates it, re-detecting a face that was lost.

    Parameters
    ----------
    frames
        The video's frames, each (H, W, 3) uint8 RGB, all of one size.
    video
        The video's name, in messages.
    **options
        :class:`Analysis`'s keyword arguments (``params``, ``actor``, ``fps``, ``eye_model``).

    Yields
    ------
    frame : (H, W, 3) uint8 array
        The frame, as given.
    analysis : Analysis
        The video's analysis: the same object on every frame.
    motion : FrameMotion
        What the analysis measured on this frame.
    """
    analysis = None
    for frame in frames:
        if analysis is None:
            analysis = start_analysis(frame, video, **options)
            yield frame, analysis, analysis.last
        else:
            yield frame, analysis, analysis.update(frame)
